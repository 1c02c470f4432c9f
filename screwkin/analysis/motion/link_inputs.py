"""Inputs given as links' absolute angles in a planar mechanism (``--set-angle LINK=ANGLE``).

A link pivoted on the ground by a revolute joint has that joint's value as its angle, plus a constant
(planar.LinkAngles.joint_value).  Any other moving link's angle is still linear in the joint
coordinates: in a planar mechanism every revolute turns about the plane's normal, so the angle is
the sum of the signed revolute angles on its tree path from the ground (sign: the joint's axis .
the normal; prismatic joints on the path turn nothing) plus its angle at q = 0, measured as
planar.LinkAngles measures it (the line between joint centres, so that the value given is the one
``solve`` lists).  Holding it is one more linear closure row (model.cuts.CouplingRow of kind
"angle", modulo a turn), added to a copy of the mechanism (Mechanism.with_rows) for one solve.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...errors import UsageError
from ...model._pin import joint_axis
from ...model.cuts import CouplingRow
from ...model.state import KinematicState
from ..singular import Generic
from .planar import LinkAngles
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["angle_row", "holding_angles"]


def angle_row(angles: LinkAngles, link: str, angle: float) -> CouplingRow:
    """The closure row that holds ``link`` at the absolute angle ``angle`` [rad] (angles: the
    mechanism's LinkAngles): sum s_k q_k + theta(0) - angle = 0 modulo a turn, over the revolute
    joints on the link's path from the ground.  A usage error for the ground, an unknown link, a
    path through a joint of more than one coordinate, or a link that cannot turn."""
    angles.check(link)
    mech = angles.mech
    model = mech.model
    q0 = mech.neutral()
    state = KinematicState(mech, q0)
    terms, path, pairs = [], [], set()
    jid = model.frames[mech.link_frame(link)].parentJoint
    while jid != 0:
        joint, name = model.joints[jid], model.names[jid]
        short = joint.shortname()
        path.append(name)
        if short.startswith("JointModelR") and model.nvs[jid] == 1:
            s = float((state.joint_placement(jid).rotation @ joint_axis(joint)) @ angles.n)
            if abs(abs(s) - 1.0) > mech.tolerances.equal:
                raise UsageError(f"{mech.path}: joint '{name}' on the path of '{link}' from the ground does not turn "
                                 "about the plane's normal: its angle is not the sum of the joint angles")
            terms.append((int(model.idx_qs[jid]), int(model.idx_vs[jid]), float(np.sign(s))))
            if model.nqs[jid] == 2:  # a continuous joint: (cos, sin)
                pairs.add(int(model.idx_qs[jid]))
        elif not (short.startswith("JointModelP") and model.nvs[jid] == 1):
            raise UsageError(f"{mech.path}: joint '{name}' on the path of '{link}' from the ground is not a revolute "
                             "or prismatic joint of one coordinate: --set-angle cannot hold that link's angle")
        jid = model.parents[jid]
    if not terms:
        raise UsageError(f"{mech.path}: the angle of '{link}' is fixed (no revolute joint between it and the "
                         f"ground: {', '.join(reversed(path)) or 'none'})")
    path_sum = CouplingRow(f"angle of {link}", "angle", tuple(terms), 0.0, input=link, pairs=frozenset(pairs))
    theta0 = angles(q0, state)[link] - path_sum.value(q0)  # the link's angle at q0 less its joints' sum there
    return replace(path_sum, constant=float(theta0 - angle))


def holding_angles(mech: Mechanism, joints: list, angles: dict):
    """``mech`` with the links of ``angles`` (link -> absolute angle [rad]) held at those angles, for a
    solve whose input joints are ``joints``: Mechanism.with_rows of their angle rows.  A usage error
    when the mechanism is not planar, or a link's angle is fixed by the other inputs (its row adds no
    rank to the loops' passive columns: e.g. a link on the ground pivot of an input joint, or two
    links of one rigid assembly)."""
    configs = mech.generic_configurations()[1]
    la = LinkAngles(mech, mech.topology(configs[0]))
    rows = [angle_row(la, link, value) for link, value in angles.items()]
    before = Generic(mech, list(joints), configurations=configs).rank_Kp
    for k, link in enumerate(angles, 1):
        held = mech.with_rows(rows[:k])
        got = Generic(held, list(joints), configurations=configs).rank_Kp
        if got < before + k:
            others = [*joints, *list(angles)[:k - 1]]
            by = f"the other inputs ({', '.join(others)})" if others else "the loops (it does not turn as the mechanism moves)"
            raise UsageError(f"{mech.path}: the angle of '{link}' is fixed by {by}: give another link or joint")
    return mech.with_rows(rows)
