"""screwkin map: map of the smallest singular value over two inputs."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..analysis.position.connect import cusp_loops
from ..analysis.motion.continuation import continuation_steps
from ..analysis.position.position import PositionSolver
from ..analysis.singularities.loci import trace_loci
from ..analysis.singularities.maps import singularity_map
from ..analysis.singularities.regions import regions
from ..errors import UsageError
from ..present.jsonout import json_of
from ..present.loci import loci_dict, loci_lines, loci_png
from ..present.outfile import write_output
from ..present.plots import map_png
from ..present.report import map_csv, map_dict
from ._configuration import add_mode_option, configuration, with_mode
from ._options import BOUNDS
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


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser("map", help="map of the smallest singular value over two inputs")
    common(sp)
    sp.add_argument("--x", required=True, metavar="NAME=A:B:N", help="first input, from A to B in N values")
    sp.add_argument("--y", required=True, metavar="NAME=A:B:N", help="second input")
    sp.add_argument("--set", action="append", metavar="NAME=VALUE", help="values of the other inputs")
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
    # the mode mapped (--mode K), chosen and said once singularity_map has checked the inputs
    mode = lambda: configuration(mech, args, moved={xn: float(xs[0]), yn: float(ys[0])}, inputs=inputs)  # noqa: E731
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

