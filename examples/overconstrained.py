"""Counting criteria against screw theory on the overconstrained linkages.

Run:  python examples/overconstrained.py

Kutzbach's count says the Bennett linkage, the Sarrus linkage and the spherical
four-bar cannot move; their special geometry makes some constraint wrenches
dependent, so the rank of the constraint Jacobian K is smaller than its number
of rows.  The script prints both numbers and the singular values of K that
show the dependency.
"""

from pathlib import Path

import numpy as np

import screwkin

ROBOTS = Path(__file__).resolve().parents[1] / "robots"

for name in ("bennett", "sarrus", "spherical_fourbar", "fourbar_crank_rocker"):
    mech = screwkin.load(ROBOTS / f"{name}.urdf")
    r = mech.mobility()
    s = np.linalg.svd(mech.closure.jacobian(r.q), compute_uv=False)
    print(f"{name}: Kutzbach {r.kutzbach:+d}, {r.topology.motion_space} count {r.topology.count_in_motion_space:+d}, "
          f"screw-theory mobility {r.mobility} (K: {r.constraint_rows} rows, rank {r.rank}, "
          f"overconstraint {r.overconstraint})")
    print("   singular values of K: " + " ".join(f"{x:.3g}" for x in s))
    for note in r.notes:
        print("   " + note)
