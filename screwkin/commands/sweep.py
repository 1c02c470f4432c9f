"""screwkin sweep: track one assembly mode along an input motion."""

from __future__ import annotations

import argparse
import math
import os
from typing import TYPE_CHECKING, Any

from ..analysis.motion.links import motion_along, strokes, sweep_motion
from ..analysis.motion.planar import LinkAngles, identify, transmission_angles
from ..analysis.motion.stream import DEFAULT_CHUNK, sweep_chunks
from ..analysis.motion.change_points import change_points
from ..analysis.motion.singular_points import locate_singularities
from ..analysis.motion.sweep import SweepSingularity
from ..analysis.motion.sweep import sweep, sweep_inputs
from ..errors import UsageError
from ..present.jsonout import json_of
from ..present.motion import motion_dict, motion_rows_text, strokes_dict, strokes_text
from ..present.tables import RateUnits, input_rate_words
from ..present.plots import sweep_plot
from ..present.progress import EVERY, Progress
from ..present.streamout import SweepWriter
from ..present.local import change_point_dict, change_point_lines
from ..present.report import (
    linkage_dict,
    sweep_dict,
    sweep_rows,
    sweep_singularity_dict,
    sweep_text,
    value_text,
)
from ._configuration import (
    add_angle_option,
    add_branch_option,
    add_mode_option,
    configuration,
    input_solver,
    moved_not_set,
    near_values,
    with_mode,
)
from ._output_frame import named_points
from ._values import check_rate_names, joint_quantities, joint_value, names_list, rate_items, split_inputs
from ._options import BOUNDS, count
if TYPE_CHECKING:
    from ..analysis.position.position import PositionSolver
    from ..analysis.motion.sweep import SweepResult
    from ..model.mechanism import Mechanism
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "sweep"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser("sweep", help="track one assembly mode along an input motion")
    common(sp)
    sp.add_argument("--input", required=True, help="the input joint to move")
    sp.add_argument("--from", dest="start", required=True, help="first input value (SI or with a unit)")
    sp.add_argument("--to", dest="stop", required=True, help="last input value")
    sp.add_argument("--steps", type=_steps, default=100,
                    help=f"number of steps (default 100, at most {BOUNDS['steps'][1]:,}; up to "
                         f"{BOUNDS['streamed_steps'][1]:,} when the sweep only writes --csv/--parquet, computed and "
                         "written in chunks)")
    sp.add_argument("--set", action="append", metavar="NAME=VALUE", help="values of the other inputs")
    add_angle_option(sp)
    sp.add_argument("--inputs", help="input joints, comma separated (default: the actuated joints)")
    sp.add_argument("--near", metavar="NAME=VALUE,...", help="start on the assembly mode nearest this configuration")
    add_mode_option(sp, "the inputs at --from")
    sp.add_argument("--rate", action="append", metavar="NAME=VALUE",
                    help="the swept input's constant rate, NAME=VALUE or a bare value (e.g. crank=60rpm or 60rpm); "
                         "default 1 rad/s or 1 m/s: the rates and accelerations are then per 1 rad/s (m/s) of the "
                         "input; typed with a unit, the links' omega and alpha are shown in it")
    sp.add_argument("--csv", help="write the joint values, rates and accelerations per step to this CSV file")
    sp.add_argument("--parquet", help="write the same columns as --csv to this Parquet file (needs pyarrow)")
    sp.add_argument("--chunk", type=count("chunk"),
                    help=f"compute and write --csv/--parquet this many steps at a time, in bounded memory "
                         f"(the default, {DEFAULT_CHUNK:,}, when --steps is over 100,000); prints a summary only")
    sp.add_argument("--rows", metavar="N|all", help="rows of the text tables (default about 11; all: every step)")
    sp.add_argument("--plot", help="draw the joint values against the input into this PNG file (needs matplotlib)")
    sp.add_argument("--singularities", action="store_true",
                   help="locate the singular input values along the motion (refined to 1e-9)")
    sp.add_argument("--output", help="output link (serial singularities)")
    sp.add_argument("--turn", action="store_true",
                   help="pass through limit positions onto the other branch (the input runs back) until the "
                        "mechanism returns to its start or the input reaches --to")
    add_branch_option(sp)
    scaled(sp)


