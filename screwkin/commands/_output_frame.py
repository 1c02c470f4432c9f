"""The output a command analyses: a named point on a link (--point NAME=LINK:x,y,z), a tool frame on
the --output link (--tool), and that frame as JSON and as one line of text."""

from __future__ import annotations

import argparse
import math

import numpy as np
import pinocchio as pin

from ..analysis.motion.links import Point
from ..errors import UsageError, quote
from ..model.state import KinematicState, place_tool
from ..units import parse_value
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["PointOption", "add_point_option", "named_points", "add_tool_option", "parse_tool", "output_frame",
           "output_frame_dict", "output_frame_line"]


class PointOption(argparse.Action):
    """``--point`` alone: the output link's origin analysed as a point (``args.point = True``, as
    before); ``--point NAME=LINK:x,y,z``: a named point on a link (``args.points``), repeatable."""

    def __call__(self, parser, namespace: argparse.Namespace, value: str | None, option_string: str | None=None) -> None:
        if value is None:
            namespace.point = True
        else:
            namespace.points = [*(getattr(namespace, "points", None) or []), value]


def add_point_option(sp: argparse.ArgumentParser, origin_help: str | None = None) -> None:
    """--point: named points NAME=LINK:x,y,z (and, with ``origin_help``, --point alone as before)."""
    sp.set_defaults(point=False, points=None)
    help = ("a point on a link, NAME=LINK:x,y,z in the link's frame (units allowed: P=coupler:60mm,20mm,0); "
            "its position, velocity and acceleration are reported; repeatable")
    if origin_help:
        help = f"{origin_help}; or {help}"
    sp.add_argument("--point", nargs="?", action=PointOption, metavar="NAME=LINK:x,y,z", help=help)


def named_points(mech: Mechanism, args: argparse.Namespace) -> tuple:
    """The analysis.motion.links.Point objects of --point NAME=LINK:x,y,z (links checked, names unique)."""
    out, seen = [], set()
    for text in getattr(args, "points", None) or []:
        name, sep, rest = text.rpartition("=")
        link, sep2, coords = rest.partition(":")
        parts = [c for c in coords.replace(" ", ",").split(",") if c.strip()]
        if not sep or not sep2 or not name.strip() or not link.strip() or len(parts) not in (2, 3):
            raise UsageError(f"--point expects NAME=LINK:x,y,z (or x,y in the plane z = 0), got {quote(text, 80)}")
        name, link = name.strip(), link.strip()
        if name in seen:
            raise UsageError(f"--point: the name {quote(name)} is given twice")
        seen.add(name)
        mech.link_frame(link)  # a clear error for an unknown link
        # each coordinate a length within units.MAGNITUDES (10 km, a file's positions: 1e308 m gave inf answers)
        local = tuple(parse_value(c, "length", f"--point {name}") for c in parts) + ((0.0,) if len(parts) == 2 else ())
        out.append(Point(name, link, local))
    return tuple(out)


def add_tool_option(sp: argparse.ArgumentParser) -> None:
    """--tool x,y,z[,roll,pitch,yaw]: the output frame moved on the output link."""
    sp.add_argument("--tool", metavar="x,y,z[,roll,pitch,yaw]",
                    help="a tool frame on the --output link, placed in the link's frame (units allowed: "
                         "0,0,60mm or 0.1,0,0,0,0,90deg): its pose, twist and Jacobian replace the link frame's")


def parse_tool(text: str):
    """``x,y,z[,roll,pitch,yaw]`` (m and rad, units allowed) -> a pinocchio.SE3 in the link's frame."""
    parts = [c for c in text.replace(" ", ",").split(",") if c.strip()]
    if len(parts) not in (3, 6):
        raise UsageError(f"--tool expects x,y,z or x,y,z,roll,pitch,yaw, got {len(parts)} numbers in {quote(text, 80)}")
    v = [parse_value(c, "length" if k < 3 else "angle", "--tool") for k, c in enumerate(parts)]  # (bounded by kind)
    rpy = np.array(v[3:] if len(v) == 6 else [0.0, 0.0, 0.0])
    return pin.SE3(pin.rpy.rpyToMatrix(rpy), np.array(v[:3]))


def output_frame(mech: Mechanism, args: argparse.Namespace, required: bool = False) -> tuple:
    """The output a command analyses, from --output, --tool and a named --point: ``(name, point)``.

    ``--tool`` moves the output frame onto the --output link (named ``LINK@tool``); a named
    ``--point NAME=LINK:x,y,z`` makes that point the output (its link's orientation, analysed as a
    point: ``point`` is True); ``--point`` alone keeps its meaning (the output link's origin as a point).
    ``name`` is what mech.link_frame takes (None when no output is given and none is ``required``)."""
    output, tool = getattr(args, "output", None), getattr(args, "tool", None)
    named = named_points(mech, args)
    if len(named) > 1:
        raise UsageError(f"--point: this command takes one named point as its output, got {len(named)}")
    if named:
        p = named[0]
        if tool is not None:
            raise UsageError("--tool and a named --point both move the output frame: give one of them")
        if output is not None and output != p.link:
            raise UsageError(f"--point {p.name} is on {quote(p.link)}, not on the --output link {quote(output)}")
        return place_tool(mech, p.name, p.link, pin.SE3(np.eye(3), np.asarray(p.local, float))), True
    if output is None:
        if tool is not None:
            raise UsageError("--tool needs --output LINK (the link the tool is on)")
        if required:
            raise UsageError("give --output LINK (or a named --point NAME=LINK:x,y,z)")
        return None, bool(getattr(args, "point", False))
    if tool is not None:
        return place_tool(mech, f"{output}@tool", output, parse_tool(tool)), bool(getattr(args, "point", False))
    return output, bool(getattr(args, "point", False))


def output_frame_dict(mech: Mechanism, q: np.ndarray, jacobian: bool = False, point: bool = False) -> dict | None:
    """JSON of the placed output frame (model.state.place_tool) at q: its name, link, placement on the
    link (x, y, z, roll, pitch, yaw) and world pose (position, rotation); with ``jacobian`` its frame
    Jacobian (world axes, rows (v, w) of its origin; only v for a ``point``: J_p = J_v - [r]x J_w, one
    column a velocity coordinate); None when none is placed."""
    if mech.tool is None:
        return None
    name, link, X = mech.tool
    state = KinematicState(mech, q)
    M = state.frame_placement(mech.tool_frame)
    out = {"name": name, "link": link, "local": [*X.translation.tolist(), *pin.rpy.matrixToRpy(X.rotation).tolist()],
           "position": M.translation.tolist(), "rotation": M.rotation.tolist()}
    if jacobian:
        J = state.frame_jacobian(mech.tool_frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        out["jacobian"] = (J[:3] if point else J).tolist()
        out["jacobian_columns"] = list(mech.coordinate_names)
    return out


def output_frame_line(frame: dict, point: bool) -> str:
    """One line saying which frame is the output (output_frame_dict), where it is on its link and in the world."""
    x = ", ".join(f"{v:.6g}" for v in frame["local"][:3])
    w = ", ".join(f"{v:.6g}" for v in frame["position"])
    if point:
        return f"output: the point {quote(frame['name'])} at ({x}) m on {quote(frame['link'])}, in the world at ({w}) m"
    rpy = ", ".join(f"{math.degrees(v):.6g}" for v in frame["local"][3:])
    return (f"output: the tool frame {quote(frame['name'])} at ({x}) m, roll pitch yaw ({rpy}) deg on "
            f"{quote(frame['link'])}, in the world at ({w}) m")
