"""A parallel platform whose every leg's length follows from the platform's pose: its legs, and
each leg's joint values for a pose, in closed form.

A leg here is a chain from the ground to the output link (the platform): revolutes whose axes meet
at a point A of the ground (one revolute: any point of its axis; two: a universal joint), one
prismatic joint, then either revolutes meeting at a point B of the platform (in the tree: one, two
or three, a spherical joint written as revolutes) or a loop joint (spherical or revolute) between
the leg's last link and the platform at B.  The platform hangs from one such leg, or from a floating
joint.  With the platform at pose T, B is known, so

    |B - A| = |d0 + x u|      (d0: from A to the leg's end at joint values 0, u: the slide's axis,
                               both in the world at the file's configuration: screw coordinates)

gives the slide x (two roots: the leg extended, and the leg reversed through its pivot A), and the
revolutes at A turn d0 + x u onto B - A (Paden-Kahan subproblems 1 and 2: the universal joint's
two angle sets), those at B the rest of the platform's rotation (model.subproblems.run_angles; a
spherical joint's two angle sets).  The angle sets of one leg with one x place every joint centre
alike (the leg spun by pi about its own line, a spherical joint's other Euler set): they are
spellings of one pose, ``LegPose.sets``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..tolerances import DEFAULT
from ._pin import joint_axis
from .geometry import lines_point
from .manifold import continuous_angle, set_continuous_angle
from .state import KinematicState
from .subproblems import rotation, rotation_to, run_angles, two_rotations
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from collections.abc import Sequence

__all__ = ["LegChain", "Platform", "platform_of", "LegPose", "leg_poses", "set_leg", "set_free", "best_set",
           "respell", "common_output"]

TINY = 1e-12  # guard: the square of a leg's length (m^2) and lines_point's parallel test, never zero


@dataclass(frozen=True)
class LegChain:
    """One leg (see the module): its prismatic joint's name; joint ids at A (from the ground), of the
    slide, and at B in the tree (none when a loop joint closes it: ``cut``); the world axes of those
    revolutes and of the slide at the file's configuration; A, the leg's end at B there (f0), and B
    in the output joint's frame (b_local) [m]."""

    name: str
    a_joints: tuple
    slide: int
    b_joints: tuple
    a_axes: tuple
    b_axes: tuple
    u0: tuple
    A: tuple
    f0: tuple
    b_local: tuple
    cut: str | None

    @property
    def joints(self) -> tuple:
        return self.a_joints + (self.slide,) + self.b_joints


@dataclass(frozen=True)
class Platform:
    """The output joint (carrying the output link), its world placement at the file's configuration
    (M0, a pinocchio.SE3), the floating joint that holds it (or None: a leg holds it), the legs."""

    out_joint: int
    M0: object
    free: int | None
    legs: tuple


@dataclass(frozen=True)
class LegPose:
    """One leg's joint values for one platform pose and one root of its slide: ``x`` [m] (``extended``:
    the root that lengthens the leg, else the leg reversed through its pivot), ``sets``: every
    angle set ({joint id: angle}) that places its joint centres there (spellings of one pose)."""

    leg: LegChain
    x: float
    extended: bool
    sets: tuple


def _joint_letter(model: pin.Model, j: int) -> str:
    """R (one-axis revolute), P (prismatic), F (floating) or ? for joint j of the model."""
    short = model.joints[j].shortname()
    if model.joints[j].nv == 1 and short.startswith("JointModelR"):
        return "R"
    if model.joints[j].nv == 1 and short.startswith("JointModelP") and "Planar" not in short:
        return "P"
    if short == "JointModelFreeFlyer":
        return "F"
    return "?"


def platform_of(mech: Mechanism, out_joint: int, tol: float = DEFAULT.closed_form):
    """The Platform whose output link is carried by ``out_joint``, or None when the mechanism is not one
    (see the module).  Read once per mechanism and output joint."""
    key = ("platform", out_joint)
    if key not in mech.cache:
        mech.cache[key] = _find_platform(mech, out_joint, tol)
    return mech.cache[key]


