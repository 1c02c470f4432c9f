"""
Singularity map of the 3-RPR
============================

``screwkin map`` over two leg lengths of the planar 3-RPR parallel robot (``robots/planar_3rpr.urdf``),
the third held: log10 of the smallest relative singular value of the actuator (direct-kinematic)
Jacobian on one assembly mode, each cell reached by continuation from a neighbour.  Dark is near
singular: there the platform gains a motion with the legs locked (the three leg lines meet at one
point).  Cells that continuation cannot reach on this mode -- past a limit position, where the mode
folds over the singular curve -- are left blank (grey), never filled from another mode.  The command
line draws the same map::

    screwkin map robots/planar_3rpr.urdf --x leg2=0:0.24:25 --y leg3=0:0.08:17 --set leg1=0 --png map.png
"""

import matplotlib.pyplot as plt
import numpy as np
from _screwkin_cli import ROBOTS, screwkin

d = screwkin("map", ROBOTS / "planar_3rpr.urdf", "--x", "leg2=0:0.24:25", "--y", "leg3=0:0.08:17",
             "--set", "leg1=0")
z = np.array(d["log10_sigma_min"], dtype=float)   # null where the continuation did not reach
xs, ys = np.array(d["xs"]) * 1e3, np.array(d["ys"]) * 1e3
print(f"{np.isfinite(z).sum()} of {z.size} cells reached; smallest log10 sigma_min {np.nanmin(z):.2f}")

fig, ax = plt.subplots(figsize=(7, 4.5))
ax.set_facecolor("0.85")
m = ax.pcolormesh(xs, ys, z, cmap="magma", shading="nearest")
fig.colorbar(m, label="log10 relative sigma_min")
ax.set(xlabel="leg2 - drawn length [mm]", ylabel="leg3 - drawn length [mm]",
       title="3-RPR, leg1 as drawn; grey: not reached on this mode")
