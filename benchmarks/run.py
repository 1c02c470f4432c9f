"""screwkin benchmarks, measured side by side with other tools in one run.

    pip install -e '.[bench]'
    python benchmarks/run.py [--configs 100000] [--steps 3600]

Prints a Markdown report (paste it into benchmarks/README.md).  Every speed
figure comes with the accuracy each side reached; ratios are taken within this
one run because the machines are shared and noisy.  Nothing here is a test.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import time
from datetime import date
from pathlib import Path

import numpy as np
import pinocchio as pin

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
import screwkin  # noqa: E402
from screwkin.analysis.singularities.batch import SerialJacobians, frame_jacobians  # noqa: E402
from study import report as study_report  # noqa: E402  (benchmarks/study.py, beside this file)


def interleaved(functions: dict, repeat=3):
    """Best wall time of each function over ``repeat`` rounds that run them one after the
    other (a slow spell of the shared machine then hits every side), and each one's last
    result: {name: (seconds, result)}."""
    best = {k: (np.inf, None) for k in functions}
    for _ in range(repeat):
        for k, f in functions.items():
            t = time.perf_counter()
            out = f()
            t = time.perf_counter() - t
            best[k] = (min(best[k][0], t), out)
    return best


def best_of(f, repeat=3):
    """Smallest wall time of ``repeat`` runs of f() [s], and its last result."""
    best, out = np.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t)
    return best, out


# ---------------------------------------------------------------- 1. serial singularity scan
def serial_scan(n):
    """Rows (tool, measure, seconds, max difference from the reference values).  The
    reference for each measure is numpy on Pinocchio's Jacobian, one configuration at a time."""
    mech = screwkin.load(ROOT / "robots" / "arm_6r.urdf")
    model, fid = mech.model, mech.link_frame("flange")
    LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    Q = np.random.default_rng(0).uniform(-np.pi, np.pi, (n, 6))
    data = model.createData()
    sj = SerialJacobians(mech, "flange", LWA)
    cores = os.cpu_count() or 1

    def pinocchio_floor():  # the bare Jacobian loop, no measure
        for q in Q:
            pin.computeFrameJacobian(model, data, q, fid, LWA)

    J_ref = frame_jacobians(model, fid, Q, LWA, data)
    ref = {"sigma_min": np.array([np.linalg.svd(J, compute_uv=False)[-1] for J in J_ref]),
           "det": np.array([np.linalg.det(J) for J in J_ref])}
    del J_ref
    rows = []

    def add(tool, measure, f, repeat=3, scale=1.0, compare=None):
        t, out = best_of(f, repeat)
        err = None if out is None else float(np.abs(out - (ref[measure] if compare is None else compare)).max())
        rows.append((tool, measure, t * scale, err))

    # (scale_translation=1.0: singular values in SI units, as the references; screwkin's
    # commands make them dimensionless with the mechanism's length)
    for measure in ("det", "sigma_min"):
        add("screwkin SerialJacobians, 1 thread", measure, lambda: sj.measures(Q, measure, scale_translation=1.0))
        if measure == "sigma_min":
            add("screwkin SerialJacobians, method gram, 1 thread", measure,
                lambda: sj.measures(Q, measure, scale_translation=1.0, method="gram"))
        if cores > 1:
            add(f"screwkin SerialJacobians, {cores} threads", measure, lambda: sj.measures(Q, measure, scale_translation=1.0, workers=cores))
            if measure == "sigma_min":
                add(f"screwkin SerialJacobians, method gram, {cores} threads", measure,
                    lambda: sj.measures(Q, measure, scale_translation=1.0, method="gram", workers=cores))
        stacked = np.linalg.det if measure == "det" else (lambda J: np.linalg.svd(J, compute_uv=False)[:, -1])
        one = np.linalg.det if measure == "det" else (lambda J: np.linalg.svd(J, compute_uv=False)[-1])
        add("Pinocchio Jacobian loop + one stacked numpy call", measure,
            lambda: stacked(frame_jacobians(model, fid, Q, LWA, data)))
        add("Pinocchio Jacobian loop + numpy per configuration", measure,
            lambda: np.array([one(pin.computeFrameJacobian(model, data, q, fid, LWA)) for q in Q]), 1)
    add("bare Pinocchio Jacobian loop, no measure (floor)", "none", lambda: pinocchio_floor(), 3)

    # the same arm in the peers: its space screws (w, v) for modern_robotics, an ETS for the toolbox
    from screwkin.analysis.screws import chains

    ch = next(c for c in chains(mech, output="flange") if c.name.startswith("output"))
    try:
        import modern_robotics as mr

        Slist = np.vstack([ch.xi0[3:], ch.xi0[:3]])  # (w, v) columns
        m = min(n, 20000)
        # modern_robotics gives the space Jacobian (at the world origin, (w, v) rows): its determinant is
        # minus ours (three row swaps), its singular values Pinocchio's WORLD Jacobian's
        world = frame_jacobians(model, fid, Q[:m], pin.ReferenceFrame.WORLD, data)
        mr_ref = {"det": -np.linalg.det(world), "sigma_min": np.linalg.svd(world, compute_uv=False)[:, -1]}
        for measure in ("det", "sigma_min"):
            one = np.linalg.det if measure == "det" else (lambda J: np.linalg.svd(J, compute_uv=False)[-1])
            add(f"modern_robotics JacobianSpace + numpy per configuration ({m} configurations, scaled)", measure,
                lambda: np.array([one(mr.JacobianSpace(Slist, Q[k])) for k in range(m)]), 1, n / m, mr_ref[measure])
    except ImportError:
        rows.append(("modern_robotics: not installed (pip install -e '.[bench]')", "-", np.nan, None))
    try:
        import roboticstoolbox as rtb

        ET = rtb.ET
        ets = (ET.tz(0.3) * ET.Rz() * ET.tx(0.05) * ET.tz(0.1) * ET.Ry() * ET.tz(0.4) * ET.Ry() * ET.tx(0.05)
               * ET.tz(0.02) * ET.Rx() * ET.tx(0.35) * ET.Ry() * ET.Rx() * ET.tx(0.08))
        # ETS.jacob0 is the toolbox's fastest path (Robot.jacob0 adds about 5 us of Python a call)
        for measure in ("det", "sigma_min"):
            one = np.linalg.det if measure == "det" else (lambda J: np.linalg.svd(J, compute_uv=False)[-1])
            stacked = np.linalg.det if measure == "det" else (lambda J: np.linalg.svd(J, compute_uv=False)[:, -1])
            add("roboticstoolbox-python ETS.jacob0 (C extension) + numpy per configuration", measure,
                lambda: np.array([one(ets.jacob0(q)) for q in Q]), 1)
            add("roboticstoolbox-python ETS.jacob0 (C extension) + one stacked numpy call", measure,
                lambda: stacked(np.array([ets.jacob0(q) for q in Q])), 1)
    except ImportError:
        rows.append(("roboticstoolbox-python: not installed", "-", np.nan, None))
    return rows


