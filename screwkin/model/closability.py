"""Why a mechanism cannot assemble, said in its own lengths: a loop of revolutes with parallel axes (a
four-bar, a planar n-bar) closes only when no side is longer than the others together."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ._pin import joint_axis

__all__ = ["closure_obstacle"]


def closure_obstacle(mech) -> str | None:
    """Why a loop of revolute joints with parallel axes (a four-bar, a planar n-bar) cannot close,
    in its links' lengths: its longest side is longer than the others together ("ground 0.2 m >
    crank + coupler + rocker = 0.18 m"); None when no such loop is found too long.  The sides are
    the distances between consecutive joint axes on each link, fixed by the file."""
    model, data = mech.model, mech.scratch_data()
    pin.framesForwardKinematics(model, data, mech.neutral())
    for c in mech.cuts:
        if c.type not in ("revolute", "continuous") or c.pair:
            continue
        j1, j2 = (model.frames[f].parentJoint for f in (c.frame1, c.frame2))
        s1, s2 = list(model.supports[j1]), list(model.supports[j2])
        common = [j for j in s1 if j in s2]
        path1 = [j for j in reversed(s1) if j not in common]  # from link1's joint towards the root
        path2 = [j for j in s2 if j not in common]  # from the root towards link2's joint
        joints = path1 + path2
        if not joints or any(not model.joints[j].shortname().startswith("JointModelR") for j in joints):
            continue
        axis = data.oMf[c.frame1].rotation @ np.asarray(c.axis, float)
        axes = [data.oMi[j].rotation @ joint_axis(model.joints[j]) for j in joints]
        if any(np.linalg.norm(np.cross(axis, a)) > mech.tolerances.geometry for a in axes):
            continue  # not planar: no side-length test
        n = axis / np.linalg.norm(axis)

        def flat(p):
            return p - (p @ n) * n

        points = [flat(data.oMf[c.frame1].translation)] + [flat(data.oMi[j].translation) for j in joints]
        points.append(flat(data.oMf[c.frame2].translation))
        names = [_link_of_joint(mech, j) for j in path1]
        ground = _link_of_joint(mech, common[-1]) if common and common[-1] > 0 else mech.spec.root
        names = names + [ground] + [_link_of_joint(mech, j) for j in path2]
        sides = [float(np.linalg.norm(points[k + 1] - points[k])) for k in range(len(points) - 1)]
        if len(sides) != len(names):
            continue
        longest = int(np.argmax(sides))
        others = sum(sides) - sides[longest]
        if sides[longest] > others + mech.tolerances.geometry:
            rest = " + ".join(nm for k, nm in enumerate(names) if k != longest)
            return (f"loop {c.name} cannot close, {names[longest]} {sides[longest]:.6g} m > {rest} = "
                    f"{others:.6g} m (no side of a closed loop is longer than the others together)")
    return None


def _link_of_joint(mech, jid: int) -> str:
    """The link a tree joint carries (its child body's link)."""
    return next((f.name for f in mech.model.frames if f.parentJoint == jid and f.type == pin.FrameType.BODY),
                mech.model.names[jid])
