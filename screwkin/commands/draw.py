"""``screwkin draw``: a skeleton diagram of a mechanism in textbook notation (PNG or SVG), its
kinematic chain as a graph (``--chain``), or one diagram per singular configuration along
the input's range (``--singular``)."""

from __future__ import annotations

import argparse
import os
import sys
from typing import TYPE_CHECKING

import numpy as np

from ..analysis.motion.sweep import sweep
from ..analysis.course.figures import singular_configurations, trace_points
from ..analysis.course.skeleton import kinematic_chain, skeleton
from ..errors import UsageError, quote
from ..present.jsonout import json_of
from ..analysis.singularities.mode_connect import Connections, connect_modes
from ..present.animate import animate_configurations, animate_connection, animation_format
from ..present.loci import connections_dict, connections_lines
from ..present.progress import EVERY, Progress
from ..present.draw import (
    chain_dict,
    configuration_text,
    draw_chain,
    draw_mechanism,
    drawing_title,
    save_figure,
    skeleton_dict,
    value_label,
    wrapped_value,
)
from ..present.draw_targets import design_drawing
from ..present.local import change_point_dict, singularity_kind_text
from ..units import unit_text
from ._configuration import (
    add_branch_option,
    add_configuration_options,
    configuration,
    input_solver,
    moved_not_set,
    near_values,
    with_mode,
)
from ._output_frame import add_point_option, named_points
from ._values import inputs, joint_quantities, joint_value, split_inputs
from ._options import BOUNDS, count

if TYPE_CHECKING:
    from ..model.mechanism import Mechanism
    from collections.abc import Callable

NAME = "draw"
NEEDS_MECHANISM = True

def add_parser(sub: argparse._SubParsersAction, common: Callable[..., None], scaled: Callable[..., None]) -> None:
    sp = sub.add_parser(NAME, help="skeleton diagram (PNG/SVG), kinematic chain graph, singular configurations")
    common(sp)
    add_configuration_options(sp)
    add_branch_option(sp, "--animate's motion")
    sp.add_argument("--png", metavar="F.png", help="write the drawing as PNG")
    sp.add_argument("--svg", metavar="F.svg", help="write the drawing as SVG")
    sp.add_argument("--angles", action="store_true", help="annotate the absolute link angles (planar mechanisms)")
    sp.add_argument("--chain", action="store_true", help="draw the kinematic chain: links as nodes, joints as edges")
    sp.add_argument("--singular", action="store_true",
                    help="one drawing per singular configuration along the input's range, F-singular-K.png ...")
    sp.add_argument("--input", help="--singular: the input joint moved (default: the first actuated joint)")
    sp.add_argument("--output", help="--singular: the output link whose serial singularities (limit positions) are "
                                     "sought (default: a four-bar's rocker, a slider-crank's slider)")
    sp.add_argument("--steps", type=count("figure_steps"), default=None,
                    help="--singular and --trace: steps over the input's range (default 360, at most 20,000); "
                         "--animate: steps from --from to --to (default 60, at most 500)")
    add_point_option(sp)
    sp.add_argument("--trace", action="append", metavar="NAME",
                    help="draw the path of the --point NAME over a whole turn of the input (or up to its limit "
                         "position) on the skeleton; repeatable")
    sp.add_argument("--no-targets", dest="targets", action="store_false",
                    help="leave out the targets a synthesized file states (<screwkin:targets>: drawn by default, "
                         "with the linkage at each precision position and a path's coupler curve)")
    sp.add_argument("--animate", metavar="OUT.gif|OUT.mp4",
                    help="write an animation of the skeleton while --input goes --from A --to B in --steps N "
                         "(GIF with Pillow; MP4 with imageio-ffmpeg); --point paths are traced")
    sp.add_argument("--from", dest="start", help="--animate: the input's first value (units allowed: -30deg, 5mm)")
    sp.add_argument("--to", dest="stop", help="--animate: the input's last value")
    sp.add_argument("--fps", type=frame_rate, default=20.0, help="--animate: frames per second (default 20, 1 to 60)")
    sp.add_argument("--connect", type=mode_pair, metavar="I:J",
                    help="with --animate: the path joining assembly modes I and J (numbered as solve --all lists "
                         "them at the --set inputs) without a singularity, as solve --all --connect finds it; "
                         "when none is found, why (and no file)")