# ---------------------------------------------------------------- 2. closed-loop forward kinematics
def _toolbox():
    """toolbox-parallel-robots without its package __init__ (which needs pinocchio.casadi,
    absent from the PyPI wheel): see benchmarks/README.md."""
    import importlib
    import importlib.util
    import types

    spec = importlib.util.find_spec("toolbox_parallel_robots")
    if spec is None:
        return None
    bare = types.ModuleType("toolbox_parallel_robots")
    bare.__path__ = list(spec.submodule_search_locations)
    sys.modules["toolbox_parallel_robots"] = bare
    fk = importlib.import_module("toolbox_parallel_robots.forward_kinematics")
    am = importlib.import_module("toolbox_parallel_robots.actuation_model")
    stand_in = types.ModuleType("pinocchio.casadi")

    class Model:  # nothing is an instance of it: mergeq takes its numpy path
        pass

    stand_in.Model = Model
    pin.casadi = stand_in
    return fk, am


def closed_loop_fk(names, solves):
    import yaml

    from screwkin.model.linalg import null_space
    from screwkin.analysis.position.position import PositionSolver

    tb = _toolbox()
    rows = []
    corpus = ROOT / "robots" / "corpus" / "example-parallel-robots"
    for name in names:
        urdf, side = corpus / name / "robot.urdf", corpus / name / "robot.yaml"
        mech = screwkin.load(urdf, warn=lambda m: None)
        solver = PositionSolver(mech)
        q0 = mech.assemble().q
        rng = np.random.default_rng(3)
        targets = []
        V = null_space(mech.closure.jacobian(q0), mech.tolerances, mech.nv)
        for _ in range(solves):  # motor values of assembled configurations near q0
            step = V @ rng.normal(size=V.shape[1])
            q1 = mech.closure.solve(pin.integrate(mech.model, q0, 0.05 * step / np.linalg.norm(step))).q
            targets.append({n: v for n, v in solver.joint_values(q1).items() if n in mech.actuated})
        near = solver.joint_values(q0)

        def ours_track():  # the configuration only, checked (closure residual, cut joint orientation)
            return [solver.track(t, q0).q for t in targets]

        def ours_solve():  # the full position analysis: joint values, singularity measure, limits
            return [solver.solve(t, near=near, starts=0).solutions[0].q for t in targets]

        functions = {"track": ours_track, "solve": ours_solve}
        # the same with the compiled inner loop (screwkin.model.kernel.compiled, numba), on its own copy of the mechanism
        fast_mech = screwkin.load(urdf, warn=lambda m: None)
        fast = PositionSolver(fast_mech, compiled=True)
        if fast.compiled:
            fast.track(targets[0], q0)  # compile (or load the compiled code from its cache) before timing

            def ours_compiled():
                return [fast.track(t, q0).q for t in targets]

            functions["compiled"] = ours_compiled
        if tb is not None:
            fk, am = tb
            model = pin.buildModelFromUrdf(str(urdf))
            data = model.createData()
            content = yaml.safe_load(side.read_text())
            cmodels = []
            for (a, b), kind in zip(content["closed_loop"], content["type"]):
                fa, fb = model.frames[model.getFrameId(a)], model.frames[model.getFrameId(b)]
                ctype = pin.ContactType.CONTACT_3D if kind.lower() == "3d" else pin.ContactType.CONTACT_6D
                cmodels.append(pin.RigidConstraintModel(ctype, model, fa.parentJoint, fa.placement, fb.parentJoint,
                                                        fb.placement, pin.ReferenceFrame.LOCAL))
            cdatas = [c.createData() for c in cmodels]
            act = am.ActuationModel(model, content["name_mot"])
            mot_order = content["name_mot"]

            class Start(np.ndarray):  # its `q_prec == []` test breaks on numpy 2 arrays; answer it as intended
                def __eq__(self, other):
                    return False if isinstance(other, list) else np.ndarray.__eq__(self, other)

            start = np.asarray(q0).view(Start)

            def theirs():
                out = []
                for t in targets:
                    qm = np.array([t[n] for n in mot_order])
                    out.append(np.asarray(fk.closedLoopForwardKinematicsScipy(model, data, cmodels, cdatas, act, qm,
                                                                              q_prec=start)))
                return out

            functions["slsqp"] = theirs
        import contextlib
        import io

        with contextlib.redirect_stdout(io.StringIO()):  # SLSQP prints a report per solve
            timed = interleaved(functions)
        residuals = {k: max(float(np.linalg.norm(mech.closure.residual(q))) for q in out)
                     for k, (_, out) in timed.items()}
        row = [name, timed["track"][0] / solves, residuals["track"], timed["solve"][0] / solves, residuals["solve"],
               None, None, None, None]
        if "slsqp" in timed:
            row[5:7] = [timed["slsqp"][0] / solves, residuals["slsqp"]]
        if "compiled" in timed:
            row[7:9] = [timed["compiled"][0] / solves, residuals["compiled"]]
        rows.append(row)
    return rows


