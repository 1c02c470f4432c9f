"""Batched inverse kinematics (screwkin.analysis.singularities.batch.BatchClosure, what the workspace grid
uses) against one ClosureSystem solve per point (what every other command uses), on the same
problems: the Delta's platform moved by 1 cm in a random direction from an assembled
configuration, Newton from that configuration.  Then `screwkin workspace` end to end.

    python benchmarks/workspace.py      # about a minute; prints a Markdown table
"""

from __future__ import annotations

import os
import platform
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

import screwkin
import screwkin.errors
from screwkin.model.kernel.stacks import BatchClosure
from screwkin.analysis.design.workspace import workspace

ROBOTS = Path(__file__).resolve().parents[1] / "robots"


def problems(mech, output, n, seed=0):
    q = mech.generic_configurations()[0].q
    pin.framesForwardKinematics(mech.model, mech.data, q)
    M = mech.data.oMf[mech.link_frame(output)].copy()
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    P = M.translation + 0.01 * d / np.linalg.norm(d, axis=1)[:, None]
    return q, M.rotation, P


def batched(mech, output, q, R, P):
    bc = BatchClosure(mech, target=(output, "pose"), check=0)
    t = time.perf_counter()
    Q, ok, norms, _ = bc.solve(np.repeat(q[None], len(P), axis=0), (P, R))
    return time.perf_counter() - t, Q, ok, norms


def per_point(mech, output, q, R, P):
    bc = BatchClosure(mech, target=(output, "pose"), check=0)  # its ClosureSystem has the same rows
    system, model, fid = bc.system, mech.model, mech.target_frame
    frame = model.frames[fid]
    saved = frame.placement.copy()
    Q, ok, norms = [], [], []
    t = time.perf_counter()
    try:
        for p in P:
            frame.placement = pin.SE3(R, p)
            model.frames[fid] = frame
            try:
                a = system.solve(q)
            except screwkin.errors.ScrewkinError:  # did not close
                Q.append(q)
                ok.append(False)
                norms.append(np.nan)
                continue
            Q.append(a.q)
            ok.append(True)
            norms.append(a.residual)
    finally:
        frame.placement = saved
        model.frames[fid] = frame
    return time.perf_counter() - t, np.array(Q), np.array(ok), np.array(norms)


def main():
    print(f"## Run on {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}\n")
    print("| problem | method | points | per point [us] | ratio | converged | max residual | max joint difference |")
    print("|---|---|---|---|---|---|---|---|")
    for name, output, n in [("delta_parallelogram", "platform", 2000), ("gough_stewart_6ups", "platform", 1000)]:
        mech = screwkin.load(ROBOTS / f"{name}.urdf")
        q, R, P = problems(mech, output, n)
        tb, Qb, okb, nb = min((batched(mech, output, q, R, P) for _ in range(3)), key=lambda r: r[0])
        tp, Qp, okp, npp = min((per_point(mech, output, q, R, P[: n // 4]) for _ in range(2)), key=lambda r: r[0])
        diff = float(np.abs(Qb[: n // 4] - Qp).max())
        for label, t, m, ok, norms in [("BatchClosure.solve", tb, n, okb, nb),
                                       ("ClosureSystem.solve per point", tp, n // 4, okp, npp)]:
            print(f"| {name} IK, 1 cm moves | {label} | {m} | {1e6 * t / m:.0f} | {(t / m) / (tb / n):.1f}x | "
                  f"{ok.mean():.3f} | {np.nanmax(norms):.1e} | {diff:.1e} |")
    print("\n| workspace | resolution | points | configurations solved | time [s] | volume |")
    print("|---|---|---|---|---|---|")
    for name, output, point, h in [("five_bar", "tip", True, None), ("delta_parallelogram", "platform", False, None),
                                   ("planar_3rrr", "platform", False, None)]:
        mech = screwkin.load(ROBOTS / f"{name}.urdf")
        t = time.perf_counter()
        res = workspace(mech, output, point=point, resolution=h)
        dt = time.perf_counter() - t
        print(f"| {name} {output}{' point' if point else ''} | {res.resolution:.4g} m | {len(res.positions)} | "
              f"{res.solves} | {dt:.1f} | {res.volume:.6g} {'m^2' if res.dimension == 2 else 'm^3'} |")


if __name__ == "__main__":
    main()