def _find_platform(mech: Mechanism, out_joint: int, tol: float) -> Platform | None:
    model = mech.model
    if not mech.cuts or mech.couplings or getattr(mech, "extra_rows", None) or out_joint <= 0:
        return None
    state = KinematicState(mech, pin.neutral(model))
    scale = max(mech.length, 1e-3)
    legs, free = [], None
    path = _joints_from_ground(model, out_joint)
    if len(path) == 1 and _joint_letter(model, path[0]) == "F":
        free = path[0]
    else:
        leg = _leg_chain(model, state, path, None, None, scale, tol)
        if leg is None or leg.b_joints[-1:] != (out_joint,) or not leg.b_joints:
            return None
        legs.append(leg)
    for c in mech.cuts:
        if c.type not in ("spherical", "revolute", "continuous", "universal") or c.pair is not None:
            return None
        j1, j2 = model.frames[c.frame1].parentJoint, model.frames[c.frame2].parentJoint
        if j2 == out_joint:
            f_leg, f_out = c.frame1, c.frame2
        elif j1 == out_joint:
            f_leg, f_out = c.frame2, c.frame1
        else:
            return None
        jl = model.frames[f_leg].parentJoint
        if jl <= 0 or _joint_letter(model, jl) != "P":
            return None
        b_local = np.array(model.frames[f_out].placement.translation)
        leg = _leg_chain(model, state, _joints_from_ground(model, jl), c.name, (f_leg, b_local), scale, tol)
        if leg is None:
            return None
        legs.append(leg)
    used = [j for leg in legs for j in leg.joints] + ([free] if free else [])
    moving = [j for j in range(1, model.njoints) if model.joints[j].nv > 0]
    if len(set(used)) != len(used) or sorted(used) != moving:
        return None
    return Platform(out_joint, state.joint_placement(out_joint), free, tuple(legs))


def _joints_from_ground(model: pin.Model, j: int) -> list:
    """The joint ids from the ground to joint j (j last)."""
    out = []
    while j > 0:
        out.append(j)
        j = model.parents[j]
    return out[::-1]


def _leg_chain(model: pin.Model, state: KinematicState, path, cut, end: tuple | None, scale: float, tol: float) -> LegChain | None:
    """The LegChain of the joints ``path`` (see the module), read in ``state``, or None when they are no leg."""
    kinds = [_joint_letter(model, j) for j in path]
    if kinds.count("P") != 1:
        return None
    p = kinds.index("P")
    a, b = path[:p], path[p + 1:]
    if not 1 <= len(a) <= 2 or any(k != "R" for k in kinds[:p] + kinds[p + 1:]) or len(b) > 3:
        return None
    if (cut is None) == (not b):
        return None

    def axis(j: int):
        return state.joint_placement(j).rotation @ joint_axis(model.joints[j])

    def centre(js: Sequence[int]):
        if len(js) == 1:
            return np.array(state.joint_placement(js[0]).translation)
        o, off = lines_point([state.joint_placement(j).translation for j in js], [axis(j) for j in js], TINY)
        if o is None or off > tol * scale:
            return None
        return o

    A = centre(a)
    if A is None:
        return None
    if b:
        f0 = centre(b)
        if f0 is None:
            return None
        b_local = state.joint_placement(path[-1]).actInv(f0)
    else:
        f0 = np.array(state.frame_placement(end[0]).translation)
        b_local = end[1]
    if len(b) == 1 and np.linalg.norm(np.cross(axis(b[0]), f0 - state.joint_placement(b[0]).translation)) > tol * scale:
        return None
    name = model.names[path[p]]
    return LegChain(name, tuple(a), path[p], tuple(b), tuple(tuple(axis(j)) for j in a),
                    tuple(tuple(axis(j)) for j in b), tuple(axis(path[p])), tuple(A), tuple(f0),
                    tuple(float(v) for v in b_local), cut)


