"""``screwkin draw``: a skeleton diagram of a mechanism in textbook notation (PNG or SVG), its
kinematic chain as a graph (``--chain``), or one diagram per singular configuration along
the input's range (``--singular``)."""

from __future__ import annotations

import json
import os

import numpy as np

from ..analysis.skeleton import (
    kinematic_chain,
    singular_configurations,
    skeleton,
    trace_points,
)
from ..errors import UsageError
from ..present.draw import (
    chain_dict,
    draw_chain,
    draw_mechanism,
    save_figure,
    skeleton_dict,
    value_label,
)
from ..present.report import to_jsonable
from ._common import (
    add_configuration_options,
    add_point_option,
    configuration,
    inputs,
    named_points,
    with_mode,
)
from ._options import count

NAME = "draw"
NEEDS_MECHANISM = True

_KIND = {
    "actuator": "actuator singularity (det of the passive Jacobian = 0)",
    "serial": "serial singularity",
    "constraint": "constraint singularity (the loops lose a constraint)",
}


def add_parser(sub, common, scaled):
    sp = sub.add_parser(NAME, help="skeleton diagram (PNG/SVG), kinematic chain graph, singular configurations")
    common(sp)
    add_configuration_options(sp)
    sp.add_argument("--png", metavar="F.png", help="write the drawing as PNG")
    sp.add_argument("--svg", metavar="F.svg", help="write the drawing as SVG")
    sp.add_argument("--angles", action="store_true", help="annotate the absolute link angles (planar mechanisms)")
    sp.add_argument("--chain", action="store_true", help="draw the kinematic chain: links as nodes, joints as edges")
    sp.add_argument("--singular", action="store_true",
                    help="one drawing per singular configuration along the input's range, F-singular-K.png ...")
    sp.add_argument("--input", help="--singular: the input joint moved (default: the first actuated joint)")
    sp.add_argument("--output", help="--singular: the output link whose serial singularities (limit positions) are "
                                     "sought (default: a four-bar's rocker, a slider-crank's slider)")
    sp.add_argument("--steps", type=count("figure_steps"), default=360,
                    help="--singular and --trace: steps over the input's range (default 360, at most 20,000)")
    add_point_option(sp)
    sp.add_argument("--trace", action="append", metavar="NAME",
                    help="draw the path of the --point NAME over a whole turn of the input (or up to its limit "
                         "position) on the skeleton; repeatable")


def _targets(mech, args) -> list:
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


def _suffixed(path, k) -> str:
    stem, ext = os.path.splitext(path)
    return f"{stem}-singular-{k}{ext}"


def _configuration_text(skel) -> str:
    if not skel.inputs:
        return "assembled configuration"
    return ", ".join(value_label(k, v, skel.units[k]) for k, v in skel.inputs.items())


def _title(mech, what) -> str:
    return f"{os.path.basename(str(mech.path))}: {what}"


def _kind_text(s) -> str:
    if s.kind == "actuator" and s.limit:
        return "limit position of the input: actuator singularity (det of the passive Jacobian = 0)"
    if s.kind == "serial":
        return (f"serial singularity of '{s.output}': its limit position (a dead centre when driven from it)"
                if s.output else "serial singularity")
    return _KIND.get(s.kind, s.kind)


def _traces(mech, args, q, input_names, given, skel) -> dict:
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


def run(mech, args) -> int:
    targets = _targets(mech, args)
    if args.chain and args.singular:
        raise UsageError(f"{mech.path}: --chain and --singular are separate drawings; give one of them")
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
        name = args.input or (input_names[0] if input_names else None)
        search = singular_configurations(mech, name, output=args.output, q=q, steps=args.steps,
                                         fixed={k: v for k, v in given.items() if k != name})
        found = []
        same, seen = {}, {}  # configurations found at one input value: the modes of another loop, said so
        for s in search.found:
            same.setdefault(round(float(s.input), 9), []).append(s)
        for k, s in enumerate(search.found, 1):
            skel = skeleton(mech, s.q, [search.input, *search.fixed])
            at = value_label(search.input, _wrapped(s.input, search.unit), search.unit)
            key = round(float(s.input), 9)
            seen[key] = seen.get(key, 0) + 1
            mode = f", assembly mode {seen[key]} of the {len(same[key])} at this input" if len(same[key]) > 1 else ""
            title = f"singular configuration {k} of {len(search.found)} at {at}{mode}"
            fig = draw_mechanism(skel, title=_title(mech, title), angles=args.angles, subtitle=_kind_text(s))
            files = []
            for path in targets:
                out = _suffixed(path, k)
                save_figure(fig, out, close=path == targets[-1])
                files.append(out)
            written += files
            found.append({"kind": s.kind, "limit": s.limit, "output": s.output, "input": s.input,
                          "input_wrapped": _wrapped(s.input, search.unit), "sigma": s.sigma, "files": files,
                          "description": _kind_text(s), "title": title})
            if not args.json:
                print(f"{_kind_text(s)} at {at}: wrote {', '.join(files)}")
        report = {"input": search.input, "unit": search.unit, "range": [search.start, search.stop],
                  "output": search.output, "singular_configurations": found}
        if not args.json and not found:
            lo, hi = (value_label(search.input, v, search.unit).split(" = ")[1] for v in (search.start, search.stop))
            print(f"no singular configuration along {search.input} from {lo} to {hi}: nothing written")
    else:
        skel = skeleton(mech, q, input_names)
        space = "" if skel.planar else f" (schematic projection of a {skel.motion_space} mechanism)"
        traces = _traces(mech, args, q, input_names, given, skel)
        for path in targets:
            fig = draw_mechanism(skel, title=_title(mech, _configuration_text(skel)), angles=args.angles,
                                 subtitle=("" if skel.planar else space.strip(" ()")) or None,
                                 traces={n: xy for n, (xy, _) in traces.items()})
            save_figure(fig, path)
            written.append(path)
        report = with_mode(args, skeleton_dict(skel))
        if traces:
            report["traces"] = {n: {"path": xy.tolist(), "stopped_at": stop} for n, (xy, stop) in traces.items()}
    if args.json:
        report["files"] = written
        print(json.dumps(to_jsonable(report), indent=2))
    elif not args.singular:
        for path in written:
            print(f"wrote {path}")
    return 0


def _wrapped(value, unit):
    return value if unit == "m" else float(np.mod(value + np.pi, 2 * np.pi) - np.pi)
