"""Command line: ``screwkin mobility FILE`` and ``screwkin info FILE``.

A thin edge over the Python API: it parses arguments, calls the same functions
and prints their results.  Exit codes: 0 success, 1 invalid or unanalysable
file, 2 usage error, 3 internal error (a bug).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import tempfile
import time
import traceback
import warnings

import numpy as np
import pinocchio as pin

from .analysis.ellipsoids import ellipsoids
from .analysis.gram_symbolic import symbolic_gram
from .analysis.maps import singularity_map
from .analysis.mobility import analyze_mobility
from .analysis.motion import motion_along, strokes
from .analysis.planar import LinkAngles, identify
from .analysis.position import PositionSolver, inverse_kinematics
from .analysis.scan import scan
from .analysis.screws import loop_screws, structure
from .analysis.singular import classify
from .analysis.sweep import locate_singularities, sweep
from .commands import draw, grasp, synthesize
from .commands import equations as equations_command
from .commands import report as report_command
from .commands import statics as statics_command
from .commands import study as study_command
from .commands import workspace as workspace_command
from .commands._options import BOUNDS, check_parsed, count, screwkin_version
from .commands._common import (
    add_angle_option,
    add_configuration_options,
    add_length_option,
    add_point_option,
    configuration,
    inputs,
    joint_assignments,
    joint_value,
    named_points,
)
from .errors import MESSAGE_LIMIT, ScrewkinError, UsageError, one_line
from .files.xacro import parse_args as parse_xacro_args
from .model.joint_types import JOINT_TYPES
from .model.loader import load
from .present.ellipsoids import ellipsoids_dict, ellipsoids_text
from .present.screws import gram_symbolic_dict, gram_symbolic_text
from .present.motion import motion_dict, motion_rows_text, strokes_dict, strokes_text
from .present.plots import map_png, sweep_plot
from .present.report import (
    joint_types_dict,
    joint_types_text,
    linkage_dict,
    loops_dict,
    loops_text,
    map_csv,
    mobility_dict,
    mobility_text,
    position_dict,
    position_text,
    scan_csv,
    scan_dict,
    screws_dict,
    screws_text,
    singularity_dict,
    singularity_text,
    sweep_csv,
    sweep_dict,
    sweep_singularity_dict,
    sweep_rows,
    sweep_text,
    to_jsonable,
    topology_dict,
    topology_text,
    trace_text,
    value_text,
)
from .present.view import PICTURE, ViewerServer, build_scene, page, screenshot, show
from .units import parse_length, parse_typed_value, parse_value, unit_kind

__all__ = ["main"]

#: Commands in modules of their own: each has NEEDS_MECHANISM, add_parser(sub, common, scaled)
#: and run(mech, args) -> exit code (mech is None when it needs none).
COMMANDS = ()
_COMMAND_MODULES = {}


def _register(*modules):
    global COMMANDS
    COMMANDS = COMMANDS + tuple(modules)
    _COMMAND_MODULES.update({m.NAME: m for m in modules})


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # a value that starts with a minus and a digit is a value, units and all: --to -90deg, --from -1e-3
        self._negative_number_matcher = re.compile(r"^-\.?[0-9]")

    def error(self, message):  # one line (the arguments quoted in it are bounded and escaped), exit code 2

        self.exit(2, f"screwkin: error: {one_line(message, MESSAGE_LIMIT)}\n")

    def parse_known_args(self, args=None, namespace=None):
        # every (sub)parser checks its own options: no empty values, outputs writable (commands/_options.py)
        ns, rest = super().parse_known_args(args, namespace)
        try:
            check_parsed(self, ns)
        except UsageError as exc:
            self.error(str(exc))
        return ns, rest


def _names(text):
    return [n.strip() for n in text.split(",") if n.strip()] if text else None


def _parser():
    p = _Parser(prog="screwkin", description="Screw-theory analysis of spatial mechanisms described in URDF.")
    p.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    p.add_argument("--version", action="version", version=f"screwkin {screwkin_version()}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser, title="commands",
                           metavar="COMMAND")

    def common(sp, mechanism: bool = True, optional_file: bool = False):
        """The options every command takes (with mechanism=False: no FILE and no mechanism options)."""
        if not mechanism:
            sp.add_argument("--json", action="store_true", help="print one JSON object")
            sp.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                            help="show tracebacks of errors")
            return
        sp.add_argument("file", help="URDF (with <loop_joint> or a YAML sidecar), SDF, or xacro file",
                        **({"nargs": "?"} if optional_file else {}))
        sp.add_argument("--arg", action="append", dest="xacro_args", metavar="NAME=VALUE",
                        help="xacro argument of a .xacro file (units allowed, e.g. crank=30mm: given in SI); "
                             "repeatable")
        sp.add_argument("--yaml", help="Extended-URDF sidecar (default: FILE with .yaml suffix, if present)")
        sp.add_argument("--json", action="store_true", help="print one JSON object")
        # SUPPRESS: when absent after the command, the top-level --debug (before the command) is kept
        sp.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show tracebacks of errors")
        sp.add_argument("--actuated", help="actuated joints, comma separated (overrides the file)")
        sp.add_argument("--package-dir", action="append", dest="package_dirs", metavar="DIR",
                        help="folder holding ROS packages (or a package) for package:// meshes, searched before "
                             "ROS_PACKAGE_PATH; repeatable")

    at_configuration, angles = add_configuration_options, add_angle_option

    def scaled(sp, point=True):
        sp.add_argument("--length", help="characteristic length that makes the measures dimensionless "
                                         "(default: the mean link length; printed with every measure)")
        if point:
            add_point_option(sp, "--point alone: analyse the output link's origin as a point (3 translations) "
                                 "instead of its full motion")

    m = sub.add_parser("mobility", help="degrees of freedom: counts and screw-theory mobility")
    common(m)
    m.add_argument("--output", help="link whose motion to characterize (e.g. the platform)")
    m.add_argument("--point", action="store_true", help="the output link's origin as a point (3 translations)")
    i = sub.add_parser("info", help="topology table: links, joints, loops (--joint-types: the joint vocabulary)")
    common(i, optional_file=True)
    i.add_argument("--joint-types", action="store_true",
                   help="list every joint type screwkin knows (DOF, motion, pair, contact); needs no FILE")
    s = sub.add_parser("solve", help="position, velocity and acceleration for given input values")
    common(s)
    s.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="input joint value, SI or with a unit (45deg, 30mm); repeat or comma-separate")
    angles(s)
    add_length_option(s)
    s.add_argument("--all", action="store_true",
                   help="show every assembly mode, also those the mechanism cannot reach by moving")
    s.add_argument("--near", metavar="NAME=VALUE,...", help="report only the assembly mode nearest this configuration")
    s.add_argument("--output", help="link whose pose (and twist) to report")
    add_point_option(s)
    s.add_argument("--rate", action="append", metavar="NAME=VALUE", help="input joint rate [1/s] (units as --set)")
    s.add_argument("--accel", action="append", metavar="NAME=VALUE", help="input joint acceleration [1/s^2]")
    s.add_argument("--trace", action="store_true", help="print the Newton iterations (residual, Jacobian, step)")
    s.add_argument("--starts", type=count("starts"), default=24, help="random starting configurations (default 24)")
    s.add_argument("--start", action="append", metavar="NAME=VALUE,...",
                   help="planar: Newton on the vector-loop equations (screwkin equations) from these estimates of "
                        "the unknowns: symbols (theta3, x4), link names (their angles) or passive joint values")
    s.add_argument("--iterations", type=count("iterations"), metavar="K",
                   help="with --start: exactly K Newton iterations, each printed (residual, Jacobian, step, "
                        "estimates); without it Newton goes on to convergence")
    scaled(s, point=False)
    c = sub.add_parser("screws", help="product-of-exponentials structure equations and joint screws")
    common(c)
    at_configuration(c)
    c.add_argument("--output", help="also the chain to this link")
    g = sub.add_parser("singularities", help="classify the singularities of a configuration")
    common(g)
    at_configuration(g)
    g.add_argument("--output", help="output link (for serial singularities and the output twist)")
    g.add_argument("--ellipsoids", action="store_true",
                   help="the output's velocity and force ellipsoids for the inputs (needs --output)")
    g.add_argument("--symbolic", action="store_true",
                   help="planar loops: each joint's Gram cofactor as a formula in the symbols of screwkin equations, "
                        "and where it vanishes (the joint is stationary)")
    scaled(g)
    mp = sub.add_parser("map", help="map of the smallest singular value over two inputs")
    common(mp)
    mp.add_argument("--x", required=True, metavar="NAME=A:B:N", help="first input, from A to B in N values")
    mp.add_argument("--y", required=True, metavar="NAME=A:B:N", help="second input")
    mp.add_argument("--set", action="append", metavar="NAME=VALUE", help="values of the other inputs")
    mp.add_argument("--output", help="output link (serial singularities)")
    mp.add_argument("--png", help="heat map with the singular curves, PNG (needs matplotlib)")
    mp.add_argument("--csv", help="the map's data as CSV")
    scaled(mp)
    sc = sub.add_parser("scan", help="singularity scan of a serial chain over random configurations")
    common(sc)
    sc.add_argument("--output", required=True, help="the chain's last link (e.g. the flange)")
    sc.add_argument("--samples", type=count("samples"), default=100000, help="random configurations (default 100000)")
    sc.add_argument("--seed", type=count("seed"), default=0, help="random seed (default 0)")
    sc.add_argument("--measure", choices=["sigma_ratio", "det"], default="sigma_ratio",
                    help="smallest / largest singular value (default) or the determinant (6 joints)")
    scaled(sc)
    sc.add_argument("--threads", type=count("threads"), help="threads (default: the machine's cores)")
    sc.add_argument("--csv", help="write every sample (joint values and the measure) to this CSV file")
    v = sub.add_parser("view", help="show the mechanism in meshcat (server on 127.0.0.1, or --html/--png)")
    common(v)
    at_configuration(v)
    v.add_argument("--output", help="output link: its frame is drawn, singularities are marked on it")
    v.add_argument("--sweep", metavar="NAME=A:B:N", help="animate the motion of one input (other inputs from --set)")
    v.add_argument("--html", help="write a self-contained static HTML page of the scene and exit")
    v.add_argument("--png", help="write a picture of the scene (headless Chromium) and exit")
    scaled(v, point=False)
    k = sub.add_parser("ik", help="inverse kinematics: joint values that place an output link at a pose")
    common(k)
    k.add_argument("--output", required=True, help="the link to place")
    k.add_argument("--pose", required=True, help='"x y z roll pitch yaw" (m and rad; units allowed, e.g. 30deg)')
    k.add_argument("--starts", type=count("starts"), default=16, help="random starting configurations (default 16)")
    k.add_argument("--all", action="store_true",
                   help="show every assembly mode, also those the mechanism cannot reach by moving")
    w = sub.add_parser("sweep", help="track one assembly mode along an input motion")
    common(w)
    w.add_argument("--input", required=True, help="the input joint to move")
    w.add_argument("--from", dest="start", required=True, help="first input value (SI or with a unit)")
    w.add_argument("--to", dest="stop", required=True, help="last input value")
    w.add_argument("--steps", type=count("steps"), default=100, help="number of steps (default 100, at most 100,000)")
    w.add_argument("--set", action="append", metavar="NAME=VALUE", help="values of the other inputs")
    w.add_argument("--inputs", help="input joints, comma separated (default: the actuated joints)")
    w.add_argument("--near", metavar="NAME=VALUE,...", help="start on the assembly mode nearest this configuration")
    w.add_argument("--rate", default="1", help="input rate for the joint rates and accelerations (default 1 /s)")
    w.add_argument("--csv", help="write the joint values, rates and accelerations per step to this CSV file")
    w.add_argument("--rows", metavar="N|all", help="rows of the text tables (default about 11; all: every step)")
    w.add_argument("--plot", help="draw the joint values against the input into this PNG file (needs matplotlib)")
    w.add_argument("--singularities", action="store_true",
                   help="locate the singular input values along the motion (refined to 1e-9)")
    w.add_argument("--output", help="output link (serial singularities)")
    w.add_argument("--turn", action="store_true",
                   help="pass through limit positions onto the other branch (the input runs back) until the "
                        "mechanism returns to its start or the input reaches --to")
    scaled(w)
    for command in COMMANDS:  # the commands kept in modules of their own (screwkin/commands/)
        command.add_parser(sub, common, scaled)
    return p


def _run(args):
    command = _COMMAND_MODULES.get(args.command)
    if command is not None and not command.NEEDS_MECHANISM:
        return command.run(None, args)
    if args.command == "info" and args.joint_types:
        if args.json:
            print(json.dumps({"joint_types": joint_types_dict(JOINT_TYPES)}, indent=2))
        else:
            print(joint_types_text(JOINT_TYPES))
        return 0
    if args.file is None:
        raise UsageError(f"{args.command} needs a FILE" + (" (or --joint-types)" if args.command == "info" else ""))
    mech = load(args.file, yaml=args.yaml, actuated=_names(getattr(args, "actuated", None)),
                package_dirs=args.package_dirs, args=parse_xacro_args(args.xacro_args))
    if getattr(args, "length", None):
        mech.length = parse_length(args.length, "--length")
    if isinstance(getattr(args, "output", None), str):  # every command's output link exists (sweep, draw...)
        mech.link_frame(args.output)
    if args.command == "info":
        try:
            q = mech.assemble().q
            note = None
        except ScrewkinError as exc:
            q = mech.neutral()
            note = f"not assembled ({exc}); geometry read at the file's configuration"
        topo = mech.topology(q)
        if args.json:
            d = topology_dict(topo)
            d.update({"file": mech.path, "actuated": mech.actuated, "cut_joints": [c.name for c in mech.cuts],
                      "coordinates": mech.nv, "assembled": note is None})
            print(json.dumps(to_jsonable(d), indent=2))
        else:
            print(topology_text(topo, f"Topology of {mech.path}"))
            print(f"actuated: {', '.join(mech.actuated) or 'none declared'}")
            if note:
                print(f"note: {note}")
        return 0
    handlers = {"solve": _solve, "sweep": _sweep, "ik": _ik, "screws": _screws,
                "singularities": _singularities, "map": _map, "view": _view, "scan": _scan}
    if command is not None:
        return command.run(mech, args)
    if args.command in handlers:
        return handlers[args.command](mech, args)
    if args.point and not args.output:
        raise UsageError("--point needs --output LINK")
    result = analyze_mobility(mech, output=args.output, point=args.point)
    if args.json:
        print(json.dumps(to_jsonable(mobility_dict(result)), indent=2))
    else:
        print(mobility_text(result))
    return 0


def _solve(mech, args):
    values = inputs(mech, args)
    if not values:
        raise UsageError("solve needs input values: --set NAME=VALUE, --set-angle LINK=ANGLE or --set-length LEG=LENGTH")
    near = joint_assignments(mech, [args.near], "--near") if args.near else None
    rates = joint_assignments(mech, args.rate, "--rate", order=1) if args.rate or args.accel else None
    accels = joint_assignments(mech, args.accel, "--accel", order=2) if args.accel else None
    if args.starts < 0:
        raise UsageError("--starts must be 0 or more")
    if args.start or args.iterations is not None:
        return equations_command.solve_from_start(mech, args, values)
    solver = PositionSolver(mech, list(values), output=args.output)
    res = solver.solve(values, near=near, rates=rates, accels=accels, starts=args.starts, trace=args.trace,
                       points=named_points(mech, args))
    if args.json:
        d = position_dict(res)
        d["characteristic_length"] = mech.length
        print(json.dumps(to_jsonable(d), indent=2))
        return 0
    if args.trace:
        names = [mech.coordinate_names[k] for k in solver.passive]
        print(trace_text(res, mech.closure.row_labels(solver=True), names))
        print()
    print(position_text(res, show_all=args.all, length=mech.length))
    return 0


def _screws(mech, args):
    if not mech.cuts and not args.output:
        raise UsageError(f"{mech.path}: the mechanism has no loops: give --output LINK for the chain to a link")
    q = configuration(mech, args)
    st = structure(mech, q, args.output)
    topo = mech.topology(q)
    normal = None
    if topo.motion_space == "planar":
        normal = topo.normal
    loops = loop_screws(mech)
    if args.json:
        print(json.dumps(to_jsonable({"motion_space": topo.motion_space, "chains": screws_dict(st, normal),
                                      "loops": loops_dict(loops, normal)}), indent=2))
    else:
        print(screws_text(st, normal))
        if loops:
            print(loops_text(loops, normal))
    return 0


def _singularities(mech, args):
    if args.point and not args.output:
        raise UsageError("--point needs --output LINK")
    if args.ellipsoids and not args.output:
        raise UsageError("--ellipsoids needs --output LINK")
    q = configuration(mech, args)
    rep = classify(mech, q, output=args.output, point=args.point)
    ell = ellipsoids(mech, q, args.output, point=args.point) if args.ellipsoids else None
    gram = symbolic_gram(mech, q, list(inputs(mech, args)) or None) if args.symbolic else None
    if args.json:
        d = singularity_dict(rep)
        if ell is not None:
            d["ellipsoids"] = ellipsoids_dict(ell)
        if gram is not None:
            d["gram_symbolic"] = gram_symbolic_dict(gram)
        print(json.dumps(to_jsonable(d), indent=2))
    else:
        print(singularity_text(rep))
        if ell is not None:
            print()
            print(ellipsoids_text(ell))
        if gram is not None:
            print()
            print(gram_symbolic_text(gram))
    return 0


def _range(text, option):
    name, sep, rest = text.partition("=")
    parts = rest.split(":")
    if not sep or len(parts) != 3:
        raise UsageError(f"{option} expects NAME=A:B:N, got '{text}'")
    try:
        n = count("grid")(parts[2])
    except argparse.ArgumentTypeError as exc:
        raise UsageError(f"{option}: N {exc}") from None

    return name.strip(), np.linspace(parse_value(parts[0]), parse_value(parts[1]), n)


def _map(mech, args):
    xn, xs = _range(args.x, "--x")
    yn, ys = _range(args.y, "--y")
    if xs.size * ys.size > BOUNDS["grid_total"][1]:
        raise UsageError(f"--x and --y: {xs.size:,} x {ys.size:,} = {xs.size * ys.size:,} configurations, "
                         f"at most {BOUNDS['grid_total'][1]:,}")
    fixed = joint_assignments(mech, args.set, "--set")
    inputs = list(mech.actuated) if {xn, yn} <= set(mech.actuated) else [xn, yn, *fixed]
    if args.point and not args.output:
        raise UsageError("--point needs --output LINK")
    res = singularity_map(PositionSolver(mech, inputs), xn, xs, yn, ys, fixed, args.output, args.point)
    if args.png:
        map_png(res, args.png)
    if args.csv:
        with open(args.csv, "w") as f:
            f.write(map_csv(res))
    if args.json:
        print(json.dumps(to_jsonable({"x": xn, "y": yn, "xs": res.xs, "ys": res.ys, "log10_sigma_min": res.log_sigma,
                                      "kind": res.kind, "characteristic_length": mech.length}), indent=2))
    else:
        finite = res.log_sigma[np.isfinite(res.log_sigma)]
        print(f"map of {xn} x {yn}: {res.log_sigma.size} points, {finite.size} assembled; "
              f"log10 sigma_min from {finite.min():.3g} to {finite.max():.3g} (L = {mech.length:.4g} m)"
              if finite.size else "no point assembled")
    return 0


def _scan(mech, args):
    t = time.perf_counter()
    res = scan(mech, args.output, args.samples, args.seed, args.measure, None, args.threads, point=args.point)
    elapsed = time.perf_counter() - t
    if args.csv:
        with open(args.csv, "w") as f:
            f.write(scan_csv(res))
    d = scan_dict(res)
    if args.json:
        print(json.dumps(to_jsonable({"file": mech.path, **d, "seconds": elapsed}), indent=2))
        return 0
    what = (("smallest / largest singular value of the output origin's velocity Jacobian (a point)"
             if res.point else "smallest / largest singular value of the output Jacobian (v / L, w)")
            + f", L = {res.length:.4g} m" if res.measure == "sigma_ratio" else "determinant of the output Jacobian (v, w)")
    worst = ", ".join(f"{n}={v:.6g}" for n, v in d["min_configuration"].items())
    p = d["percentiles"]
    print(f"scan of {mech.path}, chain to '{res.output}' ({len(res.joints)} joints): {res.samples} random "
          f"configurations within the joint limits (seed {res.seed}), {elapsed:.2f} s")
    print(f"measure: {what}")
    print(f"  nearest a singularity: {d['min']:.3g} at {worst}")
    print(f"  |measure| percentiles: 1% {p['1']:.3g}, 5% {p['5']:.3g}, median {p['50']:.3g}; largest {d['max']:.3g}")
    if d["singular_fraction"] is not None:
        print(f"  singular (below {res.threshold:g}): {100 * d['singular_fraction']:.3g}% of the configurations")
    return 0


def _view(mech, args):
    q = configuration(mech, args)
    motion, singular = None, []
    if args.sweep:
        name, values = _range(args.sweep, "--sweep")
        fixed = {k: v for k, v in joint_assignments(mech, args.set, "--set").items() if k != name}
        inputs = list(mech.actuated) if name in mech.actuated else [name, *fixed]
        solver = PositionSolver(mech, inputs)
        res = sweep(solver, name, values[0], values[-1], len(values) - 1, fixed=fixed)
        motion = res.q
        q = res.q[0]
        for s in locate_singularities(solver, res, output=args.output):
            rep = classify(mech, s.q, output=args.output)
            twist = next((t for t in rep.singular_twists if t.kind == s.kind), None)
            singular.append((s.q, twist))
            print(f"singular ({s.kind}) at {name} = {s.input:.9g}")
    scene = build_scene(mech, q, output=args.output, singular=singular)
    with ViewerServer() as server:
        show(mech, scene, server.viewer, q, motion=motion)
        if args.html or args.png:
            html = server.viewer.static_html()
            title = os.path.basename(mech.path) + (f", {args.sweep.split('=')[0].strip()} swept" if args.sweep else "")
            if args.html:
                with open(args.html, "w") as f:
                    f.write(page(html, scene, title))
                print(f"wrote {args.html}")
            if args.png:
                with tempfile.TemporaryDirectory() as d:
                    path = os.path.join(d, "scene.html")
                    with open(path, "w") as f:
                        f.write(page(html, scene, title, controls=False, size=PICTURE))
                    screenshot(path, args.png)
                print(f"wrote {args.png}")
            return 0
        print(f"meshcat: {server.web_url}  (Ctrl-C to stop)", flush=True)
        try:
            while True:
                time.sleep(1)
        except KeyboardInterrupt:
            return 0


def _ik(mech, args):
    parts = args.pose.replace(",", " ").split()
    if len(parts) != 6:
        raise UsageError(f'--pose expects "x y z roll pitch yaw", got "{args.pose}"')
    v = [parse_value(p, "length" if k < 3 else "angle", "--pose") for k, p in enumerate(parts)]
    pose = pin.SE3(pin.rpy.rpyToMatrix(np.array(v[3:])), np.array(v[:3]))
    res = inverse_kinematics(mech, args.output, pose, starts=args.starts)
    if args.json:
        print(json.dumps(to_jsonable(position_dict(res)), indent=2))
    else:
        print(f"inverse kinematics of '{args.output}' at x y z = {v[0]:.6g} {v[1]:.6g} {v[2]:.6g} m, "
              f"roll pitch yaw = {v[3]:.6g} {v[4]:.6g} {v[5]:.6g} rad")
        print(f"search: damped Newton on the loops and the pose from {res.starts} starting configurations (the "
              f"assembled and the file's configurations, and random ones within the joint limits): {len(res.solutions)} distinct "
              f"branch{'es' if len(res.solutions) != 1 else ''} found; not exhaustive, --starts N tries more")
        shown = list(res.solutions) if args.all else list(res.physical) or list(res.solutions)
        if mech.actuated:
            for k, s in enumerate(shown, 1):
                print(f"solution {k} actuated: " + ", ".join(f"{n} = {s.joints[n]:.9g}" for n in mech.actuated))
        print(position_text(res, show_all=args.all).split("\n", 1)[1])
    return 0


def _rows(text):
    if text is None or text.strip().lower() == "all":
        return None if text is None else "all"
    try:
        return count("figure_steps")(text)
    except argparse.ArgumentTypeError as exc:
        raise UsageError(f"--rows: {exc} (or all)") from None


def _sweep(mech, args):
    fixed = joint_assignments(mech, args.set, "--set")
    inputs = _names(args.inputs) or (list(mech.actuated) if args.input in mech.actuated else [args.input, *fixed])
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
        mus = [identify(mech, mech.topology(q), q, args.input).transmission_angle for q in res.q]
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
        print(json.dumps(to_jsonable(d), indent=2))
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


def main(argv=None) -> int:
    """The command line.  Exit codes: 0 success, 1 invalid or unanalysable file, 2 usage
    error, 3 internal error (a bug: never caused by input), 141 when the reader of the
    output went away (``screwkin info F | head -1``): the shell's code for a process ended
    by SIGPIPE, as ``cat`` or ``grep`` report it, so ``set -o pipefail`` scripts see screwkin
    like any other tool; nothing is printed then.

    Errors are one line on stderr, ``screwkin: error: FILE: PROBLEM``, at most about
    MESSAGE_LIMIT characters after the path, control characters escaped; ``--debug``
    (before or after the command) prints the traceback first, with the same exit code.
    """



    def say(line):
        try:
            print(line, file=sys.stderr)
        except (OSError, ValueError):  # stderr closed: nowhere to say it
            pass

    parser = _parser()
    if not (sys.argv[1:] if argv is None else argv):  # bare `screwkin`: what it can do, a line a command
        print(parser.format_help())
        return 0
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # usage errors (2), --help and --version (0): main(argv) returns its code
        return exc.code if isinstance(exc.code, int) else 2
    debug = bool(getattr(args, "debug", False))
    paths = [str(p) for p in (getattr(args, "file", None), getattr(args, "yaml", None)) if p]
    limit = MESSAGE_LIMIT + 40 + max((len(p) for p in paths), default=0)  # the problem, "(and N more)", the path
    try:
        # numpy's floating-point RuntimeWarnings (overflow in a singular configuration...) are not messages for
        # the user: screwkin reports what matters itself, as "warning: FILE: ..." lines or in the results
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            code = _run(args)
        sys.stdout.flush()
        return code
    except BrokenPipeError:  # https://docs.python.org/3/library/signal.html#note-on-sigpipe
        try:  # stdout to /dev/null, so that the interpreter's last flush does not fail again
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            os.close(devnull)
        except (OSError, ValueError, AttributeError):  # no real stdout (captured in process): nothing to redirect
            pass
        return 141
    except ScrewkinError as exc:
        if debug:
            traceback.print_exc()
        say(f"screwkin: error: {one_line(str(exc), limit)}")
        return exc.exit_code
    except KeyboardInterrupt:  # pragma: no cover
        return 130
    except Exception as exc:  # a bug in screwkin, not a problem of the input: still one line, exit 3
        if debug:
            traceback.print_exc()
        where = f" on {one_line(paths[0], 200)}" if paths else ""
        say(f"screwkin: internal error{where}: {type(exc).__name__}: {one_line(str(exc), 200)} "
            "(a bug in screwkin: run again with --debug for the traceback and report it)")
        return 3


# the commands in modules of their own, one line each:
_register(statics_command)
_register(study_command)
_register(synthesize)
_register(grasp)
_register(workspace_command)
_register(equations_command)
_register(draw)
_register(report_command)

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
