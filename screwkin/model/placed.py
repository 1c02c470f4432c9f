"""A mechanism placed at one configuration, as the plain data the writers of
:mod:`screwkin.files.exporter` turn into MJCF or URDF text.

Every link of the file's spanning tree becomes a body placed in its parent where the
configuration puts it (so that configuration is the written file's own: MuJoCo's qpos0, the
URDF's all-zero), with its joint (its axis does not move in its own link as it turns), the
inertia Pinocchio holds for it (links fixed to it are merged into it, as Pinocchio merges
them), the cut joints with their frames unchanged, the couplings measured from there and the
inputs.  The links of the tree's root hang from the world; the root itself, unless it is the
world, is a body without a joint.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..errors import MechanismFileError, quote
from ..files.exporter import PlacedBody, PlacedCompound, PlacedCut, PlacedJoint, PlacedMechanism, coupling_about
from ..files.mjcf_equality import matrix_quat
from ..tolerances import DEFAULT
from .geometry import perpendicular_basis, wrap_angle
from .manifold import continuous_angle
from .state import KinematicState
from .topology import build_topology, frame_link
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from collections.abc import Sequence

__all__ = ["placed", "check_closed", "WRITABLE_CUTS", "ball_values", "davenport"]

#: Cut-joint types the writers can express (the higher pairs cannot).
WRITABLE_CUTS = ("fixed", "revolute", "continuous", "prismatic", "cylindrical", "universal", "planar", "spherical")

#: A joint limit beyond this [rad or m] is no limit (files write 1e9 or 1e16 for "none").
_NO_LIMIT = 1e6


def _inertia(I: pin.Inertia) -> tuple:
    m = I.inertia
    return (m[0, 0], m[1, 1], m[2, 2], m[0, 1], m[0, 2], m[1, 2])


def placed(mech: Mechanism, q: np.ndarray, fmt: str = "MJCF", length: float | None = None, comment: str = "") -> PlacedMechanism:
    """``mech`` at configuration ``q`` (an assembled one, for loops closed in the file).

    Raises MechanismFileError for what ``fmt`` cannot express (a higher pair; for URDF a ball
    or universal joint in the tree)."""
    spec, model = mech.spec, mech.model
    state = KinematicState(mech, q)
    rep = dict(spec.replacements)
    for c in spec.cut_joints:
        if c.type not in WRITABLE_CUTS:
            raise MechanismFileError(mech.path, f"loop joint {quote(c.name)} is a {c.type} pair: {fmt} cannot "
                                                "express it (lower pairs only)")
    world = {name: state.frame_placement(mech.link_frame(name)) for name in spec.links}
    root = spec.root
    bodies = []
    if root != "world":
        bodies.append(PlacedBody(root, None, tuple(world[root].translation), matrix_quat(world[root].rotation)))
    values, empty = {}, []
    compounds = _compounds(mech, q, state, world) if fmt == "MJCF" else ()
    inner = {m: c for c in compounds for m in c.members[:-1]}
    last = {c.members[-1]: c for c in compounds}
    for j in spec.joints:
        if j.name in inner:  # written with the compound's last member
            continue
        first = _spec_joint(spec, last[j.name].members[0]) if j.name in last else j
        parent = None if first.parent == root else first.parent
        X = world[first.parent].inverse() * world[j.child] if parent is not None else world[j.child]
        t = rep.get(j.name) or j.type
        if t == "planar":
            raise MechanismFileError(mech.path, f"joint {quote(j.name)} is a planar tree joint: {fmt} export writes "
                                                "revolute, prismatic, ball, floating and fixed joints")
        if t.startswith(("UJOINT", "CARDAN")):
            raise MechanismFileError(mech.path, f"joint {quote(j.name)} is a universal joint (sidecar {t}): "
                                                f"write it as two revolutes to export it as {fmt}")
        joint, more, mass, com, inertia = None, (), 0.0, (0.0, 0.0, 0.0), (0.0,) * 6
        moving = t != "fixed" and t != "FIXED" and model.existJointName(j.name)
        if moving:
            jid = model.getJointId(j.name)
            kind = {"SPHERICAL": "ball", "floating": "free", "prismatic": "slide"}.get(t, "hinge")
            if kind == "ball" and fmt == "URDF":
                raise MechanismFileError(mech.path, f"joint {quote(j.name)} is a ball joint: URDF has none "
                                                    "(export it as MJCF)")
            if kind == "free" and parent is not None:
                raise MechanismFileError(mech.path, f"joint {quote(j.name)} is floating but not on a link of the "
                                                    f"ground: {fmt} allows free joints only there")
            if j.name in last:
                joint, *more = _compound_joints(mech, q, state, last[j.name], values, empty)
                more = tuple(more)
            else:
                joint = _placed_joint(mech, q, j, kind, values, empty)
            # Pinocchio's inertia of the joint's body, in the joint's frame: the child link's frame
            I = model.frames[mech.link_frame(j.child)].placement.actInv(model.inertias[jid])
            mass, com, inertia = float(I.mass), tuple(I.lever), _inertia(I)
        elif t in ("fixed", "FIXED"):
            joint = PlacedJoint(j.name, "fixed")
        bodies.append(PlacedBody(j.child, parent, tuple(X.translation), matrix_quat(X.rotation), joint, mass, com,
                                 inertia, more))
    cuts = []
    for c, s in zip(mech.cuts, spec.cut_joints):
        F = []
        for fid, frame in ((c.frame1, c.link1), (c.frame2, c.link2)):
            link = frame_link(mech, frame)
            F.append((link, world[link].inverse() * state.frame_placement(fid)))
        (b1, F1), (b2, F2) = F
        rel = state.frame_placement(c.frame1).inverse() * state.frame_placement(c.frame2)
        cuts.append(PlacedCut(s.name, s.type, b1, tuple(F1.translation), matrix_quat(F1.rotation), b2,
                              tuple(F2.translation), matrix_quat(F2.rotation), tuple(s.axis),
                              tuple(s.axis2) if s.axis2 is not None else None,
                              (tuple(rel.translation), matrix_quat(rel.rotation))))
    couplings = []
    for cp in spec.couplings:
        primary = values.get(cp.mimics, 0.0)
        couplings.append(coupling_about(cp, primary, cp.multiplier * primary + cp.offset))
    notes = ()
    coned = [c.name for c in compounds if c.type == "spherical" and any(
        abs(model.lowerPositionLimit[mech.coordinate(m).idx_q]) < _NO_LIMIT for m in c.members)]
    if coned:
        notes += (f"the members' ranges of {len(coned)} ball joints ({', '.join(quote(n, 30) for n in coned[:3])}"
                  f"{', ...' if len(coned) > 3 else ''}) are not written: a ball's range is a cone",)
    mixed = [c.name for c in compounds if c.type == "spherical" and len({tuple(_spec_joint(spec, m).dynamics.items())
                                                                        for m in c.members}) > 1]
    if mixed:
        notes += (f"the members of {len(mixed)} ball joints ({', '.join(quote(n, 30) for n in mixed[:3])}) have "
                  "different armature, damping or friction loss: a ball has one of each, none is written",)
    if empty:
        notes += (f"{len(empty)} joints with empty limits (lower = upper: {', '.join(quote(n, 30) for n in empty[:3])}"
                  f"{', ...' if len(empty) > 3 else ''}) are written unlimited, as screwkin moves them",)
    gears = tuple((t.joint, t.scale * t.gear) for t in mech.transmissions() if t.scale * t.gear != 1.0)
    return PlacedMechanism(spec.name, tuple(bodies), tuple(cuts), tuple(couplings), tuple(mech.actuated), comment,
                           length if length else mech.length, notes, gears, tuple(compounds))


def _spec_joint(spec, name: str):
    return next(j for j in spec.joints if j.name == name)


def _placed_joint(mech: Mechanism, q: np.ndarray, j, kind: str, values: dict, empty, axis=None, pos=(0.0, 0.0, 0.0)) -> PlacedJoint:
    """The PlacedJoint of tree joint ``j`` (a hinge or slide keeps its range about q; ``values``
    and ``empty`` collect its value and an empty range)."""
    model = mech.model
    rng = None
    coord = next((c for c in mech.coordinates if c.joint == j.name), None)
    if kind in ("hinge", "slide") and coord is not None:
        value = float(q[coord.idx_q]) if coord.nq == 1 else continuous_angle(q, coord.idx_q)  # a turn's (cos, sin)
        values[j.name] = value
        lo, hi = model.lowerPositionLimit[coord.idx_q], model.upperPositionLimit[coord.idx_q]
        if abs(lo) < _NO_LIMIT and abs(hi) < _NO_LIMIT:
            if hi > lo:
                rng = (float(lo - value), float(hi - value))
            else:
                empty.append(j.name)
    axis = tuple(float(a) for a in j.axis) if axis is None else axis
    dyn = dict(j.dynamics)
    if "springref" in dyn and j.name in values:  # the joint's zero moves to its value at q, as its range does
        rest = dyn["springref"] - values[j.name]  # a hinge's within half a turn (analysis/forces/joint_dynamics)
        dyn["springref"] = wrap_angle(rest) if kind == "hinge" else rest
    return PlacedJoint(j.name, kind, axis, rng, tuple(dyn.items()), tuple(float(x) for x in pos))


def _compounds(mech: Mechanism, q: np.ndarray, state: KinematicState, world: dict) -> list:
    """The tree's compound joints (model.topology: revolutes and prismatics through massless links)
    that MJCF writes as one body's joints: spherical (a ball), universal, cylindrical; only where the
    massless links carry nothing else and no member is coupled, nor, for a ball, an input."""
    spec = mech.spec
    tree = {j.name: j for j in spec.joints}
    coupled = {c.joint for c in spec.couplings} | {c.mimics for c in spec.couplings}
    cut_links = {frame_link(mech, f) for c in mech.cuts for f in (c.link1, c.link2)}
    out = []
    for J in build_topology(mech, q).joints:
        if J.type not in ("spherical", "universal", "cylindrical") or len(J.members) < 2 or J.cut:
            continue
        if any(m not in tree for m in J.members) or coupled & set(J.members):
            continue
        if J.type == "spherical" and set(mech.actuated) & set(J.members):
            continue
        ms = [tree[m] for m in J.members]
        children = {m.child for m in ms}
        first = [m for m in ms if m.parent not in children]
        if len(first) != 1:
            continue
        chain = first
        while len(chain) < len(ms):
            nxt = [m for m in ms if m.parent == chain[-1].child]
            if len(nxt) != 1:
                break
            chain.append(nxt[0])
        inside = tuple(m.child for m in chain[:-1])
        touching = [j for j in spec.joints if (j.parent in inside or j.child in inside) and j.name not in J.members]
        if len(chain) != len(ms) or touching or cut_links & set(inside):
            continue
        C = world[chain[-1].child]
        axes = []
        for m in chain:
            M = state.joint_placement(mech.model.getJointId(m.name))
            axes.append(tuple(C.rotation.T @ M.rotation @ np.asarray(m.axis, float)))
        vals = tuple(float(q[mech.coordinate(m.name).idx_q]) for m in chain)
        out.append(PlacedCompound(J.type, J.name, tuple(m.name for m in chain), inside, chain[-1].child,
                                  tuple(axes), vals))
    names = {j.name for j in spec.joints} | set(spec.links) | {c.name for c in spec.cut_joints}
    for k, c in enumerate(out):  # a ball's name (the compound's) never one of the file's
        if c.type == "spherical":
            name, n = c.name, 1
            while name in names:
                n += 1
                name = f"{c.name}~{n}"
            names.add(name)
            out[k] = PlacedCompound(c.type, name, c.members, c.links, c.body, c.axes, c.values)
    return out


def _compound_joints(mech: Mechanism, q: np.ndarray, state: KinematicState, c: PlacedCompound, values: dict, empty) -> list:
    """The PlacedJoints of compound ``c`` in its body (``state``: the KinematicState at q): one ball at
    the members' common point, or the members' own joints with their axes and points in the body's frame."""
    C = state.frame_placement(mech.link_frame(c.body))
    ms = [_spec_joint(mech.spec, m) for m in c.members]
    points = [C.actInv(state.centre(("joint", mech.model.getJointId(m.name)))) for m in ms]
    if c.type == "spherical":
        for m in ms:
            values[m.name] = float(q[mech.coordinate(m.name).idx_q])
        common = [dict(m.dynamics) for m in ms]
        dyn = tuple(common[0].items()) if all(d == common[0] for d in common) else ()
        return [PlacedJoint(c.name, "ball", (0.0, 0.0, 1.0), None, dyn, tuple(np.mean(points, axis=0)))]
    kinds = {"revolute": "hinge", "continuous": "hinge", "prismatic": "slide"}
    return [_placed_joint(mech, q, m, kinds[m.type], values, empty, axis, p)
            for m, axis, p in zip(ms, c.axes, points)]