def frame_rate(text: str) -> float:
    """argparse type of --fps: a number of frames per second from 1 to 60."""
    try:
        fps = float(text.strip())
    except (ValueError, AttributeError):
        raise argparse.ArgumentTypeError(f"expected frames per second, got {quote(text, 20)}") from None
    if not 1.0 <= fps <= 60.0:  # nan fails both comparisons
        raise argparse.ArgumentTypeError(f"must be from 1 to 60 frames per second, got {quote(text, 20)}")
    return fps


def mode_pair(text: str) -> tuple[int, int]:
    """argparse type of --connect I:J: two different assembly modes, numbered from 1."""
    parts = str(text).replace(",", ":").split(":")
    try:
        i, j = (int(p.strip()) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected two mode numbers I:J (as solve --all lists them), got "
                                         f"{quote(text, 20)}") from None
    if i < 1 or j < 1 or i == j:
        raise argparse.ArgumentTypeError(f"expected two different mode numbers from 1, got {quote(text, 20)}")
    return i, j


def _targets(mech: Mechanism, args: argparse.Namespace) -> list:
    out = []
    for option, ext in (("png", ".png"), ("svg", ".svg")):
        path = getattr(args, option)
        if path is None:
            continue
        if not path.lower().endswith(ext) or len(path) <= len(ext):
            raise UsageError(f"{mech.path}: --{option} expects a file name ending in {ext}, got '{path[:80]}'")
        out.append(path)
    if not out:
        raise UsageError(f"{mech.path}: draw writes a file: give --png F.png or --svg F.svg")
    return out


def _suffixed(path: str, k: int) -> str:
    stem, ext = os.path.splitext(path)
    return f"{stem}-singular-{k}{ext}"


def _traces(mech: Mechanism, args: argparse.Namespace, q: np.ndarray, input_names: list, given: dict, skel) -> dict:
    """--trace NAME: name -> (the point's path in the drawing's plane (N, 2) [m], where the input stopped)."""
    if not args.trace:
        return {}
    points = {p.name: p for p in named_points(mech, args)}
    for name in args.trace:
        if name not in points:
            raise UsageError(f"{mech.path}: --trace {name}: no --point {name}=LINK:x,y,z was given")
    if not input_names:
        raise UsageError(f"{mech.path}: --trace needs an input to move: declare actuated joints or give --set NAME=VALUE")
    res, motion = trace_points(mech, q, input_names[0], [points[n] for n in args.trace], args.steps,
                               {k: v for k, v in given.items() if k != input_names[0]})
    e1, e2, _ = skel.basis
    out = {}
    for name in args.trace:
        P = np.asarray(motion.points[name]["position"])
        out[name] = (np.stack([P @ np.asarray(e1), P @ np.asarray(e2)], axis=1), res.stopped_at)
        if res.stopped_at is not None and not args.json:
            print(f"path of {name}: {input_names[0]} stopped at {res.stopped_at:.6g} ({res.stop_reason})")
    return out


