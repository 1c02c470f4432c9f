"""
Transmission angle of a four-bar and a slider-crank
===================================================

The transmission angle mu -- between the coupler and the output link (the rocker, or the slider's
line of motion) -- over the crank's whole turn, as ``screwkin sweep --json`` gives it per step
(``transmission_angles``).  Its extremes over the motion are located in closed form, not sampled
(``linkage.transmission_range``): the dashed lines.  Rule of thumb: keep mu within 40 to 140 deg.
"""

import matplotlib.pyplot as plt
import numpy as np
from _screwkin_cli import ROBOTS, screwkin

fig, ax = plt.subplots(figsize=(7, 4))
for file, colour in (("fourbar_crank_rocker", "C0"), ("slider_crank_offset", "C1")):
    d = screwkin("sweep", ROBOTS / f"{file}.urdf", "--input", "crank_joint", "--from", "0",
                 "--to", "360deg", "--steps", "180")
    crank = np.degrees(d["values"])
    mu = np.degrees(np.array(d["transmission_angles"], dtype=float))
    mu = np.where(mu > 90, 180 - mu, mu)  # the acute angle, as textbooks plot it
    ax.plot(crank, mu, colour, label=f"{file}: {d['linkage']['kind']}")
    r = d["linkage"]["transmission_range"]
    worst = 90 - np.degrees(r["deviation"])
    ax.axhline(worst, color=colour, ls="--", lw=0.8)
    print(f"{file}: {d['linkage']['grashof']}; worst mu {worst:.2f} deg ({r['how']})")
ax.axhspan(0, 40, color="red", alpha=0.08, label="mu < 40 deg")
ax.set(xlabel="crank angle [deg]", ylabel="transmission angle (acute) [deg]", xlim=(0, 360), ylim=(0, 92))
ax.legend(loc="lower left", fontsize=8)
