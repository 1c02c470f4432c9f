"""Screws of a mechanism: product-of-exponentials structure equations, Jacobians.

For every chain from the ground to a frame (each side of each cut joint, and an
output link), the structure equation in product-of-exponentials form

    g(q) = exp([xi_1] theta_1) ... exp([xi_n] theta_n) g(0)

with the joint twists xi_i in the reference configuration (the file's, all
joint values zero), in the space frame, ordered (v, w) as Pinocchio's Motion:
for a revolute joint with unit axis w through point p, xi = (-w x p, w); for a
prismatic joint along v, xi = (v, 0).  They are read from Pinocchio's world
Jacobian at the reference configuration, and the current twists xi'_i at a
configuration are the columns of the space Jacobian there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import UsageError
from ..model.geometry import perpendicular_basis, plane_basis
from ..model.linalg import null_space
from ..model.state import KinematicState, frame_parent
from ..tolerances import DEFAULT
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.model.cuts import CutJoint

__all__ = ["Screw", "Chain", "LoopScrews", "screw_of", "chains", "chains_to", "poe", "structure", "loop_screws",
           "loop_product", "split_jacobians", "cut_twists"]


@dataclass(frozen=True)
class Screw:
    """A twist (v, w) with its axis: direction, the point of the axis nearest the
    origin, pitch [m/rad] (inf for a pure translation)."""

    twist: tuple
    direction: tuple
    point: tuple | None
    pitch: float


#: With a characteristic length L, a twist whose rotation moves points within L by less than this fraction of
#: its translation (|w| L < TRANSLATION_RATIO |v|: an axis a million lengths away) is a pure translation.
TRANSLATION_RATIO = 1e-6


def screw_of(xi: np.ndarray | list, length: float | None = None) -> Screw:
    """The screw of a twist (v, w); with ``length`` [m] a rotation about an axis farther than
    length / TRANSLATION_RATIO is read as the translation it is (round-off near a singularity)."""
    xi = np.asarray(xi, float)
    v, w = xi[:3], xi[3:]
    nw = np.linalg.norm(w)
    if nw < DEFAULT.zero or (length is not None and nw * length < TRANSLATION_RATIO * np.linalg.norm(v)):
        nv = np.linalg.norm(v)
        return Screw(tuple(xi), tuple(v / nv) if nv > 0 else (0.0, 0.0, 0.0), None, float("inf"))
    pitch = float(w @ v / nw**2)
    point = np.cross(w, v) / nw**2
    return Screw(tuple(xi), tuple(w / nw), tuple(point), pitch)


@dataclass(frozen=True)
class Chain:
    """A serial chain of tree joints from the ground to a frame."""

    name: str  # e.g. "C@F1", "C@F2", "output platform"
    frame: int
    joints: tuple  # joint names, base to tip (1-DOF joints only)
    columns: tuple  # their velocity indices
    xi0: np.ndarray  # (6, n) joint twists at the reference configuration
    g0: np.ndarray  # 4x4 tool frame at the reference configuration


def chains(mech: Mechanism, output: str | None=None) -> list:
    """One chain per cut-joint side and one to the output link."""
    targets = []
    for c in mech.cuts:
        targets += [(f"{c.name}@F1", c.frame1), (f"{c.name}@F2", c.frame2)]
    if output:
        targets.append((f"output {output}", mech.link_frame(output)))
    return chains_to(mech, targets)


def chains_to(mech: Mechanism, targets: list) -> list:
    """The chain from the ground to each frame of ``targets`` ((name, frame id) pairs), read
    at the reference configuration (every joint at zero)."""
    model = mech.model
    state = KinematicState(mech, mech.neutral())
    out = []
    for name, fid in targets:
        jid = frame_parent(mech, fid)[0]
        support = [j for j in model.supports[jid] if j > 0]
        joints, cols = [], []
        for j in support:
            if model.nvs[j] != 1:
                raise UsageError(f"{mech.path}: joint '{model.names[j]}' has {model.nvs[j]} DOF: the "
                                 "product-of-exponentials form here takes 1-DOF joints")
            joints.append(model.names[j])
            cols.append(model.idx_vs[j])
        Js = state.frame_jacobian(fid, pin.ReferenceFrame.WORLD)
        out.append(Chain(name, fid, tuple(joints), tuple(cols), Js[:, cols].copy(), state.frame_pose(fid)))
    return out


def joint_angles(mech: Mechanism, q: np.ndarray, chain: Chain) -> np.ndarray:
    """theta_i: each chain joint's displacement from the reference configuration."""
    dq = pin.difference(mech.model, mech.neutral(), q)
    return dq[list(chain.columns)]


