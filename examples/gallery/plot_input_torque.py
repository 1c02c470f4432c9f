"""
Input torque, shaking force and flywheel of a four-bar
======================================================

``screwkin dynamics`` drives the crank at a constant speed and solves the closed chain's inverse
dynamics at every step (Pinocchio's RNEA of the spanning tree plus the loop's constraint forces): the
torque the motor must give, every joint's reaction, the shaking force on the ground, and the flywheel
that keeps the speed within a coefficient of fluctuation ``--cs``.  With gravity, at two speeds::

    screwkin dynamics robots/fourbar_crank_rocker.urdf --input crank_joint --speed 120rpm --gravity 0,-9.81,0 --plot torque.png
"""

import matplotlib.pyplot as plt
import numpy as np
from _screwkin_cli import ROBOTS, screwkin

fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4))
for speed in ("60rpm", "240rpm"):
    d = screwkin("dynamics", ROBOTS / "fourbar_crank_rocker.urdf", "--input", "crank_joint", "--speed", speed,
                 "--gravity", "0,-9.81,0", "--steps", "72")
    crank = np.degrees(d["values"])
    ax.plot(crank, d["efforts"]["crank_joint"], label=f"{speed}: flywheel {d['flywheel']['inertia']:.2g} kg m^2")
    shaking = np.array(d["shaking"]["force"])
    bx.plot(shaking[:, 0], shaking[:, 1], label=speed)
    print(f"{speed}: peak torque {d['peak']['crank_joint']:.4f} N m, rms {d['rms']['crank_joint']:.4f} N m")
ax.set(xlabel="crank angle [deg]", ylabel="input torque [N m]", title="torque at the crank (gravity on)")
ax.axhline(0, color="0.5", lw=0.5)
ax.legend(fontsize=8)
bx.set(xlabel="Fx [N]", ylabel="Fy [N]", title="shaking force on the ground over a turn", aspect="equal")
bx.legend(fontsize=8)
fig.tight_layout()