def _steps(text: str) -> int:
    """--steps: within BOUNDS["steps"], or BOUNDS["streamed_steps"] for a streamed sweep (checked again in run)."""
    lo, hi = BOUNDS["steps"]
    try:
        return count("streamed_steps")(text)
    except argparse.ArgumentTypeError as exc:
        if "between" not in str(exc):
            raise
        raise argparse.ArgumentTypeError(
            f"must be between {lo:,} and {hi:,} (up to {BOUNDS['streamed_steps'][1]:,} when the sweep only writes "
            f"--csv or --parquet), got {text.strip()}") from None


_NOT_STREAMED = (("json", "--json"), ("plot", "--plot"), ("singularities", "--singularities"), ("turn", "--turn"),
                 ("rows", "--rows"))


def _streamed(args: argparse.Namespace) -> bool:
    """Whether this sweep is computed and written in chunks; refuses what a streamed sweep cannot do."""
    lo, hi = BOUNDS["steps"]
    if args.chunk is None and args.steps <= hi:
        return False
    why = f"--steps {args.steps:,} (over {hi:,})" if args.chunk is None else "--chunk"
    if not (args.csv or args.parquet):
        raise UsageError(f"--steps: must be between {lo:,} and {hi:,} for text, JSON and plots, got {args.steps:,}; "
                         f"up to {BOUNDS['streamed_steps'][1]:,} steps are written in chunks to --csv or --parquet")
    for dest, option in _NOT_STREAMED:
        if getattr(args, dest):
            raise UsageError(f"{option}: not available with {why}: the sweep is computed and written to "
                             f"--csv/--parquet in chunks, {hi:,} steps at most otherwise")
    return True


def _run_streamed(mech: Mechanism, args: argparse.Namespace, solver: PositionSolver, start, stop, fixed, q_start, rate) -> int:
    chunk = args.chunk or DEFAULT_CHUNK
    angles, points = None, named_points(mech, args)  # (a bad --point refused before the file is opened)
    topo = None
    pieces, methods, notes, limits, skipped = 0, [], [], [], 0
    last = None
    with Progress(label="sweep", unit="steps", every=EVERY) as progress, SweepWriter(args.csv, args.parquet) as out:
        for piece in sweep_chunks(solver, args.input, start, stop, args.steps, fixed=fixed, q_start=q_start, rate=rate,
                                  chunk=chunk, branch=args.branch):
            if topo is None:
                topo = mech.topology(piece.q[0])
                if topo.motion_space == "planar" and topo.normal is not None:
                    angles = LinkAngles(mech, topo)
            motion = motion_along(mech, piece.q, piece.rates, piece.accelerations, points, angles,
                                  None if angles is None else angles.n)
            out.write(piece, motion)
            pieces += 1
            if piece.method not in methods:
                methods.append(piece.method)
            notes += [n for n in piece.notes if n not in notes]
            limits += list(piece.limits)
            skipped += len(piece.skipped)
            last = piece
            progress(out.rows - 1, args.steps)
        rows = out.rows
    rad = last.unit == "rad"
    files = " and ".join(f for f in (args.csv, args.parquet) if f)
    print(_rates_line(args))
    print(f"sweep of {args.input} from {value_text(args.input, start, rad)} to {value_text(args.input, stop, rad)} "
          f"in {args.steps:,} steps, computed and written in {pieces} chunk{'s' if pieces > 1 else ''} of at most "
          f"{chunk:,} steps ({', '.join(methods)}): {rows:,} rows written to {files}")
    for n in notes:
        print(f"note: {n}")
    for x in limits:
        print(f"limit position at {args.input} = {value_text(args.input, x.input, rad)}, relative sigma {x.sigma:.2g}")
    if last.stopped_at is not None:
        print(f"stopped at {args.input} = {value_text(args.input, last.stopped_at, rad)}: {last.stop_reason}")
    if skipped:
        print(f"{skipped} grid value{'s' if skipped > 1 else ''} passed but not solved (holes in the motion)")
    return 0