def ball_values(c: PlacedCompound, quat: Sequence[float]) -> dict:
    """The member joints' values [rad] of an exported ball ``c`` whose quaternion (MuJoCo's w, x, y, z)
    is ``quat``: Q = R(a0, d0) R(a1, d1) R(a2, d2) about its axes (Davenport angles, the branch through
    zero), the members at c.values + d."""
    R = pin.Quaternion(*[float(x) for x in quat]).normalized().matrix()
    d = davenport(R, [np.asarray(a, float) for a in c.axes])
    return {m: v + dv for m, v, dv in zip(c.members, c.values, d)}


def _angle_about(n: int, v: np.ndarray, w: np.ndarray) -> float:
    """The angle [rad] about unit axis n taking v's projection on n's plane to w's."""
    v = v - (n @ v) * n
    w = w - (n @ w) * n
    return float(np.arctan2(n @ np.cross(v, w), v @ w))


def davenport(R: np.ndarray, axes: list):
    """(a, b, c) with R = R(n1, a) R(n2, b) R(n3, c) for unit axes n1, n2, n3 (n2 not parallel to
    either other), the solution nearest zero in b.  n1 . R n3 = n1 . R(n2, b) n3 = A cos b + B sin b + C
    with A = n1.n3 - (n1.n2)(n2.n3), B = n1.(n2 x n3), C = (n1.n2)(n2.n3) gives b; a turns R(n2, b) n3
    onto R n3 about n1; c is the turn about n3 that R(n2, b)^T R(n1, a)^T R leaves (Shuster and
    Markley's generalization of Euler angles).  Axes that span space (a spherical compound's) make
    A, B not both zero (B is their determinant)."""
    n1, n2, n3 = (a / np.linalg.norm(a) for a in axes)
    A = n1 @ n3 - (n1 @ n2) * (n2 @ n3)
    B = n1 @ np.cross(n2, n3)
    C = (n1 @ n2) * (n2 @ n3)
    rho, phi = float(np.hypot(A, B)), float(np.arctan2(B, A))
    delta = float(np.arccos(np.clip((n1 @ R @ n3 - C) / rho, -1.0, 1.0)))
    b = wrap_angle(min((phi + delta, phi - delta), key=lambda x: abs(wrap_angle(x))))
    R2 = pin.exp3(n2 * b)
    v = R2 @ n3
    lock = np.linalg.norm(v - (n1 @ v) * n1) < DEFAULT.geometry  # gimbal lock: a and c turn about one line
    a = 0.0 if lock else _angle_about(n1, v, R @ n3)
    e = perpendicular_basis(n3)[0]  # c: the turn about n3 that R(n1, a) R(n2, b) leaves, of a normal to n3
    c = _angle_about(n3, e, R2.T @ pin.exp3(-n1 * a) @ R @ e)
    return a, b, c


def check_closed(mech: Mechanism, q: np.ndarray, tol: float) -> float:
    """The largest loop-closure residual at q [m or rad]; MechanismFileError when over tol."""
    r = float(np.max(np.abs(mech.closure.residual(q)))) if mech.closure.nrows else 0.0
    if r > tol:
        raise MechanismFileError(mech.path, f"the loops are not closed at the configuration to write (residual "
                                            f"{r:.3g}): solve first")
    return r

