"""screwkin ik: inverse kinematics: joint values that place an output link at a pose."""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin

from ..analysis.motion.ik import inverse_kinematics
from ..errors import UsageError, quote
from ..present.report import (
    position_dict,
    position_text,
    to_jsonable,
)
from ..units import parse_value
from ._common import add_point_option, add_tool_option, output_frame, output_frame_dict, output_frame_line
from ._options import count

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "ik"
NEEDS_MECHANISM = True


def add_parser(sub, common, scaled):
    sp = sub.add_parser("ik", help="inverse kinematics: joint values that place an output link at a pose")
    common(sp)
    sp.add_argument("--output", help="the link to place (or its --tool; or give a named --point)")
    sp.add_argument("--pose", help='"x y z roll pitch yaw" (m and rad; units allowed, e.g. 30deg): the pose of the '
                                   'output link (of its --tool frame with --tool)')
    sp.add_argument("--position", metavar="x,y,z",
                    help="only a position, any orientation: of the named --point, the --tool's origin, or the "
                         "output link's origin (units allowed, e.g. 60mm)")
    add_tool_option(sp)
    add_point_option(sp)
    sp.add_argument("--starts", type=count("starts"), default=16, help="random starting configurations (default 16)")
    sp.add_argument("--all", action="store_true",
                   help="show every assembly mode, also those the mechanism cannot reach by moving")


def run(mech, args) -> int:
    if (args.pose is None) == (args.position is None):
        raise UsageError("give one target: --pose \"x y z roll pitch yaw\" or --position x,y,z")
    if args.points and args.pose is not None:
        raise UsageError("a named --point has a position, no orientation: give --position x,y,z")
    text, n, option = (args.pose, 6, "--pose") if args.pose is not None else (args.position, 3, "--position")
    parts = text.replace(",", " ").split()
    if len(parts) != n:
        raise UsageError(f'--pose expects "x y z roll pitch yaw", got "{args.pose}"' if n == 6 else
                         f"--position expects x,y,z, got {quote(args.position, 80)}")
    v = [parse_value(p, "length" if k < 3 else "angle", option) for k, p in enumerate(parts)] + [0.0] * (6 - n)
    pose = pin.SE3(pin.rpy.rpyToMatrix(np.array(v[3:])), np.array(v[:3]))
    output, _ = output_frame(mech, args, required=True)
    res = inverse_kinematics(mech, output, pose, starts=args.starts, position_only=n == 3)
    # the output frame (point, tool) on its link; each solution's output_pose is that frame's
    frame = output_frame_dict(mech, res.solutions[0].q) if mech.tool is not None else None
    if args.json:
        d = position_dict(res)
        if frame is not None:
            d["output_frame"] = {k: frame[k] for k in ("name", "link", "local")}
        print(json.dumps(to_jsonable(d), indent=2))
    else:
        if frame is not None:
            print(output_frame_line(frame, args.tool is None).split(", in the world")[0])
        target = (f"roll pitch yaw = {v[3]:.6g} {v[4]:.6g} {v[5]:.6g} rad" if n == 6 else "any orientation")
        print(f"inverse kinematics of '{output}' at x y z = {v[0]:.6g} {v[1]:.6g} {v[2]:.6g} m, {target}")
        print(f"search: damped Newton on the loops and the pose from {res.starts} starting configurations (the "
              f"assembled and the file's configurations, and random ones within the joint limits): {len(res.solutions)} distinct "
              f"branch{'es' if len(res.solutions) != 1 else ''} found; not exhaustive, --starts N tries more")
        shown = list(res.solutions) if args.all else list(res.physical) or list(res.solutions)
        if mech.actuated:
            for k, s in enumerate(shown, 1):
                print(f"solution {k} actuated: " + ", ".join(f"{n} = {s.joints[n]:.9g}" for n in mech.actuated))
        print(position_text(res, show_all=args.all).split("\n", 1)[1])
    return 0
