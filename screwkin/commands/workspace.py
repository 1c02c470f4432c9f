"""``screwkin workspace``: where an output link can go at a constant orientation (or its origin
with any), the part free of singularities, and the conditioning over it."""

from __future__ import annotations

import os
import tempfile

import numpy as np
import pinocchio as pin

from ..analysis.design.workspace import DEFAULT_THRESHOLD, workspace
from ..errors import UsageError, quote
from ..present.jsonout import json_of
from ..present.outfile import write_output
from ..present.view import build_scene, screenshot, show
from ..present.viewserver import ViewerServer
from ..present.workspace import (
    workspace_cloud,
    workspace_csv,
    workspace_dict,
    workspace_png,
    workspace_text,
)
from ..units import parse_length, parse_value
from ._configuration import add_mode_option, configuration, with_mode
from ._output_frame import add_point_option, add_tool_option, output_frame, output_frame_dict, output_frame_line
from ._options import count, seconds
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

NAME = "workspace"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable[..., None], scaled: Callable[..., None]) -> None:
    sp = sub.add_parser(NAME, help="workspace of an output link: volume, singularity-free part, conditioning")
    common(sp)
    sp.add_argument("--output", help="the link whose workspace to find (e.g. the platform; or its --tool frame's)")
    add_point_option(sp, "--point alone: the link's origin (the --tool's origin) as a point, any orientation "
                         "(default: the link at a constant orientation)")
    add_tool_option(sp)
    sp.add_argument("--orientation", metavar='"ROLL PITCH YAW"',
                    help="the constant orientation (rad, or with units: 10deg); default: the link's orientation in "
                         "the assembled configuration")
    sp.add_argument("--resolution", metavar="H", help="grid step (m, or with units: 5mm); default: about 24 steps "
                                                      "across the workspace in 3-D, 120 in a plane")
    sp.add_argument("--bounds", metavar="LO:HI,...", help="range along each grid axis, world coordinates (e.g. "
                                                          "-0.3:0.3,-0.3:0.3,-0.6:-0.1; units allowed)")
    sp.add_argument("--threshold", type=float, default=DEFAULT_THRESHOLD,
                    help=f"smallest actuator and serial measure of a singularity-free point (default {DEFAULT_THRESHOLD})")
    sp.add_argument("--method", choices=["grid", "sampling"],
                    help="grid: inverse kinematics on a grid (default); sampling: random joint values (serial chains, "
                         "--point; the default there)")
    sp.add_argument("--samples", type=count("workspace_samples"), default=200_000, help="joint configurations of the sampling method "
                                                                 "(default 200000)")
    sp.add_argument("--seed", type=count("seed"), default=0, help="random seed of the sampling method (default 0)")
    sp.add_argument("--timeout", type=seconds("timeout"), default=60.0,
                    help="seconds the grid may grow (default 60): past them it stops and the result says it is cut")
    add_mode_option(sp, "the inputs' values in the file's assembled configuration")
    sp.add_argument("--png", help="slices of the workspace coloured by conditioning, PNG (needs matplotlib)")
    sp.add_argument("--csv", help="every reached point: position, measures, joint values")
    sp.add_argument("--html", help="the mechanism and the workspace as a meshcat point cloud, static HTML page")
    sp.add_argument("--cloud-png", dest="cloud_png", help="a picture of that scene (headless Chromium)")
    scaled(sp, point=False)


def _bounds(text: str) -> np.ndarray | None:
    if text is None:
        return None
    ranges = []
    for part in text.split(","):
        lo, sep, hi = part.strip().partition(":")
        if not sep:
            raise UsageError(f"--bounds expects LO:HI ranges separated by commas, got {quote(text, 80)}")
        ranges.append((parse_value(lo.strip(), "length", "--bounds"), parse_value(hi.strip(), "length", "--bounds")))
    return np.array(ranges)


def _orientation(text: str):
    if text is None:
        return None
    parts = text.replace(",", " ").split()
    if len(parts) != 3:
        raise UsageError(f'--orientation expects "roll pitch yaw", got {len(parts)} numbers')
    return pin.rpy.rpyToMatrix(np.array([parse_value(p, "angle", "--orientation") for p in parts]))


def _mode(mech: Mechanism, args: argparse.Namespace) -> np.ndarray | None:
    """The assembled configuration of the mode whose workspace is asked (--mode K of the actuated joints'
    values in the file's assembled configuration, said as every command says it); None for a chain
    without loops, whose joint values are one configuration."""
    if not (mech.cuts or mech.extra_rows):
        if args.mode not in (None, 1):
            raise UsageError(f"--mode {args.mode}: {mech.path} has no loops: its joint values give one configuration")
        return None
    q0 = mech.generic_configurations()[0].q
    inputs = [n for n in mech.actuated if mech.coordinate(n).nv == 1]
    if not inputs:  # nothing declared: the file's assembly is the one configuration there is to start from
        return None
    values = mech.joint_values(q0)
    return configuration(mech, args, moved={n: values[n] for n in inputs}, inputs=inputs)


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    if args.samples < 1:
        raise UsageError(f"--samples must be positive, got {args.samples}")
    length = parse_length(args.length, "--length") if args.length else None
    output, point = output_frame(mech, args, required=True)
    if args.points and args.orientation is not None:
        raise UsageError("--orientation: a named --point has no orientation of its own (its workspace is its "
                         "positions); use --tool x,y,z for a frame at that place")
    res = workspace(mech, output, point=point, orientation=_orientation(args.orientation),
                    resolution=parse_length(args.resolution, "--resolution") if args.resolution else None,
                    bounds=_bounds(args.bounds), threshold=args.threshold, length=length, method=args.method,
                    samples=args.samples, seed=args.seed, timeout=args.timeout, q_start=lambda: _mode(mech, args))
    wrote = []
    if args.csv:
        columns = [(c.joint, c.idx_q) for c in mech.coordinates if c.nq == 1]
        workspace_csv(res, args.csv, columns)
        wrote.append(args.csv)
    if args.png:
        workspace_png(res, args.png)
        wrote.append(args.png)
    if args.html or args.cloud_png:
        q = res.configurations[0] if res.configurations is not None else mech.generic_configurations()[0].q
        with ViewerServer() as server:
            scene = build_scene(mech, q, output=mech.tool[1] if mech.tool else args.output)
            scene.points = np.vstack([scene.points, res.positions])  # framed to the mechanism and its cloud
            show(mech, scene, server.viewer, q)
            workspace_cloud(res, server.viewer)
            html = server.viewer.static_html()
        if args.html:
            write_output(args.html, html)
            wrote.append(args.html)
        if args.cloud_png:
            with tempfile.TemporaryDirectory() as d:
                page = os.path.join(d, "workspace.html")
                with open(page, "w") as f:
                    f.write(html)
                screenshot(page, args.cloud_png)
            wrote.append(args.cloud_png)
    frame = None
    if mech.tool is not None:  # the named point or tool frame whose workspace it is, in the assembled configuration
        frame = output_frame_dict(mech, mech.generic_configurations()[0].q)
    if args.json:
        d = with_mode(args, workspace_dict(res))
        d["wrote"] = wrote
        if frame is not None:
            d["output_frame"] = frame
        print(json_of(d))
    else:
        if frame is not None:
            print(output_frame_line(frame, bool(args.points)))
        print(workspace_text(res))
        for w in wrote:
            print(f"wrote {w}")
    return 0