# ---------------------------------------------------------------- 3. sweep throughput
def sweep_throughput(steps):
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.analysis.motion.sweep import sweep

    rows = []
    for name, inp, rng, fixed in (("gough_stewart_6ups", "leg1", (0.0, 0.1), {f"leg{k}": 0.0 for k in range(2, 7)}),
                                  ("delta_parallelogram", "arm1", (0.0, 0.6), {"arm2": 0.0, "arm3": 0.0})):
        for compiled in (False, True):
            mech = screwkin.load(ROOT / "robots" / f"{name}.urdf")
            solver = PositionSolver(mech, compiled=compiled)
            if compiled and not solver.compiled:
                continue
            label = f"{name}{', compiled' if compiled else ''}"
            sweep(solver, inp, rng[0], rng[1], 10, fixed=fixed)  # warm up (the compiled code loads)
            t, res = best_of(lambda: sweep(solver, inp, rng[0], rng[1], steps, fixed=fixed), 1)
            worst = max(float(np.linalg.norm(mech.closure.residual(q))) for q in res.q[:: max(steps // 100, 1)])
            rows.append((label, len(res.values) - 1, t, (len(res.values) - 1) / t, worst))
    return rows


# ---------------------------------------------------------------- 4. start-up
def startup():
    robot = ROOT / "robots" / "delta_parallelogram.urdf"
    # peak RSS from the kernel's high-water mark of this process's own address space (VmHWM):
    # ru_maxrss of a child started by fork counts the parent's memory at the fork
    code = ("import resource, runpy, sys, time; t = time.perf_counter(); "
            "sys.argv = ['screwkin', 'mobility', sys.argv[1]]; "
            "from screwkin.cli import main; rc = main(); "
            "hwm = [l for l in open('/proc/self/status') if l.startswith('VmHWM')] "
            "if sys.platform == 'linux' else []; "
            "rss = int(hwm[0].split()[1]) if hwm else resource.getrusage(resource.RUSAGE_SELF).ru_maxrss; "
            "print('WALL', time.perf_counter() - t, 'RSS', rss, file=sys.stderr)")
    walls, rss = [], []
    for _ in range(3):
        t = time.perf_counter()
        p = subprocess.run([sys.executable, "-c", code, str(robot)], capture_output=True, text=True)
        walls.append(time.perf_counter() - t)
        rss.append(int(p.stderr.split("RSS")[1].split()[0]))
    imp = subprocess.run([sys.executable, "-X", "importtime", "-c", "import screwkin.cli, screwkin.model.mechanism, "
                          "screwkin.analysis.mobility"], capture_output=True, text=True).stderr.splitlines()
    total = {}
    for line in imp:
        if "|" not in line or "cumulative" in line:
            continue
        _, cum, name = [x.strip() for x in line.split("|")]
        if "." not in name and name.strip():
            total[name] = int(cum)
    top = sorted(total.items(), key=lambda kv: -kv[1])[:5]
    # where the rest goes: parse + model, assembly, analysis
    mech_t, mech = best_of(lambda: screwkin.load(robot), 1)
    asm_t, _ = best_of(lambda: mech.assemble(), 1)
    mob_t, _ = best_of(lambda: mech.mobility(), 1)
    return min(walls), max(rss), top, (mech_t, asm_t, mob_t)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--configs", type=int, default=100000)
    ap.add_argument("--steps", type=int, default=3600)
    ap.add_argument("--solves", type=int, default=50)
    ap.add_argument("--designs", type=int, default=48, help="designs of the study throughput benchmark")
    args = ap.parse_args()
    out = [f"## Run of {date.today()} on {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
           f"numpy {np.__version__}, pinocchio {pin.__version__}", ""]
    rows = serial_scan(args.configs)
    out += [f"### 1. Serial singularity scan: Jacobian + a measure, {args.configs} random configurations of "
            "robots/arm_6r.urdf", "", "| tool | measure | per configuration [us] | time / screwkin 1 thread, same measure | "
            "max difference from numpy on Pinocchio |", "|---|---|---|---|---|"]
    ours = {m: t for tool, m, t, _ in rows if tool == "screwkin SerialJacobians, 1 thread"}
    floor = next(t for tool, m, t, _ in rows if m == "none")
    for tool, m, t, err in rows:
        base = ours.get(m, ours["det"])
        ratio = f"{t / base:.2f}x" if np.isfinite(t) and m != "none" else "-"
        out.append(f"| {tool} | {m} | {1e6 * t / args.configs:.2f} | {ratio} | {'-' if err is None else f'{err:.1e}'} |")
    out += ["", f"screwkin 1 thread / bare Pinocchio floor: det {ours['det'] / floor:.2f}, "
            f"sigma_min {ours['sigma_min'] / floor:.2f}", ""]
    out += ["### 2. Closed-loop forward kinematics on the corpus robots (robots/corpus/) (same motor targets, same assembled start)",
            "", f"{args.solves} solves per robot, best of 3 runs.  `track`: the configuration only (checked); "
            "`track, compiled`: the same with the inner loop compiled by numba (`PositionSolver(mech, compiled=True)`); "
            "`solve`: the full position analysis (joint values, singularity measure, limits).", "",
            "| robot | screwkin track [ms] | worst residual | screwkin track, compiled [ms] | worst residual | "
            "screwkin solve [ms] | worst residual | toolbox-parallel-robots SLSQP [ms] | worst residual | "
            "SLSQP / track | SLSQP / track compiled | SLSQP / solve |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, t1, r1, t2, r2, t3, r3, t4, r4 in closed_loop_fk(["5bar_linkage", "robot_delta", "cassie_like",
                                                                "talos_like", "digit_like"], args.solves):
        comp = f"{1e3 * t4:.3f} | {r4:.1e}" if t4 is not None else "numba not installed | -"
        head = f"| {name} | {1e3 * t1:.3f} | {r1:.1e} | {comp} | {1e3 * t2:.3f} | {r2:.1e} |"
        if t3 is None:
            out.append(head + " not installed | - | - | - | - |")
        else:
            fast = f"{t3 / t4:.1f}x" if t4 is not None else "-"
            out.append(head + f" {1e3 * t3:.3f} | {r3:.1e} | {t3 / t1:.1f}x | {fast} | {t3 / t2:.1f}x |")
    out += ["", "Residual: norm of screwkin's minimal closure rows at the returned configuration, the same metric for "
            "both.", ""]
    out += [f"### 3. Sweep throughput ({args.steps} steps, rates at every step)", "",
            "| mechanism | steps | time [s] | steps per second | worst closure residual |", "|---|---|---|---|---|"]
    for name, n, t, sps, worst in sweep_throughput(args.steps):
        out.append(f"| {name} | {n} | {t:.2f} | {sps:.0f} | {worst:.1e} |")
    wall, rss, top, parts = startup()
    out += ["", "### 4. Start-up of `screwkin mobility robots/delta_parallelogram.urdf` (new process)", "",
            f"wall {wall:.2f} s (best of 3, process start to exit), peak RSS {rss / 1024:.0f} MiB; "
            f"load {parts[0] * 1e3:.0f} ms, assembly {parts[1] * 1e3:.0f} ms, mobility analysis {parts[2] * 1e3:.0f} ms; "
            "largest imports (cumulative us): " + ", ".join(f"{k} {v}" for k, v in top)]
    out += [""] + study_report(args.designs)
    print("\n".join(out))


if __name__ == "__main__":
    main()