def _rates_line(args: argparse.Namespace) -> str:
    """The line that says what the rates and accelerations written are for (the input's rate)."""
    if args.rate:
        return f"rates and accelerations {args.rate_words}, held constant"
    return (f"rates and accelerations {args.rate_words} (the velocity ratios; --rate {args.input}=60rpm for "
            "another speed), at a constant input rate")


def _rows_option(text: str) -> str | None:
    if text is None or text.strip().lower() == "all":
        return None if text is None else "all"
    try:
        return count("figure_steps")(text)
    except argparse.ArgumentTypeError as exc:
        raise UsageError(f"--rows: {exc} (or all)") from None


def _singularities(args: argparse.Namespace, solver: PositionSolver, res: SweepResult) -> list:
    """The limit positions met, and with --singularities every singularity along the motion located (the
    configuration space's own, change points and shaky points, from analysis.local)."""
    sing = list(res.limits)  # the limit positions met are always listed
    if args.singularities:
        sing = locate_singularities(solver, res, output=args.output, point=args.point)
        sing = sorted(sing + [SweepSingularity("constraint", p.input, p.sigma, p.q, point=p)
                              for p in change_points(solver, res, sing) if p.located], key=lambda x: x.input)
    return sing


def _sweep_json(mech: Mechanism, args: argparse.Namespace, res: SweepResult, info: Any, mus: list | None,
                sing: list, motion: Any, slider_strokes: Any, held: dict[str, float], rate: float) -> dict:
    """sweep --json's object."""
    d = with_mode(args, sweep_dict(res, mech))
    d["input_rate"], d["rates_are"] = rate, args.rate_words  # SI; "per 1 rad/s of crank" or "at crank 60 rpm"
    if info is not None:
        d["linkage"] = linkage_dict(info)
        d["transmission_angles"] = mus
    d["singularities"] = [sweep_singularity_dict(x, mech) for x in sing]
    for entry, x in zip(d["singularities"], sing):  # what the configuration space does there
        if x.point is not None:
            entry.update({k: v for k, v in change_point_dict(x.point).items() if k not in ("input", "sigma")})
    # the change points passed: where, what the configuration space does there, the branch taken
    d["change_points"] = [{**change_point_dict(cp), "branch": "other" if cp.switched else "continue", "note": line}
                          for cp, line in zip(res.change_points, res.change_point_notes)]
    d["characteristic_length"] = mech.length
    d.update(motion_dict(motion))
    d["strokes"] = strokes_dict(slider_strokes)
    if held:
        d["held_angles"] = held  # as solve --json: link -> absolute angle [rad] held along the motion
    return d


