"""
A four-bar's coupler curve
==========================

A crank-rocker four-bar (``robots/fourbar_crank_rocker.urdf``) swept through a whole crank turn:
``screwkin sweep`` follows one assembly mode, in closed form (the linkage is made of one dyad), and
reports the path of a point fixed on the coupler, with its velocity.  The same sweep from the shell::

    screwkin sweep robots/fourbar_crank_rocker.urdf --input crank_joint --from 0 --to 360deg \\
        --steps 120 --point P=coupler:60mm,20mm --plot sweep.png
"""

import matplotlib.pyplot as plt
import numpy as np
from _screwkin_cli import ROBOTS, screwkin

d = screwkin("sweep", ROBOTS / "fourbar_crank_rocker.urdf", "--input", "crank_joint", "--from", "0",
             "--to", "360deg", "--steps", "120", "--point", "P=coupler:60mm,20mm", "--rate", "60rpm")
P = np.array(d["points"]["P"]["position"])[:, :2]          # world x, y of the point [m]
v = np.linalg.norm(np.array(d["points"]["P"]["velocity"]), axis=1)   # its speed at 60 rpm [m/s]
print(d["linkage"]["grashof"], "--", d["method"])

fig, ax = plt.subplots(figsize=(6, 4.5))
line = ax.scatter(P[:, 0] * 1e3, P[:, 1] * 1e3, c=v, s=12, cmap="viridis")
fig.colorbar(line, label="speed of P at 60 rpm [m/s]")
ax.plot([0, 100], [0, 0], "k^", ms=10, label="ground pivots")
ax.set(xlabel="x [mm]", ylabel="y [mm]", title="coupler curve of P = coupler:(60, 20) mm", aspect="equal")
ax.legend(loc="lower right")
