"""Writing a mechanism placed at one configuration as MJCF (MuJoCo) or URDF text.

The input is plain data -- bodies placed in their parents at that configuration, each with
its joint, the cut joints with their frames, couplings and inputs -- made by
:func:`screwkin.model.placed.placed`; this module knows nothing of solving.  The file's
configuration (MJCF's qpos0, URDF's all-zero) is the one given, so a loop closed there is
closed in the file, and MuJoCo's equalities, which take their second point from qpos0,
hold where they should.

MJCF has only point (``connect``) and frame (``weld``) equalities.  Cut joints become:

- spherical: a ``connect`` at F1;
- fixed: a ``weld`` at F2 with ``relpose`` written out (as MuJoCo's engine reads it: the anchor's
  place in body1 and body2's turn from body1; files/mjcf_equality.py);
- revolute, continuous: two ``connect``s, at F1 and one ``length`` further along the axis
  (MJCF has no hinge equality): 6 rows of rank 5 (one redundant, which MuJoCo's soft
  constraints accept; files/mjcf_rows names it).  The minimal form, a hinge on a small body
  welded to link2 (6 rows, none redundant), was measured and drifts more: its small body's
  unconstrained accelerations leak through MuJoCo's soft weld (1 s with 0.05 N m, the loop
  joint's axes apart: Sarrus 2.6 rad against 5e-3, the spherical four-bar 3.5e-2 against 9e-4);
- prismatic, cylindrical, universal, planar: a massless body on link1 at F1 carrying the
  joint's own motions (slide, hinge + slide, two hinges, two slides + hinge), named after
  the cut joint, welded to link2: the loop's rows exactly, with one more body and as many
  more coordinates as the joint has degrees of freedom.

A planar loop keeps its out-of-plane rows (MuJoCo has no planar equality): they are
redundant there, as in screwkin's own count.  Visual geometry is not written.

A compound joint of the tree (model.placed: revolutes and prismatics through massless links) is
one body's joints -- a ``ball``, or two joints in one body -- with the massless links left out
(PlacedCompound says which, and how a ball's quaternion gives its members' values).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..tolerances import DEFAULT
from .description import Coupling
from .inertia import inertia_problem
from .mjcf_equality import matrix_quat, quat_matrix
from .writer import number_text, origin_text, quoteattr, vector_text
from typing import TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Sequence

__all__ = ["PlacedJoint", "PlacedBody", "PlacedCompound", "PlacedCut", "PlacedMechanism", "write_mjcf",
           "write_placed_urdf", "TINY_MASS", "DEFAULT_DENSITY", "ROD_RATIO", "coupling_about", "default_solid",
           "helper_names", "joint_points", "mujoco_refuses"]

#: Mass [kg] (and inertia 1e-3 of it [kg m^2]) of the bodies of written URDF and of nothing else: kept
#: for the callers that name it; MJCF's moving bodies without mass get DEFAULT_DENSITY solids instead.
TINY_MASS = 1e-6
#: Density [kg/m^3] of the solid a moving body without mass gets in MJCF (MuJoCo's own default geom
#: density, water): a rod from the body's origin to its farthest joint (radius ROD_RATIO of its
#: length), or, with no other joint on it, a sphere of radius ROD_RATIO of the mechanism's length.
DEFAULT_DENSITY = 1000.0
ROD_RATIO = 0.05


@dataclass(frozen=True)
class PlacedJoint:
    """A body's joint. type: hinge, slide, ball, free or fixed; axis in the body's frame (at the
    written configuration: a body's later joints turn with its earlier ones, as MuJoCo composes
    them); range [rad or m] about the written configuration, None: unlimited; dynamics: its
    armature, damping and frictionloss that are not 0 (MJCF's names, description.JOINT_DYNAMICS),
    as ((name, value), ...)."""

    name: str
    type: str
    axis: tuple = (0.0, 0.0, 1.0)
    range: tuple | None = None
    dynamics: tuple = ()
    pos: tuple = (0.0, 0.0, 0.0)  # where it sits in the body's frame (a compound joint's: off the origin)


@dataclass(frozen=True)
class PlacedBody:
    """A body placed in its parent (None: the world) by pos [m] and quat (w, x, y, z); its
    inertia about the centre of mass com, in the body's axes (ixx, iyy, izz, ixy, ixz, iyz)."""

    name: str
    parent: str | None
    pos: tuple
    quat: tuple
    joint: PlacedJoint | None = None
    mass: float = 0.0
    com: tuple = (0.0, 0.0, 0.0)
    inertia: tuple = (0.0,) * 6
    more: tuple = ()  # PlacedJoint: the body's further joints, in order (a compound joint's: MJCF only)

    @property
    def joints(self) -> tuple:
        return ((self.joint,) if self.joint is not None else ()) + self.more


@dataclass(frozen=True)
class PlacedCompound:
    """A compound joint of the tree (revolutes and prismatics through massless links, recognized by
    model.topology) written as one body's joints: a ``ball`` (spherical) or two joints in one body
    (universal: two hinges; cylindrical: a hinge and a slide).  members: its URDF joints, parent to
    child; links: the massless links between them (not written); body: the body that carries it;
    axes: the members' axes in that body's frame at the written configuration, where the members
    have ``values``: a ball's quaternion Q is R(axes[0], d0) R(axes[1], d1) R(axes[2], d2), the
    members at values + d."""

    type: str
    name: str
    members: tuple
    links: tuple
    body: str
    axes: tuple
    values: tuple


@dataclass(frozen=True)
class PlacedCut:
    """A cut joint: F1 on body1 and F2 on body2 (pos, quat in the body), axis in F1, axis2 in
    F2; rel: F2 seen from F1 at the written configuration (pos, quat)."""

    name: str
    type: str
    body1: str
    pos1: tuple
    quat1: tuple
    body2: str
    pos2: tuple
    quat2: tuple
    axis: tuple
    axis2: tuple | None
    rel: tuple


@dataclass(frozen=True)
class PlacedMechanism:
    name: str
    bodies: tuple  # PlacedBody, parents before children
    cuts: tuple = ()  # PlacedCut
    couplings: tuple = ()  # Coupling (offsets about the written configuration)
    actuated: tuple = ()
    comment: str = ""
    length: float = 0.1  # [m] between a revolute cut's two connects
    notes: tuple = ()  # what the placing changed, one line each (said by the command)
    gears: tuple = ()  # (input joint, gear) where the actuator's effort is the joint's / gear (not 1)
    compounds: tuple = ()  # PlacedCompound: the tree's compound joints written as one body's joints


def _placement(pos: np.ndarray, quat: Sequence[float]):
    return pin.SE3(quat_matrix(quat), np.asarray(pos, float))


def _quat(M: pin.SE3) -> tuple:
    return matrix_quat(M.rotation)


def _children(pm: PlacedMechanism) -> dict:
    kids = {}
    for b in pm.bodies:
        kids.setdefault(b.parent, []).append(b)
    return kids


def _comment(text: str):
    """An XML comment holding ``text``: no "--" inside and no "-" at its end (XML forbids both)."""
    if not text:
        return ""
    while "--" in text:
        text = text.replace("--", "- -")
    return "<!--\n" + text.rstrip() + "\n-->"


def default_solid(points: Sequence[np.ndarray], length: float) -> tuple:
    """(mass, centre of mass, (ixx, iyy, izz, ixy, ixz, iyz)) of the solid a moving body without mass
    gets: a rod of DEFAULT_DENSITY from its origin to the farthest of ``points`` (its joints, in its
    frame), radius ROD_RATIO of that length; a sphere of radius ROD_RATIO * ``length`` when no point is
    off its origin."""
    far = max(points, key=lambda p: float(np.linalg.norm(p)), default=np.zeros(3))
    far = np.asarray(far, float)
    L = float(np.linalg.norm(far))
    if L < DEFAULT.equal * max(length, 1.0):
        r = ROD_RATIO * length
        m = DEFAULT_DENSITY * 4.0 / 3.0 * np.pi * r**3
        i = 0.4 * m * r * r
        return m, (0.0, 0.0, 0.0), (i, i, i, 0.0, 0.0, 0.0)
    r = ROD_RATIO * L
    m = DEFAULT_DENSITY * np.pi * r * r * L
    d = far / L
    I = m * (3 * r * r + L * L) / 12.0 * (np.eye(3) - np.outer(d, d)) + m * r * r / 2.0 * np.outer(d, d)
    return m, tuple(far / 2), (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])