def poe(chain: Chain, theta: np.ndarray) -> np.ndarray:
    """g(theta) = prod exp([xi_i] theta_i) g(0), as a 4x4 matrix."""
    M = pin.SE3.Identity()
    for k in range(len(chain.joints)):
        M = M * pin.exp6(pin.Motion(chain.xi0[:, k] * theta[k]))
    return M.homogeneous @ chain.g0


def structure(mech: Mechanism, q: np.ndarray, output: str | None=None) -> list:
    """Per chain: reference twists, g(0), current twists (space Jacobian columns at q)."""
    state = KinematicState(mech, q)
    result = []
    for ch in chains(mech, output):  # at the reference configuration, in a state of its own
        Js = state.frame_jacobian(ch.frame, pin.ReferenceFrame.WORLD)[:, list(ch.columns)]
        Jb = state.frame_jacobian(ch.frame, pin.ReferenceFrame.LOCAL)[:, list(ch.columns)]
        result.append({"chain": ch, "theta": joint_angles(mech, q, ch), "space_jacobian": Js, "body_jacobian": Jb,
                       "g": state.frame_pose(ch.frame)})
    return result


@dataclass(frozen=True)
class LoopScrews:
    """A loop written as the product of exponentials of all its joints, the cut joint included:

        exp([xi_1] th_1) ... exp([xi_k] th_k) exp([xi_c] th_c) exp(-[xi'_m] th'_m) ... exp(-[xi'_1] th'_1) = I

    from the ground side of F1 (the tree joints that carry link1, base to tip, less those shared
    with F2's side), the cut joint, then F2's side back down (its joints' angles counted against
    the loop's direction: sign -1).  Twists in the space frame at the reference configuration (the
    file's, every joint zero), where the identity holds when the file is drawn closed."""

    cut: str
    joints: tuple  # joint names in loop order
    signs: tuple  # +1 along the loop, -1 for F2's side
    xi0: np.ndarray  # (6, n) twists at the reference configuration, in loop order
    closed_at_reference: bool  # F1 and F2 coincide in the file's configuration


def cut_twists(mech: Mechanism, cut: CutJoint, state: KinematicState) -> list | None:
    """The cut joint's freedoms at the configuration of ``state`` (a model.state.KinematicState) as
    world twists (v at the world origin, w): [(name, twist, sliding)], or None for a higher pair (its
    loop closes through an equivalent linkage and coupling rows)."""
    if cut.pair is not None:
        return None
    M1 = state.frame_placement(cut.frame1)
    a = M1.rotation @ (np.asarray(cut.axis, float) / np.linalg.norm(cut.axis))
    p = M1.translation

    def rot(u) -> tuple[np.ndarray, bool]:
        return np.concatenate([-np.cross(u, p), u]), False

    def slide(u) -> tuple[np.ndarray, bool]:
        return np.concatenate([u, np.zeros(3)]), True

    if cut.type in ("revolute", "continuous"):
        out = [rot(a)]
    elif cut.type == "prismatic":
        out = [slide(a)]
    elif cut.type == "cylindrical":
        out = [rot(a), slide(a)]
    elif cut.type == "universal":
        a2 = state.frame_placement(cut.frame2).rotation @ np.asarray(cut.axis2, float)
        out = [rot(a), rot(a2 / np.linalg.norm(a2))]
    elif cut.type == "spherical":
        out = [rot(e) for e in np.eye(3)]
    elif cut.type == "planar":
        b1, b2 = perpendicular_basis(a)
        out = [slide(b1), slide(b2), rot(a)]
    elif cut.type == "fixed":
        out = []
    else:  # pragma: no cover - every lower-pair cut joint type is above
        return None
    if len(out) == 1:
        return [(cut.name, *out[0])]
    return [(f"{cut.name}[{k}]", *t) for k, t in enumerate(out)]


