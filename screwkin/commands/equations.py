"""``screwkin equations``: the course-solution equations in symbols (vector loops, velocity and
acceleration matrices, det A and where it vanishes); and ``solve --start``: Newton on those
equations from a person's estimates, iteration by iteration."""

from __future__ import annotations

import sys

import numpy as np

from ..analysis.course.equations import VectorLoops, equations, newton
from ..errors import AssemblyError, UsageError
from ..model.geometry import wrap_angle
from ..present.jsonout import json_of
from ..present.equations import (
    Units,
    equations_dict,
    equations_text,
    greek,
    newton_dict,
    newton_text,
)
from ..present.report import position_dict, position_text
from ..units import parse_typed_assignments
from ._configuration import add_configuration_options, configuration, input_solver, with_mode
from ._values import split_inputs

NAME = "equations"
NEEDS_MECHANISM = True

_ANGLE_UNITS = {"deg", "degree", "degrees", "°"}


def add_parser(sub, common, scaled):
    sp = sub.add_parser(NAME, help="the loop equations in symbols: vector loops, velocity and acceleration "
                                   "matrices, det A and its singular conditions")
    common(sp)
    sp.add_argument("--input", action="append", metavar="NAME",
                    help="input joint (repeat or comma-separate; default: the --set joints, else the actuated ones)")
    add_configuration_options(sp)
    sp.add_argument("--output", help="spatial mechanisms: also the chain to this link")


def _input_names(mech, args, values, held):
    """The input joints: --input, else those set (``values``: --set, --set-angle of a link pinned to the
    ground), else -- unless a floating link's angle is given (``held``: an input of its own) -- the
    actuated ones."""
    names = [n.strip() for item in (args.input or []) for n in item.split(",") if n.strip()]
    if names:
        return names
    return list(values) or ([] if held else list(mech.actuated))


def run(mech, args) -> int:
    values, held, _ = split_inputs(mech, args)
    names = _input_names(mech, args, values, held)
    q = configuration(mech, args)
    res = equations(mech, q, names, output=args.output, links=list(held))
    if args.json:
        print(json_of(with_mode(args, equations_dict(res))))
    else:
        print(equations_text(res))
    return 0


# ------------------------------------------------------------------ solve --start
def _typed(items, option):
    """[(name, units.Quantity)] from NAME=VALUE items."""
    return parse_typed_assignments(items, option)


def _needed_joints(loops, name):
    """The tree joints whose values place the quantity ``name`` (the joints from the ground to the
    links it is measured on)."""
    mech = loops.mech
    model = mech.model
    info = loops.symbol_info[name]
    if info.kind == "angle":
        links = [info.link]
    else:
        joint = next(j for j, t in loops.slide_terms.items() if t["x"].name == name)
        links = [loops.slides[joint]["guide"], loops.slides[joint]["slider"]]
    out = set()
    for lk in links:
        jid = model.frames[mech.link_frame(lk)].parentJoint
        out |= {model.names[j] for j in model.supports[jid] if j > 0}
    return out


def start_estimates(mech, loops, solver, q_in, values, typed):
    """The estimates of every unknown of the loop equations from ``--start`` items (``_typed``):
    symbols, link names (their angles) or passive joint values (placed at q_in, the inputs set);
    returns (symbol -> estimate, symbol -> the units.Quantity typed)."""
    by_link = {}
    for n in loops.variables:
        info = loops.symbol_info[n]
        if info.kind == "angle":
            by_link[info.link] = n
    symbols, joints, units = {}, {}, {}
    joint_names = set(mech.coordinate_names)
    for name, typed_value in typed:
        v = typed_value.value
        if name in loops.input_joints or name in values:
            raise UsageError(f"{mech.path}: '{name}' is an input: give its value with --set")
        if name in loops.unknowns:
            symbols[name] = v
        elif name[-1:] in ("h", "v") and name[:-1] in loops.unknowns and loops.symbol_info[name[:-1]].kind == "slider":
            # the textbook's horizontal (h) or vertical (v) coordinate of the slider's centre, measured
            # from the same joint centre, for a guide on the ground: from + x u + e n, read along x or y
            guide = loops.ground_guide(name[:-1])
            if guide is None:
                raise UsageError(f"{mech.path}: --start {name}: the guide of {name[:-1]} turns with a link; give "
                                 f"{name[:-1]}, the distance along the guide")
            beta, e = guide
            c, s_ = (np.cos(beta), -np.sin(beta)) if name[-1] == "h" else (np.sin(beta), np.cos(beta))
            if abs(c) < mech.tolerances.geometry:
                other = "v" if name[-1] == "h" else "h"
                raise UsageError(f"{mech.path}: --start {name}: the guide of {name[:-1]} is "
                                 f"{'vertical' if name[-1] == 'h' else 'horizontal'}; give {name[:-1]}{other} or "
                                 f"{name[:-1]}")
            name = name[:-1]
            symbols[name] = (v - e * s_) / c
        elif name in by_link:
            symbols[by_link[name]] = v
            name = by_link[name]
        elif name in joint_names:
            joints[name] = v
            continue
        else:
            valid = ", ".join(list(loops.unknowns) + [lk for lk, n in by_link.items() if n in loops.unknowns])
            raise UsageError(f"{mech.path}: --start: no unknown, link or joint named '{name[:80]}' "
                             f"(unknowns of the loop equations: {valid}; or passive joint names)")
        units[name] = typed_value
    start = loops.values(solver.set_inputs(q_in, joints)) if joints else {}
    covered = set(symbols)
    if joints:
        given = set(joints) | set(values)
        covered |= {n for n in loops.unknowns if _needed_joints(loops, n) <= given}
    missing = [n for n in loops.unknowns if n not in covered]
    if missing:
        raise UsageError(f"{mech.path}: --start gives no estimate of {', '.join(missing)} "
                         f"(links {', '.join(loops.symbol_info[n].link for n in missing)})")
    start = {n: symbols.get(n, start.get(n)) for n in loops.unknowns}
    return start, units


def _solved_near(mech, loops, solver, values, q, res, starts, skip=()):
    """solve's configuration near q (Newton's root), the loop symbols there, and the unknowns
    in which it differs from Newton's root."""
    near = {n: v for n, v in mech.joint_values(q).items() if n not in skip}
    pres = solver.solve(values, near=near, starts=starts)
    got = loops.values(pres.solutions[0].q)
    return pres, got, differing(mech, loops, got, res.values)


def differing(mech, loops, a: dict, b: dict) -> list:
    """The unknowns of ``loops`` whose values in ``a`` and ``b`` (symbol -> value) differ: an angle by
    more than the geometry tolerance modulo a turn, a length by more than it times max(L, 1 m)."""
    tol = mech.tolerances.geometry * max(mech.length, 1.0)
    return [n for n in loops.unknowns
            if abs(wrap_angle(a[n] - b[n]) if loops.symbol_info[n].kind == "angle" else a[n] - b[n]) > tol]


def solve_from_start(mech, args, values, held=None) -> int:
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
    typed = _typed(args.start, "--start")
    start, units = start_estimates(mech, loops, solver, q_in, {**values, **held}, typed)
    input_values = loops.values(q_in)
    given = {n: held.get(loops.input_joints[n][0], input_values[n]) for n in loops.input_syms}
    res = newton(loops, given, start, args.iterations)

    # (--set and --set-angle read again: solve's split_inputs keeps their values, not their units)
    degrees = any(q.unit in _ANGLE_UNITS
                  for _, q in typed + _typed(args.set, "--set") + _typed(args.set_angle, "--set-angle"))
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
