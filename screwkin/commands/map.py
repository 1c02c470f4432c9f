"""screwkin map: map of the smallest singular value over two inputs."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..analysis.position.connect import cusp_loops
from ..analysis.motion.continuation import continuation_steps
from ..analysis.position.position import PositionSolver
from ..analysis.singularities.loci import trace_loci
from ..analysis.singularities.maps import first_assembled, singularity_map
from ..analysis.singularities.regions import regions
from ..analysis.singularities.section import trace_section
from ..errors import UsageError, quote
from ..present.jsonout import json_of
from ..units import in_unit, parse_quantity
from ..present.loci import loci_dict, loci_lines, loci_png
from ..present.outfile import write_output
from ..present.plots import map_png
from ..present.report import map_csv, map_dict
from ._configuration import add_mode_option, configuration, with_mode
from ._options import BOUNDS, count
from ._output_frame import output_frame
from ._values import joint_assignments, parse_range
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "map"
NEEDS_MECHANISM = True
COORDINATES = ("x", "y", "z")  # --x x=A:B:N: the output origin's world coordinates (a workspace section)


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser("map", help="map of the smallest singular value over two inputs")
    common(sp)
    sp.add_argument("--x", required=True, metavar="NAME=A:B:N",
                    help="first input, from A to B in N values; x, y or z (not a joint's name) with --output and "
                         "--loci: a section of the output origin's workspace")
    sp.add_argument("--y", required=True, metavar="NAME=A:B:N", help="second input (or coordinate)")
    sp.add_argument("--set", action="append", metavar="NAME=VALUE",
                    help="values of the other inputs (a section: the held coordinate, y=0 by default, and joints)")
    add_mode_option(sp, "the inputs at the map's first corner (the first values of --x and --y)")
    sp.add_argument("--output", help="output link (serial singularities)")
    sp.add_argument("--png", help="heat map with the singular curves, PNG (needs matplotlib)")
    sp.add_argument("--csv", help="the map's data as CSV")
    sp.add_argument("--loci", action="store_true",
                    help="trace the singular curves over every assembly mode (actuator; serial with --output), "
                         "their cusps and crossings, and the regions they cut the box into with their numbers "
                         "of assembly modes (with --png: their picture instead of the heat map)")
    sp.add_argument("--connect", action="store_true",
                    help="with --loci: follow every mode at a point inside each cusp's wedge once round the cusp, "
                         "each way, and list the loops that end on another mode without meeting a singularity")
    sp.add_argument("--no-regions", dest="regions", action="store_false",
                    help="with --loci: leave out the regions and their mode counts (an all-modes solve each)")
    scaled(sp)


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    joints = {c.joint for c in mech.coordinates}
    named = [t.partition("=")[0].strip() for t in (args.x, args.y)]
    if any(n in COORDINATES and n not in joints for n in named):  # a joint named x is the joint
        return _section(mech, args, named, joints)
    xn, xs, x_unit = parse_range(args.x, "--x", mech)
    yn, ys, y_unit = parse_range(args.y, "--y", mech)
    if xs.size * ys.size > BOUNDS["grid_total"][1]:
        raise UsageError(f"--x and --y: {xs.size:,} x {ys.size:,} = {xs.size * ys.size:,} configurations, "
                         f"at most {BOUNDS['grid_total'][1]:,}")
    # each grid value is reached from a neighbour by continuation steps of at most Tolerances.max_step: a grid
    # whose neighbours are far apart (--x motor1=0:1e5rad:3) costs that many steps per point, bounded too
    per_point = max(continuation_steps(mech, n, v[1] - v[0]) if v.size > 1 and n in {c.joint for c in mech.coordinates}
                    else 1 for n, v in ((xn, xs), (yn, ys)))
    if xs.size * ys.size * per_point > BOUNDS["grid_total"][1]:
        raise UsageError(f"--x and --y: neighbouring values this far apart take {per_point:,} continuation steps each "
                         f"({xs.size * ys.size * per_point:,} in all, at most {BOUNDS['grid_total'][1]:,}): give a "
                         "smaller range or more values")
    fixed = joint_assignments(mech, args.set, "--set")
    inputs = list(mech.actuated) if {xn, yn} <= set(mech.actuated) else [xn, yn, *fixed]
    output, point = output_frame(mech, args)  # a named --point is the output
    if point and not output:
        raise UsageError("--point needs --output LINK")
    # the mode mapped (--mode K), chosen and said once singularity_map has checked the inputs: at the first corner,
    # else at the first of the box's centre, other corners and edge midpoints where something assembles

    def mode() -> tuple:
        return first_assembled(len(xs), len(ys), lambda j, i: configuration(
            mech, args, moved={xn: float(xs[i]), yn: float(ys[j])}, inputs=inputs))
    res = singularity_map(PositionSolver(mech, inputs), xn, xs, yn, ys, fixed, output, point, q_start=mode)
    if args.connect and not args.loci:
        raise UsageError("--connect needs --loci: the loops go round the cusps of the traced loci")
    traced = _loci(mech, args, inputs, xn, xs, yn, ys, fixed, output, point) if args.loci else None
    if traced is not None and args.png:
        title = f"{mech.spec.name or Path(mech.path).stem}: singular loci over {xn} and {yn}"
        loci_png(*traced[:2], args.png, xs, ys, xn, yn, x_unit, y_unit, title=title)
    elif args.png:
        title = f"{mech.spec.name or Path(mech.path).stem}: singularity map over {xn} and {yn}"
        map_png(res, args.png, x_unit, y_unit, title=title)
    if args.csv:
        write_output(args.csv, map_csv(res))
    if args.json:
        extra = loci_dict(*traced[:2], x_unit, y_unit, traced[2], mech) if traced is not None else {}
        print(json_of(with_mode(args, {**map_dict(res), "characteristic_length": mech.length, **extra})))
    else:
        finite = res.log_sigma[np.isfinite(res.log_sigma)]
        print(f"map of {xn} x {yn}: {res.log_sigma.size} points, {finite.size} on the mapped assembly mode; "
              f"log10 sigma_min from {finite.min():.3g} to {finite.max():.3g} (L = {mech.length:.4g} m)"
              if finite.size else "no point assembled")
        for note in res.notes:
            print(note)
        if traced is not None:
            for line in loci_lines(*traced[:2], xn, yn, x_unit, y_unit, traced[2]):
                print(line)
    return 0


def _loci(mech: Mechanism, args: argparse.Namespace, inputs: list[str], xn: str, xs: np.ndarray, yn: str, ys: np.ndarray, fixed: dict, output: str | None, point: bool) -> tuple:
    """(Loci, Regions or None, (cusp loops, tried) or None) of map --loci: every input other than --x and
    --y held by --set."""
    held = [n for n in inputs if n not in (xn, yn)]
    missing = [n for n in held if n not in fixed]
    if missing:
        raise UsageError(f"--loci: give the other inputs with --set ({', '.join(missing)}): the loci lie in the "
                         "plane of --x and --y with the others held")
    solver = PositionSolver(mech, inputs)
    held_values = {n: fixed[n] for n in held}
    traced = trace_loci(solver, xn, xs, yn, ys, held_values, output, point)
    cut = regions(solver, traced, xn, xs, yn, ys, held_values) if args.regions else None
    box = ((float(min(xs[0], xs[-1])), float(max(xs[0], xs[-1]))), (float(min(ys[0], ys[-1])), float(max(ys[0], ys[-1]))))
    loops = cusp_loops(solver, traced, xn, yn, held_values, box) if args.connect else None
    return traced, cut, loops



def _section(mech: Mechanism, args: argparse.Namespace, named: list, joints: set) -> int:
    """map --x x=A:B:N --y z=A:B:N --output LINK --loci: the serial singular curves of the output origin in a
    section of its workspace (the third coordinate held), their cusps and nodes, the regions with their
    numbers of real IK solutions, and whether the robot is cuspidal (analysis.singularities.section)."""
    if not all(n in COORDINATES and n not in joints for n in named) or named[0] == named[1]:
        raise UsageError(f"--x {quote(named[0], 40)} and --y {quote(named[1], 40)}: a workspace section takes two "
                         "different coordinates of x, y, z (a map over inputs two joints)")
    output, _ = output_frame(mech, args)
    if not output:
        raise UsageError("--x/--y x, y or z map a section of the workspace of a point: give --output LINK")
    if not args.loci:
        raise UsageError("a workspace section is mapped with --loci (its singular curves, cusps and regions)")
    if args.connect:
        raise UsageError("--connect goes round the cusps of a map over inputs, not of a workspace section")
    if args.csv:
        raise UsageError("--csv writes the map of sigma_min over inputs; a workspace section's answer is --json")
    if args.mode is not None:
        raise UsageError("--mode picks an assembly mode of a map over inputs; a workspace section counts every "
                         "inverse-kinematic solution of each point")
    ranges = []
    for text, option in ((args.x, "--x"), (args.y, "--y")):
        name, _, rest = text.partition("=")
        parts = rest.split(":")
        if len(parts) != 3:
            raise UsageError(f"{option} expects NAME=A:B:N, got {quote(text, 80)}")
        try:
            n = count("grid")(parts[2])
        except argparse.ArgumentTypeError as exc:
            raise UsageError(f"{option}: N {exc}") from None
        a, b = (parse_quantity(p, "length", option) for p in parts[:2])
        ranges.append((name.strip(), np.linspace(a.value, b.value, n), (a if a.unit else b).shown_unit or "m"))
    (xn, xs, x_unit), (yn, ys, y_unit) = ranges
    if xs.size * ys.size > BOUNDS["grid_total"][1]:
        raise UsageError(f"--x and --y: {xs.size * ys.size:,} points, at most {BOUNDS['grid_total'][1]:,}")
    held = ({"x", "y", "z"} - {xn, yn}).pop()
    coords, rest = [], []
    for item in args.set or []:
        (coords if item.partition("=")[0].strip() in COORDINATES and item.partition("=")[0].strip() not in joints
         else rest).append(item)
    level, lines = 0.0, []
    for item in coords:
        name, _, text = item.partition("=")
        if name.strip() != held:
            raise UsageError(f"--set {quote(item, 60)}: {name.strip()} is mapped; the held coordinate is {held}")
        level = parse_quantity(text.strip(), "length", "--set").value
    if not coords:
        lines.append(f"{held} held at 0 m (give --set {held}=VALUE for another section)")
    fixed = joint_assignments(mech, rest, "--set")
    sec = trace_section(mech, output, xn, xs, yn, ys, level, fixed, count=args.regions)
    if args.png:
        title = f"{mech.spec.name or Path(mech.path).stem}: workspace section of {output} ({held} = {level:.4g} m)"
        loci_png(sec.loci, sec.regions, args.png, xs, ys, xn, yn, x_unit, y_unit, title=title)
    if args.json:
        print(json_of({"section": {"output": output, "plane": [xn, yn], "held": {held: level},
                                   "extent": None if sec.extent is None else [float(in_unit(v, u)) for v, u in
                                                                             zip(sec.extent, (x_unit, x_unit, y_unit, y_unit))]},
                       "characteristic_length": mech.length,
                       **loci_dict(sec.loci, sec.regions, x_unit, y_unit, None, mech),
                       "regions_count": "real inverse-kinematic solutions of the point (modes), closed form",
                       "cuspidal": sec.cuspidal, "cuspidal_rests_on": sec.why, "generic": sec.generic,
                       "aspects": sec.aspects, "section_notes": lines}))
        return 0
    lines.append(f"workspace section of {output}'s origin over {xn} and {yn} ({held} = {level:.6g} m); the regions' "
                 "counts are real inverse-kinematic solutions")
    lines += loci_lines(sec.loci, sec.regions, xn, yn, x_unit, y_unit, modes="inverse-kinematic solutions")
    verdict = {True: "yes", False: "no", None: "not established"}[sec.cuspidal]
    lines.append(f"cuspidal: {verdict} -- {sec.why}")
    print("\n".join(lines))
    return 0