def mujoco_refuses(mass: float, inertia: Sequence[float]) -> bool:
    """Whether MuJoCo refuses this mass and inertia (ixx, iyy, izz, ixy, ixz, iyz) of a body with mass:
    principal moments not all positive, or breaking A + B >= C (a point mass, a URDF's zero inertia)."""
    xx, yy, zz, xy, xz, yz = inertia
    moments = np.linalg.eigvalsh(np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], float))
    scale = max(float(moments[-1]), mass * TINY_MASS)  # a zero tensor: compared with a 1 mm body's
    return mass > 0 and (moments[0] <= DEFAULT.zero * scale or inertia_problem(mass, inertia) is not None)


def _mj_inertial(mass: float, com: Sequence[float], inertia: Sequence[float], moving: bool, points: Sequence[np.ndarray]=(), length: float = 0.1) -> str:
    if mass <= 0:
        if not moving:
            return ""
        mass, com, inertia = default_solid(points, length)
    elif mujoco_refuses(mass, inertia):  # the body's mass kept, spread as the default solid's
        m0, _, i0 = default_solid(points, length)
        inertia = tuple(x * mass / m0 for x in i0)
    return f'<inertial pos="{vector_text(*com)}" mass="{number_text(mass)}" fullinertia="{vector_text(*inertia)}"/>'


