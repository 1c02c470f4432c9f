"""Writing a planar linkage as URDF text (the ``<loop_joint>`` form of docs/format.md).

The input is a plain description -- links with the joint centres on them, the tree
joints that place them, one loop (cut) joint per independent loop, the actuated joints --
given at one configuration: the file's configuration is that one, every tree-joint
coordinate at zero.  This module knows nothing of solving: whoever describes the linkage
places the links (closed, if the file must be drawn closed).

Every link is drawn in the plane z = 0: a bar (box) between neighbouring joint centres on
it, a short cylinder at each joint centre (along z, the axis of every revolute joint), a
box for a slider; it gets an inertial (slender bars of ``density`` kg/m).  Revolute joints
turn about z; prismatic joints slide along an axis in the plane.  The actuated joints get a
``<transmission>`` each.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import pinocchio as pin

from ..tolerances import DEFAULT
from .description import TARGETS_NS
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any

__all__ = ["PlanarLink", "PlanarJoint", "PlanarLoopJoint", "PlanarLinkage", "write_urdf", "number_text", "vector_text",
           "origin_text", "targets_text", "quoteattr"]

_COLOURS = ((0.35, 0.35, 0.35), (0.85, 0.3, 0.2), (0.2, 0.5, 0.85), (0.2, 0.7, 0.3), (0.85, 0.65, 0.1),
            (0.6, 0.3, 0.75), (0.1, 0.7, 0.7), (0.9, 0.45, 0.6))


@dataclass(frozen=True)
class PlanarLink:
    """A link: the points drawn on it (joint centres, a coupler point) in its own frame [m].

    frame_only: a frame welded to another link (a coupler frame or point): drawn as a small
    sphere, no inertial of its own."""

    name: str
    points: tuple = ()  # ((x, y), ...) in the link's frame
    frame_only: bool = False
    slider: bool = False  # drawn as a block around its first point


@dataclass(frozen=True)
class PlanarJoint:
    """A tree joint: the child's frame is placed at ``xyz`` in the parent's frame, turned by
    ``angle`` about z.  ``axis``: the motion axis in the child's frame ((0, 0, 1) for a
    revolute joint, in the plane for a prismatic one)."""

    name: str
    type: str  # "revolute" | "prismatic" | "fixed"
    parent: str
    child: str
    xyz: tuple  # (x, y) [m]
    angle: float = 0.0  # [rad]
    axis: tuple = (0.0, 0.0, 1.0)
    lower: float = -2 * math.pi
    upper: float = 2 * math.pi


@dataclass(frozen=True)
class PlanarLoopJoint:
    """A cut joint: frame F1 at ``xyz1`` (turned ``angle1``) on link1, F2 at ``xyz2`` (turned
    ``angle2``) on link2; ``axis`` in F1."""

    name: str
    type: str  # "revolute" | "prismatic"
    link1: str
    xyz1: tuple
    link2: str
    xyz2: tuple
    angle1: float = 0.0
    angle2: float = 0.0
    axis: tuple = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class PlanarLinkage:
    name: str
    links: tuple  # PlanarLink, the ground (the tree's root) first
    joints: tuple  # PlanarJoint
    loop_joints: tuple = ()  # PlanarLoopJoint, one per independent loop
    actuated: tuple = ()  # joint names
    comment: str = ""
    width: float = 0.0  # bar width [m]; 0: 4 % of the mean bar length
    density: float = 1.0  # [kg/m] of bar
    colours: dict = field(default_factory=dict)  # link name -> (r, g, b)
    targets: tuple = ()  # files.description.TargetSpec: written as <screwkin:targets>


def quoteattr(data: str) -> str:
    """An XML attribute value with its quotes, xml.sax.saxutils.quoteattr's text (& < > and newlines,
    carriage returns and tabs escaped; single quotes around a value holding " but no ', else double
    quotes with " as &quot;), without importing xml.sax.saxutils (it imports urllib.request, http, ssl
    and email: 15 ms of every command's start-up)."""
    data = data.replace("&", "&amp;").replace(">", "&gt;").replace("<", "&lt;")
    data = data.replace("\n", "&#10;").replace("\r", "&#13;").replace("\t", "&#9;")
    if '"' not in data:
        return f'"{data}"'
    if "'" not in data:
        return f"'{data}'"
    return '"%s"' % data.replace('"', "&quot;")


