"""
An animated four-bar
====================

The four-bar of the README's first example, written with every link along +x and its loop left open
at B (screwkin assembles it), driven through a turn of its crank O2.  ``screwkin sweep --json`` gives
each link's frame origin per step (``links``) and the named points (``--point``): the animation draws the
linkage from them, with the coupler point's path.  ``screwkin draw --animate fourbar.gif`` writes such
an animation (GIF or MP4) directly::

    screwkin draw fourbar.urdf --animate fourbar.gif --input O2 --from 0 --to 360deg --point P=coupler:60mm,20mm
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation
from _screwkin_cli import screwkin

URDF = """<?xml version="1.0"?>
<robot name="my_fourbar">
  <link name="ground"/> <link name="crank"/> <link name="coupler"/> <link name="rocker"/>
  <joint name="O2" type="continuous"> <parent link="ground"/> <child link="crank"/>
    <origin xyz="0 0 0"/> <axis xyz="0 0 1"/> </joint>
  <joint name="A" type="continuous"> <parent link="crank"/> <child link="coupler"/>
    <origin xyz="0.04 0 0"/> <axis xyz="0 0 1"/> </joint>
  <joint name="O4" type="continuous"> <parent link="ground"/> <child link="rocker"/>
    <origin xyz="0.10 0 0"/> <axis xyz="0 0 1"/> </joint>
  <loop_joint name="B" type="revolute"> <link1 link="coupler" xyz="0.12 0 0"/>
    <link2 link="rocker" xyz="0.08 0 0"/> <axis xyz="0 0 1"/> </loop_joint>
  <transmission name="motor"><joint name="O2"/></transmission>
</robot>
"""
file = Path(tempfile.mkdtemp()) / "fourbar.urdf"
file.write_text(URDF)
d = screwkin("sweep", file, "--input", "O2", "--from", "0", "--to", "360deg", "--steps", "48",
             "--point", "P=coupler:60mm,20mm", "--point", "B=coupler:120mm,0")
xy = lambda a: np.array(a)[:, :2] * 1e3  # noqa: E731  (world x, y in mm)
O2 = np.zeros((len(d["values"]), 2))
A = xy(d["links"]["coupler"]["position"])        # the coupler's frame origin is the pin A
B, P = xy(d["points"]["B"]["position"]), xy(d["points"]["P"]["position"])
O4 = xy(d["links"]["rocker"]["position"])

fig, ax = plt.subplots(figsize=(6, 4))
ax.set(xlim=(-50, 150), ylim=(-60, 110), aspect="equal", xlabel="x [mm]", ylabel="y [mm]")
ax.plot(P[:, 0], P[:, 1], ":", color="0.6")
bars, = ax.plot([], [], "o-", lw=3, color="C0")
coupler, = ax.fill([0], [0], alpha=0.3, color="C1")
trace, = ax.plot([], [], "C3-")
title = ax.set_title("")


def frame(k):
    bars.set_data([O2[k, 0], A[k, 0], B[k, 0], O4[k, 0]], [O2[k, 1], A[k, 1], B[k, 1], O4[k, 1]])
    coupler.set_xy([A[k], B[k], P[k]])
    trace.set_data(P[: k + 1, 0], P[: k + 1, 1])
    title.set_text(f"O2 = {np.degrees(d['values'][k]):.0f} deg")
    return bars, coupler, trace, title


frame(6)
animation = FuncAnimation(fig, frame, frames=len(d["values"]), interval=60)