def joint_points(pm: PlacedMechanism) -> dict:
    """Body -> the points in its frame where joints sit: its children's origins and its cut frames."""
    out = {}
    for b in pm.bodies:
        if b.parent is not None:
            out.setdefault(b.parent, []).append(np.asarray(b.pos, float))
    for c in pm.cuts:
        out.setdefault(c.body1, []).append(np.asarray(c.pos1, float))
        out.setdefault(c.body2, []).append(np.asarray(c.pos2, float))
    return out


def helper_names(pm: PlacedMechanism) -> dict:
    """Names of what the MJCF writer adds, none equal to a name of the mechanism: (kind, cut or input)
    -> name, kind one of "F1" (a cut's body), "axis" (a revolute cut's second connect), "weld", "motor"
    and "aux" (a cut's joints, with its index)."""
    joints = {b.name for b in pm.bodies} | {j.name for b in pm.bodies for j in b.joints}
    taken = joints | {c.name for c in pm.cuts} | {cp.joint for cp in pm.couplings}
    out = {}

    def fresh(base: str):
        name = base
        k = 1
        while name in taken:
            k += 1
            name = f"{base}~{k}"
        taken.add(name)
        return name

    for c in pm.cuts:
        out["F1", c.name] = fresh(c.name + "~F1")
        out["axis", c.name] = fresh(c.name + "~axis")
        out["weld", c.name] = fresh(c.name + "~weld")
        for k in range(len(_AUX.get(c.type, ()))):
            single = len(_AUX[c.type]) == 1 and c.name not in joints  # the slide keeps the loop joint's name
            out["aux", c.name, k] = c.name if single else fresh(f"{c.name}.{k}")
    for a in pm.actuated:
        out["motor", a] = fresh(a + "_motor")
    return out


def _mj_joint(j) -> str:
    dyn = "".join(f' {k}="{number_text(v)}"' for k, v in j.dynamics)
    if j.type == "free" and not dyn:
        return f"<freejoint name={quoteattr(j.name)}/>"
    rng = f' range="{vector_text(*j.range)}"' if j.range is not None else ""
    axis = "" if j.type in ("ball", "free") else f' axis="{vector_text(*j.axis)}"'
    pos = f' pos="{vector_text(*j.pos)}"' if any(j.pos) else ""
    return f"<joint name={quoteattr(j.name)} type=\"{j.type}\"{pos}{axis}{rng}{dyn}/>"


_AUX = {"prismatic": ("slide",), "cylindrical": ("hinge", "slide"), "universal": ("hinge", "hinge"),
        "planar": ("slide", "slide", "hinge")}


def _aux_axes(c: PlacedCut):
    """The axes (in F1) of the aux body's joints for a cut joint of type in _AUX."""
    a = np.asarray(c.axis, float)
    if c.type == "planar":
        u = np.cross(a, [1.0, 0, 0]) if abs(a[0]) < 0.9 else np.cross(a, [0, 1.0, 0])
        u /= np.linalg.norm(u)
        return (tuple(u), tuple(np.cross(a, u)), tuple(a))
    if c.type == "universal":  # axis2 is fixed in F2: in F1's axes at the written configuration
        R = _placement(c.rel[0], c.rel[1]).rotation
        return (tuple(a), tuple(R @ np.asarray(c.axis2, float)))
    return (tuple(a),) * len(_AUX[c.type])