def leg_poses(platform: Platform, leg: LegChain, P: pin.SE3, tol: float = DEFAULT.closed_form) -> tuple:
    """(poses, why, gap): the leg's LegPoses (extended root first) for the output joint at world
    placement P (a pinocchio.SE3); when it has none, why (else "") and how far it stays from the pose
    [m]."""
    g = P * platform.M0.inverse()
    A, f0, u0 = (np.asarray(v) for v in (leg.A, leg.f0, leg.u0))
    B = P.act(np.asarray(leg.b_local)) if leg.cut else g.act(f0)
    d0, target = f0 - A, B - A
    L = float(np.linalg.norm(target))
    bb = float(d0 @ u0)
    disc = bb * bb - float(d0 @ d0) + L * L
    if disc < -tol * max(L * L, TINY):
        across = np.sqrt(max(float(d0 @ d0) - bb * bb, 0.0))
        return [], (f"leg {leg.name} cannot be {L:.6g} m long: its ends stay {across:.6g} m apart across its "
                    "axis"), across - L
    root = np.sqrt(max(disc, 0.0))
    out, why, gap = [], "", 0.0
    for x, extended in ((-bb + root, True), (-bb - root, False)):
        v = d0 + x * u0
        a_axes = [np.asarray(w) for w in leg.a_axes]
        if len(a_axes) == 1:
            w = a_axes[0]
            off = abs(float(w @ v - w @ target))
            t = rotation_to(w, v, target)
            a_sets = [] if t is None or off > DEFAULT.closed_check * max(L, 1e-3) else [(t,)]
            if off > DEFAULT.closed_check * max(L, 1e-3):
                why, gap = f"leg {leg.name} would leave the plane its pivot turns in by {off:.3g} m", off
        else:
            a_sets, _ = two_rotations(a_axes[0], a_axes[1], v, target, tol)
            if not a_sets:
                why = f"leg {leg.name}'s universal joint cannot turn it toward its platform joint"
        sets = []
        for ta in a_sets:
            RA = np.eye(3)
            for w, t in zip(a_axes, ta):
                RA = RA @ rotation(w, t)
            if np.linalg.norm(RA @ v - target) > DEFAULT.closed_check * max(L, 1e-3):
                continue
            vals = dict(zip(leg.a_joints, ta))
            if leg.b_joints:
                bs = run_angles([np.asarray(w) for w in leg.b_axes], RA.T @ g.rotation)
                if not bs:
                    why = f"leg {leg.name}'s joints at the platform cannot turn it to this orientation"
                for tb in bs:
                    sets.append({**vals, **dict(zip(leg.b_joints, tb))})
            else:
                sets.append(vals)
        if sets:
            out.append(LegPose(leg, float(x), extended, tuple(sets)))
    return out, ("" if out else why or f"leg {leg.name} cannot reach the pose"), gap


def set_leg(model: pin.Model, q: np.ndarray, pose: LegPose, angles: dict) -> np.ndarray:
    """q with the leg's slide at pose.x and its revolutes at ``angles`` (in place; returned)."""
    q[model.joints[pose.leg.slide].idx_q] = pose.x
    for j, t in angles.items():
        jm = model.joints[j]
        if jm.nq == 2:
            set_continuous_angle(q, jm.idx_q, t)
        else:
            q[jm.idx_q] = t
    return q


def set_free(platform: Platform, model: pin.Model, q: np.ndarray, P: pin.SE3) -> np.ndarray:
    """q with the floating joint holding the platform at the output joint's world placement P."""
    if platform.free is not None:
        jm = model.joints[platform.free]
        q[jm.idx_q:jm.idx_q + 7] = pin.SE3ToXYZQUAT(model.jointPlacements[platform.free].inverse() * P)
    return q