def _draw_singular(mech: Mechanism, args: argparse.Namespace, q: np.ndarray, given: dict[str, float],
                   input_names: list[str], targets: list[str], written: list[str]) -> dict:
    """draw --singular: the skeleton at each singular configuration along the input, one file each; the JSON
    report."""
    name = args.input or (input_names[0] if input_names else None)
    search = singular_configurations(mech, name, output=args.output, q=q, steps=args.steps,
                                     fixed={k: v for k, v in given.items() if k != name})
    found = []
    same: dict[float, list] = {}  # configurations found at one input value: the modes of another loop, said so
    seen: dict[float, int] = {}
    for s in search.found:
        same.setdefault(round(float(s.input), 9), []).append(s)
    for k, s in enumerate(search.found, 1):
        skel = skeleton(mech, s.q, [search.input, *search.fixed])
        at = value_label(search.input, wrapped_value(s.input, search.unit), search.unit)
        key = round(float(s.input), 9)
        seen[key] = seen.get(key, 0) + 1
        mode = f", assembly mode {seen[key]} of the {len(same[key])} at this input" if len(same[key]) > 1 else ""
        title = f"singular configuration {k} of {len(search.found)} at {at}{mode}"
        fig = draw_mechanism(skel, title=drawing_title(mech, title), angles=args.angles,
                             subtitle=singularity_kind_text(s))
        files = []
        for path in targets:
            out = _suffixed(path, k)
            save_figure(fig, out, close=path == targets[-1])
            files.append(out)
        written += files
        found.append({"kind": s.kind, "limit": s.limit, "output": s.output, "input": s.input,
                      "input_wrapped": wrapped_value(s.input, search.unit), "sigma": s.sigma, "files": files,
                      "description": singularity_kind_text(s), "title": title})
        if getattr(s, "point", None) is not None:
            found[-1].update({k: v for k, v in change_point_dict(s.point).items() if k not in ("input", "sigma")})
        if not args.json:
            print(f"{singularity_kind_text(s)} at {at}: wrote {', '.join(files)}")
    report = {"input": search.input, "unit": search.unit, "range": [search.start, search.stop],
              "output": search.output, "singular_configurations": found}
    if not args.json and not found:
        lo, hi = (value_label(search.input, v, search.unit).split(" = ")[1] for v in (search.start, search.stop))
        print(f"no singular configuration along {search.input} from {lo} to {hi}: nothing written")
    return report


def _draw_skeleton(mech: Mechanism, args: argparse.Namespace, q: np.ndarray, given: dict[str, float],
                   input_names: list[str], targets: list[str], written: list[str]) -> dict:
    """draw: the skeleton at the configuration, with the traced points' paths and a design's targets; the JSON
    report."""
    skel = skeleton(mech, q, input_names)
    space = "" if skel.planar else f" (schematic projection of a {skel.motion_space} mechanism)"
    traces = _traces(mech, args, q, input_names, given, skel)
    marks, curve = (None, None)
    if mech.spec.targets and args.targets:
        marks, curve = design_drawing(mech, q, input_names, skel, args.steps, None if args.json else print,
                               "; --no-targets leaves them out")
    if curve is not None:
        traces[curve[0]] = curve[1:]
    for path in targets:
        fig = draw_mechanism(skel, title=drawing_title(mech, configuration_text(skel)), angles=args.angles,
                             subtitle=("" if skel.planar else space.strip(" ()")) or None,
                             traces={n: xy for n, (xy, _) in traces.items()}, marks=marks)
        save_figure(fig, path)
        written.append(path)
    report = with_mode(args, skeleton_dict(skel))
    if traces:
        report["traces"] = {n: {"path": xy.tolist(), "stopped_at": stop} for n, (xy, stop) in traces.items()}
    if marks:
        report["targets"] = [{k: v for k, v in m.items() if k != "ghost"} for m in marks]
    return report


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    if args.connect and not args.animate:
        raise UsageError(f"{mech.path}: --connect I:J goes with --animate OUT.gif (it animates the path joining the "
                         "two modes)")
    if args.animate:
        return _animate_pair(mech, args) if args.connect else _animate(mech, args)
    if args.start is not None or args.stop is not None:
        raise UsageError(f"{mech.path}: --from and --to go with --animate OUT.gif")
    untraced = [p.name for p in named_points(mech, args) if p.name not in (args.trace or ())]  # said at the end
    targets = _targets(mech, args)
    if args.chain and args.singular:
        raise UsageError(f"{mech.path}: --chain and --singular are separate drawings; give one of them")
    if (args.chain or args.singular) and mech.spec.targets and args.targets and not args.json:
        print(f"the file's {len(mech.spec.targets)} targets (<screwkin:targets>) are drawn on the skeleton "
              f"(draw without --{'chain' if args.chain else 'singular'}), not here")
    args.steps = 360 if args.steps is None else args.steps
    if args.steps < 4:
        raise UsageError(f"{mech.path}: --steps must be at least 4")
    given = inputs(mech, args)
    q = configuration(mech, args)
    input_names = list(given) or list(mech.actuated)
    written, report = [], {}
    if args.chain:
        chain = kinematic_chain(mech, q, input_names)
        for path in targets:
            save_figure(draw_chain(chain), path)
            written.append(path)
        report = chain_dict(chain)
    elif args.singular:
        report = _draw_singular(mech, args, q, given, input_names, targets, written)
    else:
        report = _draw_skeleton(mech, args, q, given, input_names, targets, written)
    if args.json:
        report["files"] = written
        print(json_of(report))
    elif not args.singular:
        for path in written:
            print(f"wrote {path}")
    if untraced:  # (checked, as every --point is: cli.py)
        print(f"note: --point {', '.join(quote(n, 40) for n in untraced)}: a point is drawn as its path, with "
              "--trace NAME (or in --animate); not drawn here", file=sys.stderr)
    return 0