def write_mjcf(pm: PlacedMechanism) -> str:
    """MJCF text of ``pm`` (see the module docstring)."""
    kids = _children(pm)
    aux = {}  # body1 -> cuts whose aux body it carries
    for c in pm.cuts:
        if c.type in _AUX:
            aux.setdefault(c.body1, []).append(c)
    names = helper_names(pm)
    points = joint_points(pm)
    out = [_comment(pm.comment), f"<mujoco model={quoteattr(pm.name)}>",
           '  <compiler angle="radian" autolimits="true"/>', "  <worldbody>"]

    def aux_bodies(name: str, pad) -> None:
        for c in aux.get(name, ()):
            out.append(f'{pad}<body name={quoteattr(names["F1", c.name])} pos="{vector_text(*c.pos1)}" '
                       f'quat="{vector_text(*c.quat1)}">')
            for k, (t, ax) in enumerate(zip(_AUX[c.type], _aux_axes(c))):
                out.append(f"{pad}  <joint name={quoteattr(names['aux', c.name, k])} type=\"{t}\" "
                           f"axis=\"{vector_text(*ax)}\"/>")
            out.append(f"{pad}  {_mj_inertial(0, 0, 0, True, (), pm.length)}")
            out.append(f"{pad}</body>")

    def body(b, depth: int) -> None:
        pad = "  " * depth
        out.append(f'{pad}<body name={quoteattr(b.name)} pos="{vector_text(*b.pos)}" quat="{vector_text(*b.quat)}">')
        moving = b.joint is not None and b.joint.type != "fixed"
        if moving:
            out.extend(f"{pad}  {_mj_joint(j)}" for j in b.joints)
        inertial = _mj_inertial(b.mass, b.com, b.inertia, moving, points.get(b.name, ()), pm.length)
        if inertial:
            out.append(f"{pad}  {inertial}")
        aux_bodies(b.name, pad + "  ")
        for k in kids.get(b.name, ()):
            body(k, depth + 1)
        out.append(f"{pad}</body>")

    aux_bodies("world", "    ")
    for b in kids.get(None, ()):
        body(b, 2)
    out.append("  </worldbody>")
    eq = []
    for c in pm.cuts:
        if c.type == "spherical":
            eq.append(f"<connect name={quoteattr(c.name)} body1={quoteattr(c.body1)} body2={quoteattr(c.body2)} "
                      f'anchor="{vector_text(*c.pos1)}"/>')
        elif c.type in ("revolute", "continuous"):
            F1 = _placement(c.pos1, c.quat1)
            far = F1.act(pm.length * np.asarray(c.axis, float))
            for name, p in ((c.name, c.pos1), (names["axis", c.name], far)):
                eq.append(f"<connect name={quoteattr(name)} body1={quoteattr(c.body1)} body2={quoteattr(c.body2)} "
                          f'anchor="{vector_text(*p)}"/>')
        else:  # fixed: body2 in body1; an aux body: body2 in the aux body, which is at F1 at qpos0
            F1 = pin.SE3.Identity() if c.type in _AUX else _placement(c.pos1, c.quat1)
            F2 = _placement(c.pos2, c.quat2)
            at = F1 * _placement(*c.rel)  # F2 in body1 at qpos0: relpose is the anchor's place there, and body2's turn
            rel = at * F2.inverse()
            body1 = names["F1", c.name] if c.type in _AUX else c.body1
            eq.append(f"<weld name={quoteattr(c.name if c.type == 'fixed' else names['weld', c.name])} "
                      f"body1={quoteattr(body1)} body2={quoteattr(c.body2)} anchor=\"{vector_text(*c.pos2)}\" "
                      f'relpose="{vector_text(*at.translation, *_quat(rel))}"/>')
    for cp in pm.couplings:
        eq.append(f"<joint joint1={quoteattr(cp.joint)} joint2={quoteattr(cp.mimics)} "
                  f'polycoef="{vector_text(cp.offset, cp.multiplier, 0, 0, 0)}"/>')
    if eq:
        out += ["  <equality>"] + [f"    {e}" for e in eq] + ["  </equality>"]
    if pm.actuated:
        gears = dict(pm.gears)
        out += ["  <actuator>"] + [f"    <motor name={quoteattr(names['motor', a])} joint={quoteattr(a)}"
                                   + (f' gear="{number_text(gears[a])}"' if a in gears else "") + "/>"
                                   for a in pm.actuated] + ["  </actuator>"]
    out.append("</mujoco>")
    return "\n".join(x for x in out if x) + "\n"


