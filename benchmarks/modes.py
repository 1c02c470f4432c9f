"""Every assembly mode of a 6-6 Gough-Stewart platform: homotopy continuation (certified) against
screwkin's random-start search at equal coverage.

    python benchmarks/modes.py

The platform is tests/model/homotopy/test_certified.py's of random geometry, seed 5 (40 complex assembly modes, 6 real).
Measured in one run, on the same machine, one after the other:
- ``solve`` by homotopy continuation (the default): time to every mode and its certificate (the
  published count of 40 reached), with the numba kernel and with numpy alone;
- ``solve(method="starts")`` (damped Newton from random configurations, the previous release's only
  search) with more and more starts until it has every real mode the homotopy found: how many starts
  that takes, and how long.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests"), str(ROOT / "tests" / "model" / "homotopy")]  # conftest, test_certified

import screwkin  # noqa: E402
from screwkin.analysis.position.position import PositionSolver  # noqa: E402
from screwkin.model.kernel import algebraic  # noqa: E402
from test_certified import stewart_urdf  # noqa: E402


SEED = 5  # of seeds 0..11 (all 40 complex modes), one with the most real modes: 6


def best(f, rounds=3):
    out, t = None, np.inf
    for _ in range(rounds):
        t0 = time.perf_counter()
        out = f()
        t = min(t, time.perf_counter() - t0)
    return out, t


def main():
    text, _, _ = stewart_urdf(SEED)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "stewart.urdf"
        path.write_text(text)
        mech = screwkin.load(path)
    solver = PositionSolver(mech)
    values = {n: 0.0 for n in solver.inputs}
    solver.solve(values)  # warm: the reference configuration, numba's compiled kernel
    rows = []
    res, t = best(lambda: solver.solve(values))
    c = res.modes
    rows.append(("homotopy continuation, numba kernel", t, c.found, c.real, c.certificate or c.reason))
    original = algebraic.numba_kernels.available
    algebraic.numba_kernels.available = lambda: False
    try:
        res_np, t_np = best(lambda: solver.solve(values), rounds=1)
    finally:
        algebraic.numba_kernels.available = original
    rows.append(("homotopy continuation, numpy only", t_np, res_np.modes.found, res_np.modes.real,
                 res_np.modes.certificate or res_np.modes.reason))
    want = [s.q for s in res.solutions]
    for starts in (24, 100, 300, 1000, 3000):
        got, t_s = best(lambda: solver.solve(values, method="starts", starts=starts), rounds=1)
        have = sum(any(np.max(np.abs(solver.signature(q) - solver.signature(s.q))) < 1e-6 for s in got.solutions)
                   for q in want)
        rows.append((f"random starts, {starts} starts", t_s, None, have, f"{have} of the {len(want)} real modes"))
        if have == len(want):
            break
    print(f"6-6 Gough-Stewart platform of random geometry: {c.found} complex assembly modes, {c.real} real")
    print(f"search detail: {c.detail}\n")
    print("| search | seconds | modes found (complex) | real modes | completeness |")
    print("|---|---|---|---|---|")
    for name, secs, found, real, note in rows:
        print(f"| {name} | {secs:.2f} | {'-' if found is None else found} | {real} | {note} |")
    print(f"\nhomotopy (numba) / random starts to equal coverage of the real modes: {t / rows[-1][1]:.1f}x "
          "(the random starts cannot know they have them all, nor count the complex ones)")


if __name__ == "__main__":
    main()
