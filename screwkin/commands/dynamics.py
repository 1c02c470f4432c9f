"""``screwkin dynamics``: the efforts, joint reactions, shaking forces, kinetic energy and flywheel of
a mechanism driven at constant input speed (inverse dynamics of the closed chain)."""

from __future__ import annotations

import math
import os

from ..analysis.forces.dynamics import CS_RANGE, Load, dynamics
from ..errors import UsageError, quote
from ..present.jsonout import json_of
from ..present.outfile import write_output
from ..present.dynamics import dynamics_csv, dynamics_dict, dynamics_plot, dynamics_text
from ..present.progress import EVERY, Progress
from ..units import parse_value
from ..analysis.motion.sweep import sweep_inputs
from ._configuration import add_branch_option, add_mode_option, configuration, moved_not_set, near_values, with_mode
from ._output_frame import named_points
from ._values import joint_assignments, joint_value, names_list, rate_items, value_kind
from ._options import count
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "dynamics"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser(NAME, help="input efforts, joint reactions, shaking forces and flywheel at constant input speed")
    common(sp)
    sp.add_argument("--input", required=True, help="the input joint driven at constant speed")
    sp.add_argument("--speed", required=True, metavar="[NAME=]VALUE",
                    help="its constant speed, as every --rate: 60rpm or NAME=60rpm (90deg/s, 2rad/s, 50mm/s; SI bare)")
    sp.add_argument("--from", dest="start", help="first input value (default 0 for a turning input)")
    sp.add_argument("--to", dest="stop", help="last input value (default 360deg for a turning input)")
    sp.add_argument("--steps", type=count("dynamics_steps"), default=72,
                    help="number of steps (default 72, at most 10,000)")
    sp.add_argument("--set", action="append", metavar="NAME=VALUE", help="values of the other inputs")
    sp.add_argument("--inputs", help="input joints, comma separated (default: the actuated joints)")
    sp.add_argument("--near", metavar="NAME=VALUE,...", help="start on the assembly mode nearest this configuration")
    add_mode_option(sp, "the inputs at --from")
    add_branch_option(sp)
    sp.add_argument("--gravity", metavar="GX,GY,GZ",
                    help="gravity [m/s^2] in world axes, e.g. 0,0,-9.81 (default: none)")
    sp.add_argument("--load", action="append", metavar="LINK:FX,FY,FZ,MX,MY,MZ",
                    help="a constant wrench on a link at its frame's origin (or on a --point by its name), "
                         "force [N] and moment [N*m] in world axes, units allowed (10N, 2kN, 0.5Nm); repeatable")
    sp.set_defaults(point=False)
    sp.add_argument("--point", action="append", dest="points", metavar="NAME=LINK:x,y,z",
                    help="a named point on a link, in the link's frame (units allowed: P=coupler:60mm,20mm,0), for "
                         "--load NAME:...; repeatable")
    sp.add_argument("--cs", default="0.05",
                    help="coefficient of speed fluctuation of the flywheel figure, 0.0001 to 0.5 (default 0.05)")
    sp.add_argument("--csv", help="write the efforts, energies, shaking wrench and reactions per step to this CSV file")
    sp.add_argument("--plot", help="draw the input effort against the input into this PNG file (needs matplotlib)")


def _gravity(text: str) -> tuple:
    if text is None:
        return (0.0, 0.0, 0.0)
    parts = [p for p in text.replace(" ", ",").split(",") if p.strip()]
    if len(parts) != 3:
        raise UsageError(f"--gravity expects GX,GY,GZ, got {quote(text, 60)}")
    return tuple(parse_value(p, "linear acceleration", "--gravity") for p in parts)


def _loads(mech: Mechanism, items: list | None, points: tuple) -> tuple:
    by_name = {p.name: p for p in points}
    out = []
    for text in items or []:
        target, sep, rest = text.rpartition(":")
        parts = [p for p in rest.replace(" ", ",").split(",") if p.strip()]
        if not sep or not target.strip() or len(parts) != 6:
            raise UsageError(f"--load expects LINK:FX,FY,FZ,MX,MY,MZ (6 numbers), got {quote(text, 80)}")
        target = target.strip()
        wrench = tuple(parse_value(p, "force" if k < 3 else "moment", "--load") for k, p in enumerate(parts))
        if target in by_name:
            p = by_name[target]
            out.append(Load(p.link, wrench, tuple(p.local), p.name))
        else:
            mech.link_frame(target)  # a clear error for an unknown link
            out.append(Load(target, wrench))
    return tuple(out)


def _cs(text: str) -> float:
    try:
        cs = float(text)
    except ValueError:
        raise UsageError(f"--cs expects a number, got {quote(text, 40)}") from None
    lo, hi = CS_RANGE
    if not lo <= cs <= hi:  # nan fails both
        raise UsageError(f"--cs must lie between {lo:g} and {hi:g} (machines ask for 0.002 to 0.2; default 0.05), "
                         f"got {quote(text, 40)}")
    return cs


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    fixed = joint_assignments(mech, args.set, "--set")
    moved_not_set(fixed, args.input, "dynamics drives it from --from to --to")
    inputs = names_list(args.inputs) or None
    near = near_values(mech, args)
    kind = value_kind(mech, args.input)
    if kind is None:
        mech.coordinate(args.input)  # a clear error for an unknown joint
        raise UsageError(f"--input {quote(args.input)}: dynamics drives a one-coordinate joint (revolute, prismatic)")
    # the grammar of every --rate: NAME=VALUE, or the bare value of the one input driven
    name, _, args.speed = rate_items(args.speed, [args.input], "--speed")[0].rpartition("=")
    if name.strip() != args.input:
        raise UsageError(f"--speed {quote(name.strip(), 60)}=...: dynamics drives --input {quote(args.input, 60)} only")
    speed = joint_value(mech, args.input, args.speed, "--speed", order=1).value
    typed = [joint_value(mech, args.input, text, option) for text, option in ((args.start, "--from"),
                                                                              (args.stop, "--to")) if text is not None]
    if kind == "length" and len(typed) < 2:
        raise UsageError(f"--input {quote(args.input)} slides: give its range with --from and --to")
    start = 0.0 if args.start is None else typed[0].value
    stop = start + 2 * math.pi if args.stop is None else typed[-1].value
    # the input shown in the unit typed (the first --from/--to with a unit; SI when typed bare), degrees when
    # no range is typed
    units = [q.shown_unit for q in typed if q.unit]
    shown = units[0] if units else ("deg" if kind == "angle" and not typed else None)
    points = named_points(mech, args)
    loads, cs, gravity = _loads(mech, args.load, points), _cs(args.cs), _gravity(args.gravity)
    # the mode (--mode K), chosen and said once dynamics has checked the file and the options
    mode = lambda: configuration(mech, args, moved={args.input: start},  # noqa: E731
                                 inputs=inputs or sweep_inputs(mech, args.input, fixed))
    with Progress(label="dynamics", unit="configurations", every=EVERY) as progress:  # on a terminal only
        res = dynamics(mech, args.input, speed, start, stop, args.steps, inputs=inputs, fixed=fixed, near=near,
                       gravity=gravity, loads=loads, cs=cs, progress=progress, q_start=mode, branch=args.branch)
    if args.csv:
        write_output(args.csv, dynamics_csv(res, shown))
    if args.plot:
        dynamics_plot(res, args.plot, shown, title=f"{os.path.basename(mech.path)}: {args.input} at {args.speed}")
    if args.json:
        print(json_of(with_mode(args, dynamics_dict(res))))
    else:
        print(dynamics_text(res, shown, args.speed))
    return 0