def loop_screws(mech: Mechanism) -> list:
    """A LoopScrews for each one-coordinate cut joint (revolute, continuous, prismatic; no higher pair)."""
    model = mech.model
    state = KinematicState(mech, mech.neutral())
    out = []
    for c in mech.cuts:
        if c.pair or c.dof != 1:
            continue
        twists = cut_twists(mech, c, state)  # [(name, twist, sliding)] of the cut joint's freedoms
        if not twists or len(twists) != 1:
            continue
        xi_c = twists[0][1]
        sides = []
        for f in (c.frame1, c.frame2):
            jid = model.frames[f].parentJoint
            sides.append([j for j in model.supports[jid] if j > 0])
        shared = set(sides[0]) & set(sides[1])
        one, two = ([j for j in side if j not in shared] for side in sides)
        if any(model.nvs[j] != 1 for j in one + two):
            continue  # the product of exponentials here takes 1-DOF joints
        Jw = {j: state.frame_jacobian(f, pin.ReferenceFrame.WORLD)
              for f, side in ((c.frame1, one), (c.frame2, two)) for j in side}
        cols = [Jw[j][:, model.idx_vs[j]] for j in one] + [xi_c] + [Jw[j][:, model.idx_vs[j]] for j in reversed(two)]
        names = [model.names[j] for j in one] + [c.name] + [model.names[j] for j in reversed(two)]
        signs = [1] * (len(one) + 1) + [-1] * len(two)
        closed = state.frame_placement(c.frame1).isApprox(state.frame_placement(c.frame2), mech.tolerances.geometry)
        out.append(LoopScrews(c.name, tuple(names), tuple(signs), np.array(cols).T.copy(), bool(closed)))
    return out


def loop_product(loop: LoopScrews, theta: list) -> np.ndarray:
    """The left side of the loop's equation, a 4x4 matrix, for joint displacements ``theta`` in loop
    order (the cut joint's as model.state.KinematicState.loop_value); the identity when the loop closes."""
    M = pin.SE3.Identity()
    for k in range(len(loop.joints)):
        M = M * pin.exp6(pin.Motion(loop.signs[k] * loop.xi0[:, k] * theta[k]))
    return M.homogeneous


def planar_form(xi: np.ndarray, normal: list | tuple) -> np.ndarray:
    """(v_x, v_y, w) of a planar twist in the plane's axes (e1, e2, n) (geometry.plane_basis: the axes
    the drawing, the vector loops and the link angles use)."""
    e1, e2, n = plane_basis(normal)
    xi = np.asarray(xi)
    return np.array([xi[:3] @ e1, xi[:3] @ e2, xi[3:] @ n])


def split_jacobians(mech: Mechanism, q: np.ndarray, output: str, inputs: list[str] | None=None) -> dict:
    """Constraint Jacobian split into input and passive columns, and the forward
    (output twist from input rates) and inverse (input rates from output twist)
    Jacobians at q.  Output twists are (v, w) of the output frame origin in
    world axes.  The inverse Jacobian exists when the output motion determines
    the input rates (parallel manipulators); it is None otherwise."""
    names = list(inputs or mech.actuated)
    a = mech.velocity_indices(names)
    p = np.setdiff1d(np.arange(mech.nv), a)
    K = mech.closure.jacobian(q)
    J = KinematicState(mech, q).link_jacobian(output, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    # q' = S q'_a with K_p q'_p = -K_a q'_a (minimum norm: no idle spins)
    S = np.zeros((mech.nv, len(a)))
    S[a] = np.eye(len(a))
    if K.size:
        S[p] = -np.linalg.lstsq(K[:, p], K[:, a], rcond=None)[0]
    forward = J @ S
    # inverse: [K; J] q' = [0; t]; unique input rates when the output and the loops fix them
    A = np.vstack([K, J]) if K.size else J
    N = null_space(A, mech.tolerances, mech.nv)
    inverse = None
    if N.size == 0 or np.allclose(N[a], 0, atol=1e-9):
        pinv = np.linalg.pinv(A)
        inverse = pinv[a][:, -6:]
    return {"inputs": names, "K_actuated": K[:, a] if K.size else K, "K_passive": K[:, p] if K.size else K,
            "forward": forward, "inverse": inverse}