def _print_text(mech: Mechanism, args: argparse.Namespace, res: SweepResult, info: Any, mus: list | None,
                sing: list, motion: Any, slider_strokes: Any, held: dict[str, float], typed_range: list,
                units: RateUnits | None) -> None:
    """sweep's text: the table of the motion, the rates, strokes, notes, the links' motion and the singularities."""
    rows = sweep_rows(len(res.values), _rows_option(args.rows))
    typed_deg = any(q.kind == "angle" and q.shown_unit == "deg" for q in typed_range)
    linear_names = [n for k, n in enumerate(res.names) if mech.translational[k]] if len(res.names) == mech.nv \
        else []
    for link, angle in held.items():
        print(f"held along the motion: the angle of {link} = {angle:.9g} rad ({math.degrees(angle):.6g} deg)")
    print(sweep_text(res, info, mus, rows=_rows_option(args.rows), degrees=typed_deg and res.unit == "rad",
                     linear_names=linear_names))
    print(_rates_line(args))
    for line in strokes_text(slider_strokes, res.unit == "rad"):
        print(line)
    for n in res.notes:
        print(f"note: {n}")
    table_text = motion_rows_text(res, motion, rows, typed_deg and res.unit == "rad", units)
    if table_text:
        print()
        print(table_text)
    if args.singularities:
        print(f"\nsingularities along the motion (L = {mech.length:.4g} m):" if sing
              else "\nno singularity along the motion")
        for x in sing:
            print(f"  {x.kind:<10} at {res.input} = {value_text(res.input, x.input, res.unit == 'rad')}, "
                  f"relative sigma {x.sigma:.2g}" + ("  (limit position)" if x.limit else ""))
            if x.point is not None:
                print("\n".join(change_point_lines(x.point, "this configuration")))


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    # the other inputs: joints (--set, or --set-angle of a link pinned to the ground), or a floating link's
    # absolute angle held by one more loop equation along the whole motion (--set-angle LINK=ANGLE)
    fixed, held, _ = split_inputs(mech, args)
    inputs = names_list(args.inputs) or ([args.input, *(k for k in fixed if k != args.input)] if held else
                                         sweep_inputs(mech, args.input, fixed))
    solver = input_solver(mech, inputs, held)
    near_values(mech, args)  # checked before the work (configuration() reads it where the motion starts)
    if args.point and not args.output:
        raise UsageError("--point needs --output LINK")
    typed_range = [joint_value(mech, args.input, text, option) for text, option in ((args.start, "--from"),
                                                                                    (args.stop, "--to"))]
    start, stop = (q.value for q in typed_range)
    args.rate = rate_items(args.rate, [args.input], "--rate") or None  # the one grammar: NAME=VALUE or bare
    typed = joint_quantities(mech, args.rate, "--rate", order=1)
    check_rate_names(typed, [args.input], "--rate")  # only the swept input moves
    rate = typed[args.input].value if args.input in typed else 1.0
    args.rate_words = input_rate_words(args.input, typed.get(args.input),
                                       bool(mech.translational[mech.coordinate(args.input).idx_v]))
    if args.parquet:
        SweepWriter.require_parquet(args.parquet)  # before any work
    moved_not_set(fixed, args.input, "sweep moves it from --from to --to")
    others = {k: v for k, v in fixed.items() if k != args.input}
    streamed = _streamed(args)
    # the mode followed (--mode K), chosen and said once sweep has checked the inputs
    q_start = lambda: configuration(mech, args, moved={args.input: start}, inputs=inputs)  # noqa: E731
    if streamed:
        return _run_streamed(mech, args, solver, start, stop, others, q_start, rate)
    with Progress(label="sweep", unit="steps", every=EVERY) as progress:  # on a terminal only
        res = sweep(solver, args.input, start, stop, args.steps, fixed=others, q_start=q_start, rate=rate,
                    progress=progress, turn=args.turn, branch=args.branch)
    topo = mech.topology(res.q[0])
    motion = sweep_motion(mech, res, named_points(mech, args))
    info = identify(mech, topo, res.q[0], args.input) if len(inputs) == 1 and not held else None
    slider_strokes = strokes(res, motion, mech, solver)
    mus = None
    if info is not None:
        mus = transmission_angles(mech, info, res.q).tolist()
    sing = _singularities(args, solver, res)
    if args.csv or args.parquet:
        with SweepWriter(args.csv, args.parquet) as out:
            out.write(res, motion)
    # a --rate typed: the links' omega and alpha in its units (60rpm: rpm, rpm/s), in the tables and the plot
    units = RateUnits.typed(typed.values()) if args.rate else None
    if args.plot:
        sweep_plot(res, args.plot, mus, singularities=sing, linear=mech.translational, motion=motion,
                   title=f"{os.path.basename(mech.path)}: {args.input} from {args.start} to {args.stop}, "
                         f"{args.rate_words}", rate_words=args.rate_words, units=units)
    if args.json:
        print(json_of(_sweep_json(mech, args, res, info, mus, sing, motion, slider_strokes, held, rate)))
    else:
        _print_text(mech, args, res, info, mus, sing, motion, slider_strokes, held, typed_range, units)
    return 0
