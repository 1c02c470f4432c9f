"""What several commands share: the configuration they analyse, from the options typed."""

from __future__ import annotations

from ..analysis.planar import LinkAngles
from ..analysis.position import PositionSolver
from ..errors import UsageError
from ..units import parse_assignments

__all__ = ["inputs", "configuration"]


def inputs(mech, args) -> dict:
    """Input values from --set (joint values) and --set-angle (absolute link angles)."""

    values = parse_assignments(getattr(args, "set", None), "--set")
    angles = parse_assignments(getattr(args, "set_angle", None), "--set-angle")
    if angles:
        q = mech.generic_configurations()[1][0]
        link_angles = LinkAngles(mech, mech.topology(q))
        for link, angle in angles.items():
            joint, value = link_angles.joint_value(link, angle)
            if joint in values:
                raise UsageError(f"joint '{joint}' is given twice (--set and --set-angle {link})")
            values[joint] = value
    return values


def configuration(mech, args):
    """The configuration a command analyses: solved for --set values, else the assembled file one."""

    values = inputs(mech, args)
    near = parse_assignments([args.near], "--near") if getattr(args, "near", None) else None
    if not values:
        return mech.generic_configurations()[0].q
    res = PositionSolver(mech, list(values)).solve(values, near=near)
    return res.solutions[0].q
