"""
Workspace of a five-bar's tip
=============================

``screwkin workspace`` grows a grid of the output point's positions from the assembled configuration,
solving the inverse kinematics of the loop at each point on one assembly mode, and measures the
conditioning there (the smallest of the actuator and serial measures).  ``--csv`` writes every point;
here the planar five-bar's tip (``robots/five_bar.urdf``), coloured by conditioning.  The reported
area is the sum of the grid's runs extended to the boundary by bisection::

    screwkin workspace robots/five_bar.urdf --output tip --point --resolution 12mm --png workspace.png
"""

import csv
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from _screwkin_cli import ROBOTS, screwkin

out = Path(tempfile.mkdtemp()) / "workspace.csv"
d = screwkin("workspace", ROBOTS / "five_bar.urdf", "--output", "tip", "--point", "--resolution", "12mm",
             "--csv", out)
rows = list(csv.DictReader(out.open()))
print(f"area {d['volume']:.5f} {d['volume_unit']}, singularity-free {d['free_fraction']:.0%}; "
      f"{len(rows)} grid points; columns: {', '.join(list(rows[0])[:6])}, ...")
x, y, c = (np.array([float(r[k]) for r in rows]) for k in ("x", "y", "conditioning"))

fig, ax = plt.subplots(figsize=(6, 5.5))
m = ax.scatter(x * 1e3, y * 1e3, c=c, s=9, marker="s", cmap="viridis")
fig.colorbar(m, label="conditioning (relative sigma_min)")
ax.scatter(*(np.array([[float(r["x"]), float(r["y"])] for r in rows if r["free"] == "0"]).T * 1e3).reshape(2, -1),
           s=9, c="red", marker="s", label="below the threshold (near singular)")
ax.plot([0, 100], [0, 0], "k^", ms=9, label="motors")
ax.set(xlabel="x [mm]", ylabel="y [mm]", aspect="equal", title=f"five-bar tip: {d['volume'] * 1e4:.0f} cm^2")
ax.legend(loc="lower left", fontsize=8)
