"""screwkin ik: inverse kinematics: joint values that place an output link at a pose."""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin

from ..analysis.motion.ik import inverse_kinematics
from ..errors import UsageError
from ..present.report import (
    position_dict,
    position_text,
    to_jsonable,
)
from ..units import parse_value
from ._options import count

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "ik"
NEEDS_MECHANISM = True


def add_parser(sub, common, scaled):
    sp = sub.add_parser("ik", help="inverse kinematics: joint values that place an output link at a pose")
    common(sp)
    sp.add_argument("--output", required=True, help="the link to place")
    sp.add_argument("--pose", required=True, help='"x y z roll pitch yaw" (m and rad; units allowed, e.g. 30deg)')
    sp.add_argument("--starts", type=count("starts"), default=16, help="random starting configurations (default 16)")
    sp.add_argument("--all", action="store_true",
                   help="show every assembly mode, also those the mechanism cannot reach by moving")


def run(mech, args) -> int:
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
