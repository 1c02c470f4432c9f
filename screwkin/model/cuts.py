"""What a closure system closes: the cut joints bound to a model (frames F1, F2 and axes), the
linear couplings of rolling and screw pairs, the contacts of profiles in a plane, and the closed
configuration a solve returns.  Plain frozen data (bind_cut makes it from a description's loop joint);
model.kernel.closure evaluates their rows.  Also where
a rolling or gear pair's pitch curves touch (pair_contact: the one place that computes it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import MechanismFileError, quote
from ..files.description import placement
from ._pin import frame_id
from .geometry import plane_basis, wrap_angle
from .manifold import continuous_angle
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.files.description import CutJointSpec

__all__ = ["CutJoint", "CouplingRow", "ContactRow", "Assembly", "in_plane", "pair_contact", "bind_cut",
           "virtual_roles", "virtual_joint_name"]


@dataclass(frozen=True)
class CutJoint:
    """A cut joint bound to a model: frame ids of F1, F2 and its axes.

    axis is expressed in F1, axis2 (universal joints) in F2.
    """

    name: str
    type: str
    dof: int
    frame1: int
    frame2: int
    link1: str
    link2: str
    axis: tuple
    axis2: tuple | None = None
    pair: str | None = None  # a higher pair built on this cut joint: "rolling", "gear", "helical", "contact"

    @property
    def rows(self) -> int:
        return 6 - self.dof


@dataclass(frozen=True)
class CouplingRow:
    """A linear relation of one-coordinate joints, sum c_k q_k + c0 = 0 [m]: the no-slip condition
    of a rolling pair (r1 a1 + r2 a2 = 0) or the lead of a screw pair (advance - lead turn / 2 pi
    = 0), written in the unwrapped coordinates of the pair's virtual joints, so that it holds over
    any number of turns.  Its Jacobian row is constant and it adds nothing to K'q'.

    kind "angle": a link's absolute angle in a planar mechanism held as an input (the signed
    revolute angles on its path from the ground plus its angle at q = 0, minus the angle given)
    [rad]; it holds modulo a turn, so its residual is taken in [-pi, pi).  ``input`` names what
    the row holds (the link): its rate and acceleration are given as that input's
    (ClosureSystem.row_rates)."""

    name: str
    kind: str  # "roll" | "lead" | "angle"
    terms: tuple  # ((q index, v index, coefficient), ...)
    constant: float = 0.0
    input: str | None = None
    pairs: frozenset = frozenset()  # q indices of continuous joints (cos, sin) in an angle row's terms

    def value(self, q: np.ndarray):
        """The row's residual at q: sum c_k q_k + c0, or for an angle row the joints' angles (a
        continuous joint's atan2(sin, cos)) so summed, taken into [-pi, pi) (geometry.wrap_angle)."""
        if self.kind != "angle":
            return sum(c * q[iq] for iq, _, c in self.terms) + self.constant
        total = sum(c * (continuous_angle(q, iq) if iq in self.pairs else q[iq]) for iq, _, c in self.terms)
        return wrap_angle(total + self.constant)


@dataclass(frozen=True)
class ContactRow:
    """Two profiles touching in the plane that a planar cut joint between F1 and F2 keeps them in:
    a circle (centre at the frame's origin), a line (the frame's x axis) or a point (the origin)
    [m].  circle-line and line-circle: the centre's distance from the line equals the radius;
    point-line, line-point: the point on the line (a pin in a slot); circle-circle: the distance
    of the centres equals r1 + r2, or |r1 - r2| inside; point-circle, circle-point: the point on
    the circle.  normal: a line's normal in the plane, in its frame (axis x e_x)."""

    name: str
    frame1: int
    frame2: int
    shape1: str
    radius1: float | None
    shape2: str
    radius2: float | None
    internal: bool
    normal: tuple

    def target(self) -> float:
        if self.shape1 == "circle" and self.shape2 == "circle":
            return abs(self.radius1 - self.radius2) if self.internal else self.radius1 + self.radius2
        return self.radius1 if self.shape1 == "circle" else (self.radius2 or 0.0)


@dataclass(frozen=True)
class Assembly:
    """A configuration that satisfies the closure equations.

    q: joint configuration (Pinocchio's nq-vector);
    residual: closure residual norm reached [m, rad];
    iterations: solver iterations used (from the start that closed);
    start: which starting configuration closed (e.g. "the file's configuration");
    starts: how many starting configurations were tried to get there.
    """

    q: np.ndarray
    residual: float
    iterations: int
    start: str = "the given configuration"
    starts: int = 1


def in_plane(axis: tuple) -> tuple:
    """(a, u, n): the unit axis a, the unit direction of x projected into the plane normal to
    a, and a x u (the plane of a rolling or gear pair: u is its line's direction in F1) --
    geometry.plane_basis(axis) in the order (normal, e1, e2)."""
    e1, e2, a = plane_basis(axis)
    return a, e1, e2


def pair_contact(pair: CutJointSpec, M1, M2) -> tuple:
    """(p, a): the world point where the pitch curves of a rolling or gear pair touch, and the
    pair's unit axis in the world (the normal of its plane).  ``pair``: the file's loop joint
    (files.description: axis in F1, radius1 -- inf for a line --, radius2, contact); M1, M2: the
    world placements (pinocchio.SE3) of its frames F1 (circle 1's centre, or a point of the line,
    which runs along u of in_plane(axis) in F1) and F2 (circle 2's centre).

    Two circles, outside or inside: r1 from circle 1's centre towards circle 2's (the line of
    centres); a circle on a line: the foot of circle 2's centre on the line.  Rolling without
    slip turns one link relative to the other about this point (its instantaneous centre), so a
    revolute about ``a`` through ``p`` is the pair's instantaneous equivalent."""
    a, u, _ = in_plane(pair.axis)
    a = M1.rotation @ a
    p1, p2 = np.asarray(M1.translation, float), np.asarray(M2.translation, float)
    d = p2 - p1
    d = d - (d @ a) * a  # in the pair's plane
    if np.isinf(pair.radius1):
        u = M1.rotation @ u
        return p1 + (d @ u) * u, a
    dist = float(np.linalg.norm(d))
    e = d / dist if dist > 0 else M1.rotation @ u  # concentric (inside): F1's line as the contact direction
    return p1 + float(pair.radius1) * e, a


def virtual_roles(c: CutJointSpec) -> tuple:
    """The roles of the virtual joints of a rolling, gear or helical loop joint ``c``, in chain order."""
    if c.type == "helical":
        return ("turn", "advance")
    if np.isinf(c.radius1):
        return ("x", "a2")
    return ("a1", "a2")


def virtual_joint_name(loop_joint: str, role: str) -> str:
    """The model's name of the virtual joint of ``loop_joint`` in ``role`` (``mesh.a1``)."""
    return f"{loop_joint}.{role}"


def bind_cut(model: pin.Model, c: CutJointSpec, coordinates: dict, path: str) -> tuple:
    """(CutJoint, its extra row or None, the names of its virtual chain's joints or ()) of the
    description's loop joint ``c`` on ``model`` (its frames F1, F2 are added to the model): what closes
    the loop there -- the cut joint itself; for a rolling, gear or helical pair a weld from its virtual
    chain's end (model.loader._virtual_pairs) to F2 and a coupling row; for a sliding contact a planar
    joint and a contact row.  ``coordinates``: joint name -> Mechanism's Coordinate."""
    ids = []
    for k, (frame, xyz, rpy) in enumerate(((c.frame1, c.xyz1, c.rpy1), (c.frame2, c.xyz2, c.rpy2)), 1):
        fid = frame_id(model, frame)
        if fid is None:
            raise MechanismFileError(path, f"loop joint {quote(c.name)} names frame {quote(frame)}, which is not "
                                           "in the model")
        parent = model.frames[fid]
        new = pin.Frame(f"{c.name}@F{k}", parent.parentJoint, fid, parent.placement * placement(xyz, rpy),
                        pin.FrameType.OP_FRAME)
        ids.append(model.addFrame(new, False))
    axis, axis2 = tuple(c.axis), tuple(c.axis2) if c.axis2 is not None else None
    if c.type in ("rolling", "gear", "helical"):
        # the joints loader._virtual_pairs named, by role: names are built, never parsed (a loop
        # joint's name may hold dots, and "a" and "a.x" may both be loop joints)
        roles = virtual_roles(c)
        names = tuple(virtual_joint_name(c.name, role) for role in roles)
        coord = {role: coordinates[name] for role, name in zip(roles, names)}
        if c.type == "helical":  # advance - lead turn / 2 pi = 0
            terms = ((coord["advance"], 1.0), (coord["turn"], -c.lead / (2 * np.pi)))
            kind = "lead"
        elif np.isinf(c.radius1):  # x + r2 a2 = 0 with a2 = -q
            terms = ((coord["x"], 1.0), (coord["a2"], -c.radius2))
            kind = "roll"
        else:  # r1 a1 + r2 a2 = 0 outside, r1 a1 - r2 a2 = 0 inside, with a2 = -q
            sign = -1.0 if c.contact != "internal" else 1.0
            terms = ((coord["a1"], c.radius1), (coord["a2"], sign * c.radius2))
            kind = "roll"
        row = CouplingRow(c.name, kind, tuple((k.idx_q, k.idx_v, v) for k, v in terms))
        end = model.getFrameId(f"{c.name}@end")
        return CutJoint(c.name, "fixed", 0, end, ids[1], c.frame1, c.frame2, axis, None, pair=c.type), row, names
    if c.type == "contact":
        a = np.asarray(c.axis, float)
        normal = np.cross(a / np.linalg.norm(a), [1.0, 0.0, 0.0])
        normal = normal / max(np.linalg.norm(normal), 1e-300)
        (s1, r1), (s2, r2) = c.profile1, c.profile2
        row = ContactRow(c.name, ids[0], ids[1], s1, r1, s2, r2, c.contact == "internal", tuple(normal))
        return CutJoint(c.name, "planar", 3, ids[0], ids[1], c.frame1, c.frame2, axis, None, pair="contact"), row, ()
    return CutJoint(c.name, c.type, c.dof, ids[0], ids[1], c.frame1, c.frame2, axis, axis2), None, ()
