"""screwkin sweep: track one assembly mode along an input motion."""

from __future__ import annotations

import argparse
import os

from ..analysis.motion.links import motion_along, strokes
from ..analysis.motion.planar import LinkAngles, identify, transmission_angles
from ..analysis.motion.position import PositionSolver
from ..analysis.motion.sweep import locate_singularities, sweep
from ..errors import UsageError
from ..present.motion import motion_dict, motion_rows_text, strokes_dict, strokes_text
from ..present.plots import sweep_plot
from ..present.report import (
    json_text,
    linkage_dict,
    sweep_csv,
    sweep_dict,
    sweep_rows,
    sweep_singularity_dict,
    sweep_text,
    to_jsonable,
    value_text,
)
from ..units import parse_typed_value, unit_kind
from ._common import (
    joint_assignments,
    joint_value,
    named_points,
    names_list,
)
from ._options import count

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "sweep"
NEEDS_MECHANISM = True


def add_parser(sub, common, scaled):
    sp = sub.add_parser("sweep", help="track one assembly mode along an input motion")
    common(sp)
    sp.add_argument("--input", required=True, help="the input joint to move")
    sp.add_argument("--from", dest="start", required=True, help="first input value (SI or with a unit)")
    sp.add_argument("--to", dest="stop", required=True, help="last input value")
    sp.add_argument("--steps", type=count("steps"), default=100, help="number of steps (default 100, at most 100,000)")
    sp.add_argument("--set", action="append", metavar="NAME=VALUE", help="values of the other inputs")
    sp.add_argument("--inputs", help="input joints, comma separated (default: the actuated joints)")
    sp.add_argument("--near", metavar="NAME=VALUE,...", help="start on the assembly mode nearest this configuration")
    sp.add_argument("--rate", default="1", help="input rate for the joint rates and accelerations (default 1 /s)")
    sp.add_argument("--csv", help="write the joint values, rates and accelerations per step to this CSV file")
    sp.add_argument("--rows", metavar="N|all", help="rows of the text tables (default about 11; all: every step)")
    sp.add_argument("--plot", help="draw the joint values against the input into this PNG file (needs matplotlib)")
    sp.add_argument("--singularities", action="store_true",
                   help="locate the singular input values along the motion (refined to 1e-9)")
    sp.add_argument("--output", help="output link (serial singularities)")
    sp.add_argument("--turn", action="store_true",
                   help="pass through limit positions onto the other branch (the input runs back) until the "
                        "mechanism returns to its start or the input reaches --to")
    scaled(sp)


def _rows(text):
    if text is None or text.strip().lower() == "all":
        return None if text is None else "all"
    try:
        return count("figure_steps")(text)
    except argparse.ArgumentTypeError as exc:
        raise UsageError(f"--rows: {exc} (or all)") from None


def run(mech, args) -> int:
    fixed = joint_assignments(mech, args.set, "--set")
    inputs = names_list(args.inputs) or (list(mech.actuated) if args.input in mech.actuated else [args.input, *fixed])
    solver = PositionSolver(mech, inputs)
    near = joint_assignments(mech, [args.near], "--near") if args.near else None
    if args.point and not args.output:
        raise UsageError("--point needs --output LINK")
    start, stop = (joint_value(mech, args.input, text, option) for text, option in ((args.start, "--from"),
                                                                                      (args.stop, "--to")))
    res = sweep(solver, args.input, start, stop, args.steps,
                fixed={k: v for k, v in fixed.items() if k != args.input}, near=near,
                rate=joint_value(mech, args.input, args.rate, "--rate", order=1), progress=True, turn=args.turn)
    topo = mech.topology(res.q[0])
    angles = LinkAngles(mech, topo) if topo.motion_space == "planar" and topo.normal is not None else None
    motion = motion_along(mech, res.q, res.rates, res.accelerations, named_points(mech, args), angles,
                          None if angles is None else angles.n)
    info = identify(mech, topo, res.q[0], args.input) if len(inputs) == 1 else None
    slider_strokes = strokes(res, motion, mech)
    mus = None
    if info is not None:
        mus = transmission_angles(mech, info, res.q).tolist()
    sing = list(res.limits)  # the limit positions met are always listed
    if args.singularities:
        sing = locate_singularities(solver, res, output=args.output, point=args.point)
    if args.csv:
        with open(args.csv, "w") as f:
            f.write(sweep_csv(res, motion))
    if args.plot:
        sweep_plot(res, args.plot, mus, singularities=sing, linear=mech.translational, motion=motion,
                   normal=None if angles is None else angles.n,
                   title=f"{os.path.basename(mech.path)}: {args.input} from {args.start} to {args.stop}")
    if args.json:
        d = sweep_dict(res, mech)
        if info is not None:
            d["linkage"] = linkage_dict(info)
            d["transmission_angles"] = mus
        d["singularities"] = [sweep_singularity_dict(x, mech) for x in sing]
        d["characteristic_length"] = mech.length
        d.update(motion_dict(motion))
        d["strokes"] = strokes_dict(slider_strokes)
        print(json_text(to_jsonable(d)))
    else:
        rows = sweep_rows(len(res.values), _rows(args.rows))
        typed_deg = any(unit_kind(parse_typed_value(t)[1]) == "angle" and "deg" in t.lower()
                        for t in (args.start, args.stop))
        linear_names = [n for k, n in enumerate(res.names) if mech.translational[k]] if len(res.names) == mech.nv \
            else []
        print(sweep_text(res, info, mus, rows=_rows(args.rows), degrees=typed_deg and res.unit == "rad",
                         linear_names=linear_names))
        for line in strokes_text(slider_strokes, res.unit == "rad"):
            print(line)
        table_text = motion_rows_text(res, motion, rows, typed_deg and res.unit == "rad")
        if table_text:
            print()
            print(table_text)
        if args.singularities:
            print(f"\nsingularities along the motion (L = {mech.length:.4g} m):" if sing
                  else "\nno singularity along the motion")
            for x in sing:
                print(f"  {x.kind:<10} at {res.input} = {value_text(res.input, x.input, res.unit == 'rad')}, "
                      f"relative sigma {x.sigma:.2g}" + ("  (limit position)" if x.limit else ""))
    return 0
