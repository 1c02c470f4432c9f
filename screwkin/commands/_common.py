"""What several commands share: the configuration they analyse, from the options typed."""

from __future__ import annotations

from ..analysis.planar import LinkAngles
from ..analysis.position import PositionSolver
from ..errors import UsageError
from ..units import parse_assignments

__all__ = ["inputs", "configuration", "add_configuration_options", "add_angle_option"]


def add_angle_option(sp):
    """--set-angle: an input as a link's absolute angle (planar mechanisms)."""
    sp.add_argument("--set-angle", action="append", metavar="LINK=ANGLE",
                    help="planar mechanisms: an input given as the absolute angle of a link pinned to the "
                         "ground, from the ground's x axis (e.g. crank=45deg)")


def add_configuration_options(sp):
    """--set, --set-angle and --near: the configuration a command analyses (see configuration)."""
    sp.add_argument("--set", action="append", metavar="NAME=VALUE", help="input values of the configuration")
    add_angle_option(sp)
    sp.add_argument("--near", metavar="NAME=VALUE,...", help="assembly mode nearest this configuration")


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
