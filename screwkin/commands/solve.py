"""``screwkin solve``: position, velocity and acceleration for given input values; with ``--start``,
Newton on the vector-loop equations (screwkin equations) from a person's estimates, iteration by
iteration."""

from __future__ import annotations

import sys

from ..analysis.course.newton import differing, start_estimates, textbook_newton
from ..analysis.course.vector_loops import VectorLoops
from ..errors import AssemblyError, UsageError
from ..present.equations import Units, greek, newton_dict, newton_text
from ..analysis.singularities.mode_connect import Connections, connect_modes
from ..present.animate import animate_connection, animation_format
from ..present.jsonout import json_of
from ..present.loci import connections_dict, connections_lines
from ..present.report import (
    position_dict,
    position_text,
    trace_text,
)
from ..present.tables import RateUnits
from ..units import parse_typed_assignments
from ._configuration import add_angle_option, add_length_option, input_solver, near_values
from ._output_frame import add_point_option, named_points
from ._values import check_rate_names, joint_quantities, link_rates, rate_items, split_inputs
from ._options import count
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    import numpy as np
    from collections.abc import Callable
    from screwkin.analysis.course.newton import NewtonResult
    from screwkin.analysis.position.position import PositionSolver

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "solve"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser("solve", help="position, velocity and acceleration for given input values")
    common(sp)
    sp.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="input joint value, SI or with a unit (45deg, 30mm); repeat or comma-separate")
    add_angle_option(sp)
    add_length_option(sp)
    sp.add_argument("--all", action="store_true",
                   help="search every assembly mode (homotopy continuation, certified where it can be, where no "
                        "closed form lists them) and show them all, also those the mechanism cannot reach by "
                        "moving; without it, such a mechanism answers at once the mode Newton reaches from the "
                        "file's configuration")
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
                        "the unknowns: symbols (theta3 or θ3 as equations writes it, x4), link names (their angles) or "
                        "passive joint values")
    sp.add_argument("--iterations", type=count("iterations"), metavar="K",
                   help="with --start: exactly K Newton iterations, each printed (residual, Jacobian, step, "
                        "estimates); without it Newton goes on to convergence")
    sp.add_argument("--connect", action="store_true",
                    help="with --all: for each pair of the modes listed, whether a path joins them without a singularity "
                         "(det J's sign; a loop of two inputs round a cusp of the actuator singular curve), the path or why not")
    sp.add_argument("--animate", metavar="OUT.gif|OUT.mp4",
                    help="with --connect: write an animation of the first path that joins two modes")
    scaled(sp, point=False)


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    values, held, pivots = split_inputs(mech, args)
    if not values and not held:
        solver = input_solver(mech, [], output=args.output)
        raise UsageError(f"{mech.path}: solve needs input values: --set NAME=VALUE, --set-angle LINK=ANGLE or "
                         f"--set-length LEG=LENGTH (its inputs, at the file's values: {solver.file_values_hint()})")
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
    if (args.connect or args.animate) and not args.all:
        raise UsageError("--connect needs --all: it compares the modes --all lists"
                         if args.connect else "--animate needs --all --connect: it animates a path between two modes")
    if args.animate and not args.connect:
        raise UsageError("--animate needs --connect: it animates a path between two modes")
    if args.connect and (held or pivots or args.start or args.iterations is not None or args.near):
        raise UsageError("--connect compares the modes of --set (and --set-length) inputs; leave out --set-angle, "
                         "--start, --iterations and --near")
    if args.animate:
        animation_format(args.animate)  # checked before the work
    if args.start or args.iterations is not None:
        return _solve_from_start(mech, args, values, held)
    solver = input_solver(mech, values, held, output=args.output)
    res = solver.solve(values, near=near, rates=rates, accels=accels, starts=args.starts, trace=args.trace,
                       points=named_points(mech, args), method="auto" if args.all else "nearest")
    conns = None
    if args.connect:
        conns = connect_modes(solver, values, [s.q for s in res.solutions]) if not res.free_dofs else Connections(
            (), (), "not compared: the inputs leave a continuum of configurations (the solutions listed are samples)")
    animated = _animate_first_joined(mech, args, conns, values) if args.animate else None
    if args.json:
        d = position_dict(res)
        d["characteristic_length"] = mech.length
        if conns is not None:
            d.update(connections_dict(conns, mech, solver.output_frame))
        if args.animate:
            d["animation"] = {k: v for k, v in animated.items() if k != "said"}
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
    if conns is not None:
        print()
        print("\n".join(connections_lines(conns)))
    if args.animate:
        print(animated["said"])
    return 0


def _animate_first_joined(mech: Mechanism, args: argparse.Namespace, conns, values: dict) -> dict:
    """solve --connect --animate OUT: the skeleton along the first path that joins two modes (drawn as draw
    --connect I:J --animate draws it: present.animate.animate_connection)."""
    c = next((c for c in conns.connections if c.joined), None)
    if c is None:
        return {"file": None, "modes": None, "frames": 0, "said": f"--animate: no path joins two modes; {args.animate} not written"}
    i, j = c.modes[0] + 1, c.modes[1] + 1
    units = {n: q.shown_unit for n, q in joint_quantities(mech, args.set, "--set").items()}
    n = animate_connection(args.animate, mech, c, list(values), units, named_points(mech, args))
    return {"file": args.animate, "modes": [i, j], "frames": n,
            "said": f"wrote {args.animate}: the path from mode {i} to mode {j}, {n} frames (the first joined pair; "
                    f"draw --connect I:J --animate for another)"}