_URDF_TYPE = {"slide": "prismatic", "free": "floating", "fixed": "fixed"}


def write_placed_urdf(pm: PlacedMechanism, root: str) -> str:
    """URDF text of ``pm`` with ``<loop_joint>``s (docs/format.md), the tree rooted at link
    ``root`` (the bodies without a parent hang from it).  Ball joints have no URDF form: the
    caller refuses them first."""
    coupled = {c.joint: c for c in pm.couplings}
    out = [_comment(pm.comment), f"<robot name={quoteattr(pm.name)}>", f"  <link name={quoteattr(root)}/>"]
    joints = []
    for b in pm.bodies:
        if b.name == root:
            continue
        inertial = ""
        if b.mass > 0:
            xx, yy, zz, xy, xz, yz = b.inertia
            inertial = (f'<inertial><origin xyz="{vector_text(*b.com)}"/><mass value="{number_text(b.mass)}"/><inertia ixx="{number_text(xx)}" '
                        f'iyy="{number_text(yy)}" izz="{number_text(zz)}" ixy="{number_text(xy)}" ixz="{number_text(xz)}" iyz="{number_text(yz)}"/></inertial>')
        out.append(f"  <link name={quoteattr(b.name)}>{inertial}</link>")
        j = b.joint or PlacedJoint(f"{b.name}__fixed", "fixed")
        t = _URDF_TYPE.get(j.type) or ("revolute" if j.range is not None else "continuous")
        text = (f"  <joint name={quoteattr(j.name)} type=\"{t}\"><parent link={quoteattr(b.parent or root)}/>"
                f"<child link={quoteattr(b.name)}/>{origin_text(_placement(b.pos, b.quat))}")
        if t in ("revolute", "continuous", "prismatic"):
            lo, hi = j.range if j.range is not None else (-1e9, 1e9)
            text += f'<axis xyz="{vector_text(*j.axis)}"/><limit lower="{number_text(lo)}" upper="{number_text(hi)}" effort="0" velocity="0"/>'
        urdf_dyn = {"damping": "damping", "frictionloss": "friction"}  # armature has no URDF form
        dyn = " ".join(f'{urdf_dyn[k]}="{number_text(v)}"' for k, v in j.dynamics if k in urdf_dyn)
        if dyn and t != "fixed":
            text += f"<dynamics {dyn}/>"
        if j.name in coupled:
            cp = coupled[j.name]
            text += f'<mimic joint={quoteattr(cp.mimics)} multiplier="{number_text(cp.multiplier)}" offset="{number_text(cp.offset)}"/>'
        joints.append(text + "</joint>")
    out += joints
    for c in pm.cuts:
        r1, r2 = (pin.rpy.matrixToRpy(_placement(c.pos1 if k == 1 else c.pos2, c.quat1 if k == 1 else c.quat2).rotation)
                  for k in (1, 2))
        text = (f"  <loop_joint name={quoteattr(c.name)} type=\"{c.type}\"><link1 link={quoteattr(c.body1)} "
                f'xyz="{vector_text(*c.pos1)}" rpy="{vector_text(*r1)}"/><link2 link={quoteattr(c.body2)} xyz="{vector_text(*c.pos2)}" '
                f'rpy="{vector_text(*r2)}"/><axis xyz="{vector_text(*c.axis)}"/>')
        if c.axis2 is not None:
            text += f'<axis2 xyz="{vector_text(*c.axis2)}"/>'
        out.append(text + "</loop_joint>")
    gears = dict(pm.gears)
    for name in pm.actuated:
        out.append(f"  <transmission name={quoteattr('t_' + name)}><type>transmission_interface/SimpleTransmission"
                   f"</type><joint name={quoteattr(name)}><hardwareInterface>hardware_interface/EffortJointInterface"
                   f"</hardwareInterface></joint><actuator name={quoteattr(name + '_motor')}><mechanicalReduction>"
                   f"{number_text(gears.get(name, 1.0))}</mechanicalReduction></actuator></transmission>")
    out.append("</robot>")
    return "\n".join(x for x in out if x) + "\n"


def coupling_about(c: Coupling, primary_value: float, joint_value: float) -> Coupling:
    """The coupling ``joint = m primary + o`` in coordinates measured from the given values."""
    return Coupling(c.joint, c.mimics, c.multiplier, c.multiplier * primary_value + c.offset - joint_value)