def best_set(mech: Mechanism, q: np.ndarray, pose: LegPose, near: np.ndarray | None=None):
    """The angle set of ``pose`` to report: the fewest of its joints outside the file's limits, then
    the nearest ``near`` (a configuration; default the file's), angles compared modulo a turn."""
    model = mech.model
    near = pin.neutral(model) if near is None else near
    names, idx, lo, hi, angle = mech.limited_coordinates()
    limits = {int(i): (a, b, ang) for i, a, b, ang in zip(idx, lo, hi, angle)}

    def key(s) -> tuple:
        bad, far = 0, 0.0
        for j, t in s.items():
            jm = model.joints[j]
            if jm.nq == 1 and jm.idx_q in limits:
                a, b, ang = limits[jm.idx_q]
                bad += not (a <= t <= b or (ang and a <= t + 2 * np.pi * np.ceil((a - t) / (2 * np.pi)) <= b))
            ref = np.arctan2(near[jm.idx_q + 1], near[jm.idx_q]) if jm.nq == 2 else near[jm.idx_q]
            far += abs(float(np.angle(np.exp(1j * (t - ref)))))
        return bad, far

    return min(pose.sets, key=key)


def common_output(mech: Mechanism):
    """The joint carrying the link every loop joint closes on (a platform's), or None."""
    model = mech.model
    common = None
    for c in mech.cuts:
        js = {model.frames[c.frame1].parentJoint, model.frames[c.frame2].parentJoint}
        common = js if common is None else common & js
    return next(iter(common)) if common and len(common) == 1 else None


def respell(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """q with each platform leg (see the module) whose joints lie outside the file's limits written in
    an angle set of the same pose within them, where one exists (the leg's slide kept); q itself when
    the mechanism is no such platform or nothing changes.  A pose, not its spelling, is within the
    limits or not."""
    key = "respell_joint"
    if key not in mech.cache:
        j = common_output(mech) if mech.cuts else None
        mech.cache[key] = j
    j = mech.cache[key]
    platform = platform_of(mech, j) if j else None
    if platform is None:
        return q
    model = mech.model
    P = KinematicState(mech, q).joint_placement(platform.out_joint)
    out = np.array(q, float)
    names, idx, lo, hi, angle = mech.limited_coordinates()
    bad = {int(i) for i in idx[_outside_rows(q, idx, lo, hi, angle)]}
    for leg in platform.legs:
        if not any(model.joints[j].idx_q in bad for j in leg.joints if model.joints[j].nq == 1 and j != leg.slide):
            continue  # its angles are within their limits (a slide outside them no spelling moves)
        poses = leg_poses(platform, leg, P)[0]
        if not poses:
            continue
        x = q[model.joints[leg.slide].idx_q]
        pose = min(poses, key=lambda p: abs(p.x - x))
        if abs(pose.x - x) > mech.tolerances.geometry * max(mech.length, 1e-3):
            continue
        best = best_set(mech, q, pose, near=pin.neutral(model))
        now = {j: _joint_angle(model, q, j) for j in best}
        if _bad(mech, best) < _bad(mech, now):  # only where the leg gets within its limits
            set_leg(model, out, pose, best)
    return out


def _joint_angle(model: pin.Model, q: np.ndarray, j: int) -> float:
    """Joint j's value in q (a continuous joint's angle from its (cos, sin))."""
    jm = model.joints[j]
    return float(continuous_angle(q, jm.idx_q)) if jm.nq == 2 else float(q[jm.idx_q])


def _bad(mech: Mechanism, angles: dict) -> int:
    """How many of the revolutes {joint id: angle} lie outside the file's limits (modulo a turn)."""
    _, idx, lo, hi, angle = mech.limited_coordinates()
    where = {int(i): k for k, i in enumerate(idx)}
    rows = [(where[mech.model.joints[j].idx_q], t) for j, t in angles.items()
            if mech.model.joints[j].nq == 1 and mech.model.joints[j].idx_q in where]
    if not rows:
        return 0
    k = np.array([r[0] for r in rows])
    q = np.zeros(int(idx.max()) + 1)
    q[idx[k]] = [r[1] for r in rows]
    return int(_outside_rows(q, idx[k], lo[k], hi[k], angle[k]).sum())


def _outside_rows(q: np.ndarray, idx, lo, hi, angle):
    """Which limited coordinates of q lie outside their range (angles modulo a turn)."""
    v = np.asarray(q)[idx]
    out = (v < lo) | (v > hi)
    shifted = v + 2 * np.pi * np.ceil((lo - v) / (2 * np.pi))
    return out & ~(angle & (lo <= shifted) & (shifted <= hi))
