"""screwkin ik: inverse kinematics: joint values that place an output link at a pose."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin

from ..analysis.position.ik import branches, inverse_kinematics
from ..errors import UsageError, quote
from ..analysis.singularities.mode_connect import serial_connections
from ..present.jsonout import json_of
from ..present.loci import connections_dict, connections_lines
from ..present.report import position_dict, position_text
from ..units import parse_value
from ._output_frame import add_point_option, add_tool_option, output_frame, output_frame_dict, output_frame_line
from ._options import count
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from screwkin.analysis.position.solution import PositionResult
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "ik"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable[..., None], scaled: Callable[..., None]) -> None:
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
    sp.add_argument("--connect", action="store_true",
                    help="with --all: for each pair of the solutions, whether det J's signs prove every path between "
                         "them meets a singularity (paths of the same sign are not searched: said so)")


def run(mech: Mechanism, args: argparse.Namespace) -> int:
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
    if args.connect and not args.all:
        raise UsageError("--connect needs --all: it compares the solutions --all lists")
    output, _ = output_frame(mech, args, required=True)
    res = inverse_kinematics(mech, output, pose, starts=args.starts, position_only=n == 3)
    # the output frame (point, tool) on its link; each solution's output_pose is that frame's
    frame = output_frame_dict(mech, res.solutions[0].q) if mech.tool is not None else None
    count = branches(mech, res)
    conns = None
    if args.connect:
        plain = mech.tool is None and not args.points  # the link's own origin: its Jacobian is the one compared
        conns = serial_connections(mech, output, [s.q for s in res.solutions], point=n == 3,
                                   target=v[:3] if n == 3 else None) if plain else \
            replace(serial_connections(mech, output, [], False), notes=(
                "--tool or --point: the det J of the tool frame is not compared; give the output link alone",))
    if args.json:
        d = position_dict(res)
        if conns is not None:
            d.update(connections_dict(conns, mech))
        d["branches"] = {"found": count.found, "at_most": count.at_most, "why": count.why or None,
                         "legs": [{"joints": list(j), "found": k, "at_most": m} for j, k, m in count.legs]}
        if frame is not None:
            d["output_frame"] = {k: frame[k] for k in ("name", "link", "local")}
        print(json_of(d))
    else:
        if frame is not None:
            print(output_frame_line(frame, args.tool is None).split(", in the world")[0])
        target = (f"roll pitch yaw = {v[3]:.6g} {v[4]:.6g} {v[5]:.6g} rad" if n == 6 else "any orientation")
        print(f"inverse kinematics of '{output}' at x y z = {v[0]:.6g} {v[1]:.6g} {v[2]:.6g} m, {target}")
        if res.free_dofs:  # the continuum first: what follows are samples of it
            print(f"note: the target leaves {res.free_dofs} degree{'s' if res.free_dofs != 1 else ''} of freedom free"
                  + (" (a position alone: the output may turn)" if n == 3 else "")
                  + f": the solutions form a continuum; the {len(res.solutions)} below are samples of it")
        c = res.modes
        if c is not None and c.method.startswith("closed form"):
            print(_closed_text(mech, res, count))
        elif c is not None and c.complete:
            print(f"search: homotopy continuation on the loops and the pose, every solution (certified: "
                  f"{c.certificate}): " + _found_text(count, res.free_dofs, certified=True)
                  + (f"; {c.complex} more complex" if c.complex else ""))
        else:
            print(f"search: {'homotopy continuation and ' if c is not None and c.method != 'random starts' else ''}"
                  f"damped Newton on the loops and the pose from {res.starts} starting configurations (the "
                  f"assembled and the file's configurations, and random ones within the joint limits): "
                  + _found_text(count, res.free_dofs)
                  + (f"; completeness not certified because {c.reason}" if c is not None and c.reason else ""))
        shown = list(res.solutions) if args.all else list(res.physical) or list(res.solutions)
        if mech.actuated:
            for k, s in enumerate(shown, 1):
                print(f"solution {k} actuated: " + ", ".join(f"{n} = {s.joints[n]:.9g}" for n in mech.actuated))
        # the continuum was said first: not again in the table's header
        print(position_text(replace(res, free_dofs=0), show_all=args.all).split("\n", 1)[1])
        if conns is not None:
            print()
            print("\n".join(connections_lines(conns, "solutions")))
    return 0


def _closed_text(mech: Mechanism, res: PositionResult, count) -> str:
    """The search line of a closed-form answer (analysis.position.closed_ik), and for a platform whose
    combinations are not all listed each leg's other branch beside the first solution."""
    c = res.modes
    ms = f" ({c.detail.get('seconds', 0) * 1e3:.3g} ms)"
    if c.method == "closed form (Pieper)":
        return (f"search: {c.certificate}: {c.real} real joint solution{'s' if c.real != 1 else ''}"
                + ", every one" + (f"; {c.complex} more complex" if c.complex else "") + ms)
    text = f"search: {c.certificate}: " + _found_text(count, res.free_dofs, certified=True) + ms
    if c.found > len(res.solutions):
        first = res.solutions[0]
        others = [f"{n} = {s.joints[n]:.6g} m" for s in res.solutions[1:] for n in mech.actuated
                  if abs(s.joints[n] - first.joints[n]) > mech.tolerances.zero]
        text += (f"\nlisted: the physical solution and each leg's other branch, reversed through its pivot "
                 f"(solutions 2 to {len(res.solutions)}; --all shows them in full): " + ", ".join(others))
    sets = c.detail.get("angle_sets", 1)
    if sets > 1:
        text += (f"\neach solution is reached by {sets} joint-angle sets (a universal joint's (a, b) and "
                 "(a + pi, pi - b) with its leg spun about its line, a spherical joint's two Euler sets): one pose; "
                 "shown in the set within the joint limits where one exists")
    return text


def _found_text(count, free: int, certified: bool = False) -> str:
    """'8 distinct branches found (legs: 2 x 2 x 2) of at most 8 (why): all of them', or how far from it
    (``certified``: the homotopy has them all, whatever the legs' bound)."""
    n = count.found
    what = ("solution" if n == 1 else "solutions") if free else ("branch" if n == 1 else "branches")
    text = f"{n} distinct {what} found"
    if count.legs and count.at_most is not None:
        text += " (legs: " + " x ".join(str(k) for _, k, _ in count.legs) + f") of at most {count.at_most} ({count.why})"
        return text + (": all of them" if count.complete or certified else "; --starts N tries more")
    return text + (": all of them" if certified else "; not exhaustive, --starts N tries more")
