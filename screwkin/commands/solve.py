"""screwkin solve: position, velocity and acceleration for given input values."""

from __future__ import annotations


from ..errors import UsageError
from ..present.jsonout import json_of
from ..present.report import (
    position_dict,
    position_text,
    trace_text,
)
from ..present.tables import RateUnits
from ..units import parse_typed_assignments
from . import equations as equations_command
from ._configuration import add_angle_option, add_length_option, input_solver, near_values
from ._output_frame import add_point_option, named_points
from ._values import check_rate_names, joint_quantities, link_rates, rate_items, split_inputs
from ._options import count

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "solve"
NEEDS_MECHANISM = True


def add_parser(sub, common, scaled):
    sp = sub.add_parser("solve", help="position, velocity and acceleration for given input values")
    common(sp)
    sp.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="input joint value, SI or with a unit (45deg, 30mm); repeat or comma-separate")
    add_angle_option(sp)
    add_length_option(sp)
    sp.add_argument("--all", action="store_true",
                   help="show every assembly mode, also those the mechanism cannot reach by moving")
    sp.add_argument("--near", metavar="NAME=VALUE,...", help="report only the assembly mode nearest this configuration")
    sp.add_argument("--output", help="link whose pose (and twist) to report")
    add_point_option(sp)
    sp.add_argument("--rate", action="append", metavar="NAME=VALUE",
                    help="input joint rate [1/s] (units: 120rpm, 90deg/s, 5mm/s; a bare value where there is one input)")
    sp.add_argument("--accel", action="append", metavar="NAME=VALUE",
                    help="input joint acceleration [1/s^2] (units: 10deg/s^2; a bare value where there is one input)")
    sp.add_argument("--trace", action="store_true", help="print the Newton iterations (residual, Jacobian, step)")
    sp.add_argument("--starts", type=count("starts"), default=24, help="random starting configurations (default 24)")
    sp.add_argument("--start", action="append", metavar="NAME=VALUE,...",
                   help="planar: Newton on the vector-loop equations (screwkin equations) from these estimates of "
                        "the unknowns: symbols (theta3, x4), link names (their angles) or passive joint values")
    sp.add_argument("--iterations", type=count("iterations"), metavar="K",
                   help="with --start: exactly K Newton iterations, each printed (residual, Jacobian, step, "
                        "estimates); without it Newton goes on to convergence")
    scaled(sp, point=False)


def run(mech, args) -> int:
    values, held, pivots = split_inputs(mech, args)
    if not values and not held:
        raise UsageError("solve needs input values: --set NAME=VALUE, --set-angle LINK=ANGLE or --set-length LEG=LENGTH")
    near = near_values(mech, args)
    args.rate, args.accel = (rate_items(getattr(args, o), [*values, *held], f"--{o}") or None for o in ("rate", "accel"))
    typed = {o: joint_quantities(mech, getattr(args, o), f"--{o}", order=k, links=(*held, *pivots))
             for k, o in ((1, "rate"), (2, "accel"))}  # the tables answer in the units typed
    rates = {n: q.value for n, q in typed["rate"].items()} if args.rate or args.accel else None
    accels = {n: q.value for n, q in typed["accel"].items()} if args.accel else None
    rates, accels = link_rates(rates, pivots, "--rate"), link_rates(accels, pivots, "--accel")
    for given, option in ((rates, "--rate"), (accels, "--accel")):  # a link's rate goes with its --set-angle
        check_rate_names(given, [*values, *held], option)
    if args.starts < 0:
        raise UsageError("--starts must be 0 or more")
    if args.start or args.iterations is not None:
        return equations_command.solve_from_start(mech, args, values, held)
    solver = input_solver(mech, values, held, output=args.output)
    res = solver.solve(values, near=near, rates=rates, accels=accels, starts=args.starts, trace=args.trace,
                       points=named_points(mech, args))
    if args.json:
        d = position_dict(res)
        d["characteristic_length"] = mech.length
        print(json_of(d))
        return 0
    if args.trace:
        names = [mech.coordinate_names[k] for k in solver.passive]
        print(trace_text(res, solver.mech.closure.row_labels(solver=True), names))
        print()
    legs = {n: q.value for n, q in parse_typed_assignments(args.set_length, "--set-length")} if args.set_length \
        else None
    units = RateUnits.typed(typed["rate"].values(), typed["accel"].values())
    print(position_text(res, show_all=args.all, length=mech.length, units=units, leg_lengths=legs))
    return 0