def _typed(name: str, value, unit: str) -> str:
    """'crank = 30 deg' in the unit the person typed (``unit``: rad or m when bare)."""
    return f"{name} = {unit_text(value, unit, 5)}"


def _animate(mech: Mechanism, args: argparse.Namespace) -> int:
    """draw --animate OUT: the skeleton along a sweep of --input from --from to --to."""
    ext = animation_format(args.animate)
    if args.png or args.svg or args.chain or args.singular or args.trace:
        raise UsageError(f"{mech.path}: --animate writes one animation: leave out --png, --svg, --chain, --singular "
                         "and --trace (--point paths are traced in the animation)")
    if args.start is None or args.stop is None:
        raise UsageError(f"{mech.path}: --animate needs --from A and --to B (the input's range)")
    steps = 60 if args.steps is None else args.steps
    lo, hi = BOUNDS["animation_steps"]
    if not lo <= steps <= hi:
        raise UsageError(f"{mech.path}: --animate --steps must be from {lo} to {hi:,} (frames: steps + 1), got {steps}")
    if mech.spec.targets and not args.json:
        print(f"the file's {len(mech.spec.targets)} targets (<screwkin:targets>) are drawn on the skeleton "
              "(draw --png/--svg), not in the animation")
    given, held, _ = split_inputs(mech, args)  # a floating link's angle is held along the motion, as in sweep
    name = args.input or (mech.actuated[0] if mech.actuated else None)  # (a --set value is held, never moved)
    if name is None:
        raise UsageError(f"{mech.path}: --animate needs --input NAME (the file declares no actuated joint)")
    typed = [joint_value(mech, name, args.start, "--from"), joint_value(mech, name, args.stop, "--to")]
    start, stop = (q.value for q in typed)
    moved_not_set(given, name, "--animate moves it from --from to --to")
    fixed = {k: v for k, v in given.items() if k != name}
    input_names = [name, *fixed] if held or name not in mech.actuated else list(mech.actuated)
    near_values(mech, args)  # checked before the work (configuration() reads it where the motion starts)
    solver = input_solver(mech, input_names, held)
    # the mode followed (--mode K, --near), chosen and said as sweep's
    res = sweep(solver, name, start, stop, steps, fixed=fixed, branch=args.branch,
                q_start=lambda: configuration(mech, args, moved={name: start}, inputs=input_names))
    if not args.json:
        for line in res.change_point_notes:  # the change points passed, and the branch taken at each
            print(f"note: {line}")
    unit = next((q.shown_unit for q in typed if q.unit), None) or ("m" if res.unit == "m" else "rad")
    qs, values = list(res.q), list(res.values)
    limit = next((s for s in res.limits if res.stopped_at is not None and abs(s.input - res.stopped_at) <= mech.tolerances.equal), None)
    if limit is not None:  # the last frame: the mechanism at the limit position itself
        qs.append(limit.q)
        values.append(limit.input)
    if res.stopped_at is not None and not args.json:
        print(f"{name} stopped at {_typed(name, res.stopped_at, unit).split(' = ')[1]} ({res.stop_reason}): "
              f"{len(qs)} frames, not the {steps + 1} asked")
    if res.skipped and not args.json:
        print(f"{len(res.skipped)} input value(s) on the way could not be solved: no frame for them")
    titles = [drawing_title(mech, _typed(name, x, unit)) for x in values]
    if limit is not None:
        titles[-1] += " (limit position)"
    with Progress(label="animate", unit="frame draws (each framed, then drawn)", every=EVERY) as progress:  # a terminal
        n, traces = animate_configurations(args.animate, mech, qs, input_names, titles, named_points(mech, args),
                                           fps=args.fps, angles=args.angles, progress=progress)
    if args.json:
        print(json_of({"file": args.animate, "format": ext[1:], "frames": n, "fps": args.fps,
                       "input": name, "unit": res.unit, "values": values,
                       "stopped_at": res.stopped_at, "stop_reason": res.stop_reason,
                       "change_points": list(res.change_point_notes),
                       "traces": {k: xy.tolist() for k, xy in traces.items()}}))
    else:
        print(f"wrote {args.animate}: {n} frames at {args.fps:g} fps, {_typed(name, values[0], unit)} "
              f"to {_typed(name, values[-1], unit).split(' = ')[1]}")
    return 0


