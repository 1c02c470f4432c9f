"""A joint configuration from the values of the vector-loop equations' symbols
(screwkin.analysis.course.vector_loops): where Newton's root on the loop equations puts the
mechanism's joints, rolling pairs' virtual joints included (screwkin.analysis.course.rolling).
"""

from __future__ import annotations

import numpy as np

from ...model.geometry import wrap_angle as wrap
from ...model.manifold import continuous_angle, set_continuous_angle
from .rolling import virtual_coordinates

__all__ = ["LOWER", "joint_configuration"]

#: The joints the vector-loop equations take (besides rolling and gear pairs).
LOWER = ("revolute", "continuous", "prismatic")


def joint_configuration(loops, values: dict) -> np.ndarray:
    """A joint configuration whose link angles and slider coordinates are ``values``: each
    tree joint's value from the relative angle (revolute) or the slider coordinate
    (prismatic) it carries, calibrated at the configuration the equations were built at.
    The loops close there when ``values`` solve the equations."""
    mech, q0 = loops.mech, loops.q
    v0 = loops.values(q0)
    theta0 = loops.theta_q
    q = np.array(q0, float)
    slide_of = {j: t["x"].name for j, t in loops.slide_terms.items()}

    def angle(link: str, vals, th):
        r = loops.rep[link]
        name = f"theta{loops.numbers[r]}"
        if r == loops.topo.ground or name not in vals:
            return th[link]
        return vals[name] + wrap(th[link] - th[r])

    for j in loops.topo.joints:
        if j.cut or j.type not in LOWER:
            continue
        c = mech.coordinate(j.name)
        if j.type == "prismatic":
            name = slide_of.get(j.name)
            if name is None or name not in values:
                continue
            sigma = float(np.sign(loops._p2(j.direction) @ loops.slides[j.name]["u"]))
            delta = sigma * (values[name] - v0[name])
            q[c.idx_q] = q0[c.idx_q] + delta
            continue
        parent, child = j.links
        sign = float(np.sign(np.asarray(j.direction) @ loops.n))
        rel0 = angle(child, v0, theta0) - angle(parent, v0, theta0)
        rel = angle(child, values, theta0) - angle(parent, values, theta0)
        delta = sign * (wrap(rel - rel0) if not loops.pairs else rel - rel0)  # a rolling pair counts turns
        if c.nq == 2:
            set_continuous_angle(q, c.idx_q, float(continuous_angle(q0, c.idx_q)) + delta)
        else:
            q[c.idx_q] = q0[c.idx_q] + delta
    if loops.pairs:  # the virtual joints of the rolling pairs' equivalent linkages
        virtual_coordinates(loops, q, values, v0)
    return q