# ------------------------------------------------------------------ solve --start
def _solved_near(mech: Mechanism, loops: VectorLoops, solver: PositionSolver, values: dict, q: np.ndarray, res: NewtonResult, starts: int, skip: set | tuple = ()) -> tuple:
    """solve's configuration near q (Newton's root), the loop symbols there, and the unknowns
    in which it differs from Newton's root."""
    near = {n: v for n, v in mech.joint_values(q).items() if n not in skip}
    pres = solver.solve(values, near=near, starts=starts)
    got = loops.values(pres.solutions[0].q)
    return pres, got, differing(mech, loops, got, res.values)


def _solve_from_start(mech: Mechanism, args: argparse.Namespace, values: dict, held: dict | None=None) -> int:
    """``solve --start ...``: Newton on the loop equations from the estimates typed.  ``held``: links
    whose absolute angle is given (--set-angle of a floating link) -> angle [rad], known in the equations."""
    held = dict(held or {})
    if args.iterations is not None and args.iterations < 1:
        raise UsageError("--iterations must be 1 or more")
    if not args.start:
        raise UsageError("--iterations needs --start NAME=VALUE,... (the estimates to iterate from)")
    q_ref = mech.generic_configurations()[0].q
    loops = VectorLoops(mech, q_ref, list(values), links=list(held))
    solver = input_solver(mech, values, held)
    q_in = solver.set_inputs(q_ref, values)
    typed = parse_typed_assignments(args.start, "--start")
    start, units = start_estimates(mech, loops, solver, q_in, {**values, **held}, typed)
    input_values = loops.values(q_in)
    given = {n: held.get(loops.input_joints[n][0], input_values[n]) for n in loops.input_syms}
    res = textbook_newton(loops, given, start, args.iterations)

    # (--set and --set-angle read again: solve's split_inputs keeps their values, not their units)
    degrees = any(q.kind == "angle" and q.shown_unit == "deg" for _, q in typed + parse_typed_assignments(args.set, "--set")
                  + parse_typed_assignments(args.set_angle, "--set-angle"))
    lengths = {n: q.shown_unit for n, q in units.items() if q.kind == "length" and loops.symbol_info[n].kind != "angle"}
    show = Units(degrees, lengths)
    trace_wanted = args.trace or args.iterations is not None
    if args.iterations is not None or not res.closes:
        if args.json:
            print(json_of({"file": mech.path, **newton_dict(res)}))
        else:
            print(newton_text(res, loops.symbol_info, show, mech.path))
        if args.iterations is None:  # asked to converge and it did not: an error, not a result
            raise AssemblyError(mech.path, res.residual, len(res.steps),
                                detail="Newton from the given estimates did not converge"
                                       + (f": {res.stopped}" if res.stopped else ""))
        return 0
    # converged: the configuration it reached, closed and reported as solve reports it
    q = loops.configuration({**given, **res.values})
    pres, got, far = _solved_near(mech, loops, solver, values, q, res, args.starts)
    if far and loops.pairs:  # the solver turns a pair's virtual joints on by the input's whole turns: near without them
        virtual = {n for names in mech.virtual_joints.values() for n in names}
        print(f"note: solve's configuration near Newton's root differs in {', '.join(far)}; solved again near it "
              "without the rolling pairs' virtual joints", file=sys.stderr)
        pres, got, far = _solved_near(mech, loops, solver, values, q, res, args.starts, skip=virtual)
    if far and loops.pairs:  # solve placed the gears otherwise (its count of a pair's turns): say so, no table
        raise AssemblyError(mech.path, res.residual, len(res.steps),
                            detail="Newton's root closes the loop equations (" + ", ".join(
                                f"{n} = {res.values[n]:.6g}" for n in far) + ") but solve's configuration at these "
                            "inputs has " + ", ".join(f"{n} = {got[n]:.6g}" for n in far) + ": it counts a rolling "
                            "pair's turns otherwise (give --iterations K to see Newton's steps alone)")
    if far:  # pragma: no cover - the polished configuration left Newton's root
        raise AssemblyError(mech.path, res.residual, len(res.steps),
                            detail=f"the configuration of Newton's root does not close as solved ({', '.join(far)})")
    if args.json:
        d = position_dict(pres)
        d["characteristic_length"] = mech.length
        d["newton"] = newton_dict(res)
        d["trace"] = d["newton"]["trace"]
        print(json_of(d))
        return 0
    if trace_wanted:
        print(newton_text(res, loops.symbol_info, show, mech.path))
        print()
    else:
        print(f"Newton on the vector-loop equations from the estimates given: {len(res.steps)} iterations to "
              f"|F| = {res.residual:.3g} m: " + ", ".join(
                  f"{greek(n)} = {show.value(n, loops.symbol_info[n].kind, v)}" for n, v in res.values.items()))
        print()
    print(position_text(pres, show_all=True, length=mech.length))
    return 0
