"""A four-bar through a full crank turn: positions, Grashof class, transmission angle, dead centres.

Run:  python examples/fourbar_motion.py [steps]

Solves the loop-closure equations at each crank angle on one circuit, reports
the textbook extras (Grashof class, worst transmission angle, the crank angles
where the rocker stops) and the two assembly modes at one crank angle.
"""

import sys
from pathlib import Path

import numpy as np

import screwkin
from screwkin.analysis.motion.planar import identify
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.motion.singular_points import locate_singularities
from screwkin.analysis.motion.sweep import sweep

ROBOTS = Path(__file__).resolve().parents[1] / "robots"
steps = int(sys.argv[1]) if len(sys.argv) > 1 else 180

mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
solver = PositionSolver(mech)  # inputs: the actuated joints of the file (crank_joint)

both = solver.solve({"crank_joint": np.radians(30)})
print(f"crank +30 deg from the drawn pose: {len(both.solutions)} assembly modes, rocker at "
      + ", ".join(f"{np.degrees(s.joints['rocker_joint']):.4f} deg" for s in both.solutions))

res = sweep(solver, "crank_joint", 0.0, 2 * np.pi, steps)
q = res.q[0]
info = identify(mech, mech.topology(q), q, "crank_joint")
mus = [identify(mech, mech.topology(q), q, "crank_joint").transmission_angle for q in res.q]
rocker = res.joints[:, res.names.index("rocker_joint")]
print(info.grashof)
print(f"rocker swings over {np.degrees(rocker.max() - rocker.min()):.4f} deg")
print(f"transmission angle between {np.degrees(min(mus)):.3f} and {np.degrees(max(mus)):.3f} deg")
for s in locate_singularities(solver, res, output="rocker"):
    print(f"rocker stops ({s.kind} singularity) at crank joint {np.degrees(s.input):.9f} deg")