def number_text(x: float) -> str:
    x = float(x)
    return repr(0.0 if x == 0 else x)


def vector_text(*xs: Any) -> str:
    return " ".join(number_text(x) for x in xs)


def origin_text(M: pin.SE3) -> str:
    """The URDF ``<origin>`` of a placement M (pinocchio.SE3): its translation and its rotation as rpy."""
    return f'<origin xyz="{vector_text(*M.translation)}" rpy="{vector_text(*pin.rpy.matrixToRpy(M.rotation))}"/>'


def _bars(points: tuple) -> list:
    """Pairs of points drawn as bars: the one segment of two points, the closed polygon of
    more (points in order of angle about their centroid)."""
    pts = [tuple(map(float, p)) for p in points]
    if len(pts) < 2:
        return []
    if len(pts) == 2:
        return [(pts[0], pts[1])]
    cx = sum(p[0] for p in pts) / len(pts)
    cy = sum(p[1] for p in pts) / len(pts)
    ring = sorted(pts, key=lambda p: math.atan2(p[1] - cy, p[0] - cx))
    return [(ring[k], ring[(k + 1) % len(ring)]) for k in range(len(ring))]


def _check_linkage(linkage: PlanarLinkage) -> None:
    names = [lk.name for lk in linkage.links]
    if len(set(names)) != len(names):
        raise ValueError("link names repeat")
    joint_names = [j.name for j in linkage.joints] + [c.name for c in linkage.loop_joints]
    if len(set(joint_names)) != len(joint_names):
        raise ValueError("joint names repeat")
    children = [j.child for j in linkage.joints]
    if len(set(children)) != len(children) or names[0] in children or set(children) != set(names[1:]):
        raise ValueError("the joints do not make a tree rooted at the first link")
    known = set(names)
    for j in linkage.joints:
        if j.parent not in known or j.type not in ("revolute", "prismatic", "fixed"):
            raise ValueError(f"joint {j.name}: unknown parent or type")
    for c in linkage.loop_joints:
        if c.link1 not in known or c.link2 not in known or c.link1 == c.link2:
            raise ValueError(f"loop joint {c.name}: unknown or equal links")
    movable = {j.name for j in linkage.joints if j.type != "fixed"}
    if not set(linkage.actuated) <= movable:
        raise ValueError("an actuated joint is not a moving tree joint")


