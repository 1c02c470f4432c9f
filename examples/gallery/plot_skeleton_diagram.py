"""
Skeleton diagram and kinematic chain of a Watt six-bar
======================================================

``screwkin draw`` draws a mechanism in textbook notation -- links numbered (the ground is 1), joints
lettered, ground pivots hatched, the input marked with an arrow -- and, with ``--chain``, its kinematic
chain as a graph (a node per link, an edge per joint).  Here both, for ``robots/watt_sixbar.urdf``::

    screwkin draw robots/watt_sixbar.urdf --set crank_joint=30deg --png watt.png
    screwkin draw robots/watt_sixbar.urdf --chain --png watt_chain.png
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
from _screwkin_cli import ROBOTS, screwkin

out = Path(tempfile.mkdtemp())
d = screwkin("draw", ROBOTS / "watt_sixbar.urdf", "--set", "crank_joint=30deg", "--png", out / "watt.png")
c = screwkin("draw", ROBOTS / "watt_sixbar.urdf", "--chain", "--png", out / "chain.png")
print("links:", d["links"])
print("joints:", d["joints"])

fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), gridspec_kw={"width_ratios": [1.4, 1]})
for ax, name in zip(axes, ("watt.png", "chain.png")):
    ax.imshow(plt.imread(out / name))
    ax.set_axis_off()
fig.tight_layout()