def _animate_pair(mech: Mechanism, args: argparse.Namespace) -> int:
    """draw --connect I:J --animate OUT: the skeleton along the path joining modes I and J of the --set inputs
    without a singularity (mode_connect, as solve --all --connect), or why there is none: said, no file, exit 0."""
    ext = animation_format(args.animate)
    given = [o for o, v in (("--png", args.png), ("--svg", args.svg), ("--chain", args.chain),
                            ("--singular", args.singular), ("--trace", args.trace), ("--from", args.start),
                            ("--to", args.stop), ("--input", args.input), ("--steps", args.steps),
                            ("--near", args.near), ("--mode", args.mode), ("--set-angle", args.set_angle),
                            ("--output", args.output)) if v]
    if given:
        raise UsageError(f"{mech.path}: --connect animates the path between two modes of the --set inputs; leave out "
                         f"{', '.join(given)}")
    values, held, _ = split_inputs(mech, args)
    if not values:
        raise UsageError(f"{mech.path}: --connect needs the inputs' values: --set NAME=VALUE (the modes are those "
                         "solve --all lists there)")
    if mech.spec.targets and not args.json:
        print(f"the file's {len(mech.spec.targets)} targets (<screwkin:targets>) are drawn on the skeleton "
              "(draw --png/--svg), not in the animation")
    i, j = args.connect
    solver = input_solver(mech, values)
    res = solver.solve(values, method="auto")  # the list solve --all gives (the same call, the same order)
    if res.free_dofs:
        raise UsageError(f"{mech.path}: --connect: these inputs leave {res.free_dofs} degree(s) of freedom (a "
                         "continuum of configurations, not a list of modes); give every input")
    n = len(res.solutions)
    if max(i, j) > n:
        raise UsageError(f"{mech.path}: --connect {i}:{j}: solve --all lists {n} assembly mode{'s' if n != 1 else ''} "
                         "at these inputs")
    conns = connect_modes(solver, values, [s.q for s in res.solutions], pairs=[(i - 1, j - 1)])  # from I to J
    c = conns.connections[0]
    units = {n: q.shown_unit for n, q in joint_quantities(mech, args.set, "--set").items()}
    report = {**connections_dict(Connections((c,), conns.signs, conns.how, conns.notes), mech),
              "file": None, "format": ext[1:], "frames": 0, "fps": args.fps, "sigma_so_far": []}
    if c.joined:
        with Progress(label="animate", unit="frame draws (each framed, then drawn)", every=EVERY) as progress:
            report["frames"] = animate_connection(args.animate, mech, c, list(values), units, named_points(mech, args),
                                                  fps=args.fps, angles=args.angles, progress=progress)
        report["file"] = args.animate
        report["sigma_so_far"] = [float(v) for v in c.sigma_so_far]  # each frame's title: the smallest measure so far
    if args.json:
        print(json_of(report))
        return 0
    print("\n".join(connections_lines(Connections((c,), conns.signs, conns.how, conns.notes))))
    if c.joined:
        print(f"wrote {args.animate}: the path from mode {i} to mode {j}, {report['frames']} frames at {args.fps:g} fps")
    else:
        print(f"no path from mode {i} to mode {j} to animate: {args.animate} not written")
    return 0
