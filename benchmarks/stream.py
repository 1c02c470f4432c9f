"""Streamed sweeps (memory) and batched continuation (speed): issue 26 items 2 and 4.

    python benchmarks/stream.py            # about 2 minutes on 2 cores
    python benchmarks/stream.py --quick    # 10^5 steps only, fewer repetitions

1. Peak memory of `screwkin sweep FOURBAR --steps N --csv F` in a fresh process each
   (resource.getrusage(RUSAGE_SELF).ru_maxrss at its end, KiB on Linux), for N = 10^5 in memory
   (the bound for text/JSON), 10^5 and 10^6 streamed in chunks, beside the process that only
   imports the CLI: memory flat means the streamed rows add nothing that grows with N.
2. `screwkin.sweep` on spatial loops: the per-step tracker (closed_form=False, batch=False)
   against the batched corrector (the default), same grid, median of a few runs each.
Never a timed test: numbers for benchmarks/README.md.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FOURBAR = os.path.join(ROOT, "robots", "fourbar_crank_rocker.urdf")

CHILD = """
import resource, sys, time
t = time.perf_counter()
from screwkin.cli import main
argv = sys.argv[1:]
code = main(argv) if argv else 0
print("RESULT", code, time.perf_counter() - t, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
"""


def child(argv):
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    out = subprocess.run([sys.executable, "-c", CHILD, *argv], capture_output=True, text=True, env=env, check=True)
    line = [x for x in out.stdout.splitlines() if x.startswith("RESULT")][-1].split()
    return int(line[1]), float(line[2]), int(line[3])


def memory(quick):
    with tempfile.TemporaryDirectory() as tmp:
        csv = os.path.join(tmp, "s.csv")
        base = ["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "360deg", "--csv", csv]
        runs = [("import the CLI only", []),
                ("10^5 steps, in memory (--csv, text summary)", base + ["--steps", "100000"]),
                ("10^5 steps, streamed (--chunk 20000)", base + ["--steps", "100000", "--chunk", "20000"])]
        if not quick:
            runs.append(("10^6 steps, streamed (20,000 a chunk)", base + ["--steps", "1000000"]))
        print("| run | wall [s] | peak RSS [MiB] | CSV [MB] |\n|---|---|---|---|")
        for label, argv in runs:
            if os.path.exists(csv):
                os.remove(csv)
            code, wall, rss = child(argv)
            size = os.path.getsize(csv) / 1e6 if os.path.exists(csv) else 0.0
            print(f"| {label} | {wall:.1f} | {rss / 1024:.0f} | {size:.0f} |" + ("" if code == 0 else f" exit {code}"))


def speed(quick):
    import numpy as np

    import screwkin
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.analysis.motion.sweep import sweep

    cases = [("bennett.urdf", "joint1", 0.0, 2 * np.pi, 2000), ("rssr.urdf", "crank_joint", 0.0, 0.36, 1000),
             ("gough_stewart_6ups.urdf", None, 0.0, 0.05, 1000), ("tsai_3upu.urdf", None, 0.0, 0.14, 1000)]
    reps = 1 if quick else 3
    print("\n| motion | steps | tracker [s] | batched [s] | speed-up | batched notes |\n|---|---|---|---|---|---|")
    for robot, name, a, b, n in cases:
        mech = screwkin.load(os.path.join(ROOT, "robots", robot))
        inputs = list(mech.actuated)
        name = name or inputs[0]
        solver = PositionSolver(mech, inputs)
        fixed = {k: 0.0 for k in inputs if k != name}
        q0 = solver.solve({name: a, **fixed}).solutions[0].q
        times = {}
        for label, kw in (("tracker", dict(closed_form=False, batch=False)), ("batched", {})):
            ts = []
            for _ in range(reps):
                t = time.perf_counter()
                res = sweep(solver, name, a, b, n, fixed=fixed, q_start=q0, **kw)
                ts.append(time.perf_counter() - t)
            times[label] = (float(np.median(ts)), res)
        (tt, rt), (tb, rb) = times["tracker"], times["batched"]
        print(f"| {robot} {name} {a:g}..{b:.3g} | {n} | {tt:.2f} | {tb:.2f} | {tt / tb:.1f}x | "
              f"{len(rb.notes)} ({rb.method}; {len(rb.values)} values, tracker {len(rt.values)}) |")


if __name__ == "__main__":
    quick = "--quick" in sys.argv
    print(f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores, load "
          f"{os.getloadavg()[0]:.1f}, Python {sys.version.split()[0]}\n")
    memory(quick)
    speed(quick)