def write_urdf(linkage: PlanarLinkage) -> str:
    """The URDF text of ``linkage`` (see the module docstring)."""
    _check_linkage(linkage)
    lengths = [math.dist(p, q) for lk in linkage.links if not lk.frame_only for p, q in _bars(lk.points)]
    lengths = [x for x in lengths if x > 0]
    mean = sum(lengths) / len(lengths) if lengths else 0.1
    w = linkage.width or 0.04 * mean
    out = ['<?xml version="1.0"?>']
    if linkage.comment:
        text = linkage.comment.replace("--", "- -")
        out.append("<!--\n" + text.rstrip() + "\n-->")
    space = f' xmlns:screwkin="{TARGETS_NS}"' if linkage.targets else ""
    out.append(f'<robot name="{linkage.name}"{space}>')
    for k, lk in enumerate(linkage.links):
        r, g, b = linkage.colours.get(lk.name, _COLOURS[k % len(_COLOURS)])
        material = f'<material name="m_{lk.name}"><color rgba="{vector_text(r, g, b, 1)}"/></material>'
        out.append(f'  <link name="{lk.name}">')
        if lk.frame_only:
            out.append(f'    <visual><geometry><sphere radius="{number_text(0.6 * w)}"/></geometry>{material}</visual>')
            out.append("  </link>")
            continue
        mass = 0.0
        mx = my = 0.0
        parts = []
        for p, q in _bars(lk.points):
            length = math.dist(p, q)
            if length <= DEFAULT.zero:
                continue
            c = ((p[0] + q[0]) / 2, (p[1] + q[1]) / 2)
            ang = math.atan2(q[1] - p[1], q[0] - p[0])
            out.append(f'    <visual><origin xyz="{vector_text(c[0], c[1], 0)}" rpy="{vector_text(0, 0, ang)}"/>'
                       f'<geometry><box size="{vector_text(length, w, w)}"/></geometry>{material}</visual>')
            m = linkage.density * length
            parts.append((m, c, length))
            mass += m
            mx += m * c[0]
            my += m * c[1]
        for p in lk.points:
            out.append(f'    <visual><origin xyz="{vector_text(p[0], p[1], 0)}"/><geometry><cylinder radius="{number_text(0.7 * w)}" '
                       f'length="{number_text(1.5 * w)}"/></geometry>{material}</visual>')
        if lk.slider and lk.points:
            p = lk.points[0]
            out.append(f'    <visual><origin xyz="{vector_text(p[0], p[1], 0)}"/><geometry><box size="{vector_text(3 * w, 2 * w, 2 * w)}"/>'
                       f'</geometry>{material}</visual>')
            m = linkage.density * 3 * w
            parts.append((m, (float(p[0]), float(p[1])), 3 * w))
            mass += m
            mx += m * p[0]
            my += m * p[1]
        if mass > 0:
            cx, cy = mx / mass, my / mass
            izz = sum(m * (length**2 / 12 + (c[0] - cx) ** 2 + (c[1] - cy) ** 2) for m, c, length in parts)
            izz += mass * w * w / 6
            ixx = iyy = izz / 2 + mass * w * w / 12
            out.append(f'    <inertial><origin xyz="{vector_text(cx, cy, 0)}"/><mass value="{number_text(mass)}"/>'
                       f'<inertia ixx="{number_text(ixx)}" iyy="{number_text(iyy)}" izz="{number_text(izz)}" ixy="0" ixz="0" iyz="0"/>'
                       "</inertial>")
        out.append("  </link>")
    for j in linkage.joints:
        out.append(f'  <joint name="{j.name}" type="{j.type}">')
        out.append(f'    <parent link="{j.parent}"/><child link="{j.child}"/>')
        out.append(f'    <origin xyz="{vector_text(j.xyz[0], j.xyz[1], 0)}" rpy="{vector_text(0, 0, j.angle)}"/>')
        if j.type != "fixed":
            out.append(f'    <axis xyz="{vector_text(*j.axis)}"/>')
            out.append(f'    <limit lower="{number_text(j.lower)}" upper="{number_text(j.upper)}" effort="100" velocity="10"/>')
        out.append("  </joint>")
    for c in linkage.loop_joints:
        out.append(f'  <loop_joint name="{c.name}" type="{c.type}">')
        out.append(f'    <link1 link="{c.link1}" xyz="{vector_text(c.xyz1[0], c.xyz1[1], 0)}" rpy="{vector_text(0, 0, c.angle1)}"/>')
        out.append(f'    <link2 link="{c.link2}" xyz="{vector_text(c.xyz2[0], c.xyz2[1], 0)}" rpy="{vector_text(0, 0, c.angle2)}"/>')
        out.append(f'    <axis xyz="{vector_text(*c.axis)}"/>')
        out.append("  </loop_joint>")
    for name in linkage.actuated:
        out.append(f'  <transmission name="t_{name}">')
        out.append("    <type>transmission_interface/SimpleTransmission</type>")
        out.append(f'    <joint name="{name}"><hardwareInterface>hardware_interface/EffortJointInterface'
                   "</hardwareInterface></joint>")
        out.append(f'    <actuator name="m_{name}"><mechanicalReduction>1</mechanicalReduction></actuator>')
        out.append("  </transmission>")
    out += targets_text(linkage.targets)
    out.append("</robot>")
    return "\n".join(out) + "\n"


def _attribute(text: str) -> str:
    return text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;").replace(">", "&gt;")


def targets_text(targets: tuple) -> list:
    """The lines of the <screwkin:targets> element of ``targets`` (TargetSpec); none when empty."""
    if not targets:
        return []
    out = ["  <screwkin:targets>"]
    for t in targets:
        yaw = "" if t.yaw is None else f' yaw="{number_text(t.yaw)}"'
        out.append(f'    <screwkin:target kind="{t.kind}" link="{_attribute(t.link)}" input="{_attribute(t.input)}" '
                   f'value="{number_text(t.value)}" xyz="{vector_text(*t.xyz)}"{yaw} label="{_attribute(t.label)}"/>')
    out.append("  </screwkin:targets>")
    return out
