"""Closed-loop forward kinematics in a control loop: a Gough-Stewart platform driven by its legs.

Run:  python examples/stewart_motor_loop.py [steps]

Each step moves the six leg lengths a little along a smooth trajectory and asks
PositionSolver.track for the configuration, by damped Newton from the previous
one (the same assembly mode), checked like every solution.  Prints the platform's
motion, the worst closure residual and the time per step, with numpy and, when
numba is installed (pip install -e '.[fast]'), with the compiled inner loop.
"""

import sys
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

import screwkin
from screwkin.analysis.position.position import PositionSolver

ROBOTS = Path(__file__).resolve().parents[1] / "robots"
steps = int(sys.argv[1]) if len(sys.argv) > 1 else 500


def run(compiled):
    mech = screwkin.load(ROBOTS / "gough_stewart_6ups.urdf")
    solver = PositionSolver(mech, compiled=compiled)
    q = mech.assemble().q
    legs = np.array([solver.joint_values(q)[n] for n in mech.actuated])
    phases = np.linspace(0.0, 2 * np.pi, 6, endpoint=False)
    data = mech.model.createData()
    platform = mech.link_frame("platform")
    path, worst = [], 0.0
    solver.track(dict(zip(mech.actuated, legs)), q)  # the compiled code loads before the clock starts
    start = time.perf_counter()
    for k in range(steps):
        t = 2 * np.pi * k / steps
        target = legs + 0.02 * np.sin(t + phases)  # each leg +-20 mm, out of phase
        a = solver.track(dict(zip(mech.actuated, target)), q)
        q = a.q
        worst = max(worst, a.residual)
        pin.framesForwardKinematics(mech.model, data, q)
        path.append(data.oMf[platform].translation.copy())
    elapsed = time.perf_counter() - start
    return np.array(path), worst, elapsed, solver.compiled


path, worst, elapsed, _ = run(compiled=False)
print(f"{steps} steps, numpy: {1e6 * elapsed / steps:.0f} us a step, worst closure residual {worst:.1e}")
span = path.max(axis=0) - path.min(axis=0)
print("platform origin moved within a box of " + " x ".join(f"{1e3 * s:.2f}" for s in span) + " mm")
fast_path, fast_worst, fast_elapsed, compiled = run(compiled=True)
if compiled:
    print(f"{steps} steps, compiled: {1e6 * fast_elapsed / steps:.0f} us a step, worst closure residual "
          f"{fast_worst:.1e}; same path to {np.abs(fast_path - path).max():.1e} m")
else:
    print("compiled inner loop not available (pip install -e '.[fast]' installs numba)")
