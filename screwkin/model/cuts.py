"""What a closure system closes: the cut joints bound to a model (frames F1, F2 and axes), the
linear couplings of rolling and screw pairs, the contacts of profiles in a plane, and the closed
configuration a solve returns.  Plain frozen data; model.closure evaluates their rows.  Also where
a rolling or gear pair's pitch curves touch (pair_contact: the one place that computes it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import plane_basis, wrap_angle
from .manifold import continuous_angle

__all__ = ["CutJoint", "CouplingRow", "ContactRow", "Assembly", "in_plane", "pair_contact"]


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

    def value(self, q) -> float:
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


def in_plane(axis):
    """(a, u, n): the unit axis a, the unit direction of x projected into the plane normal to
    a, and a x u (the plane of a rolling or gear pair: u is its line's direction in F1) --
    geometry.plane_basis(axis) in the order (normal, e1, e2)."""
    e1, e2, a = plane_basis(axis)
    return a, e1, e2


def pair_contact(pair, M1, M2):
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
