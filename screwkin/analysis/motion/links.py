"""Absolute motion in the user's quantities: links, named points and loop-joint coordinates.

Read from :class:`~screwkin.model.state.KinematicState` for one solution (``solve``); for every
step of a motion (``sweep``) the same quantities computed on stacks of configurations:

* ``link_motions(state, angles, normal)``: each moving link's frame origin (position, velocity,
  acceleration), its angular velocity and acceleration; planar mechanisms: the vector-loop angle
  and omega, alpha as numbers about the plane's normal;
* ``point_motions(state, points)``: the points people name, ``NAME=LINK:x,y,z`` (coordinates in the
  link's frame): position, velocity, acceleration in world axes;
* ``motion_along(mech, Q, V, A, points, angles, normal)``: the same for every step of a sweep,
  as arrays, with the loop joints' coordinates; ``sweep_motion(mech, res, points)``: that along a
  SweepResult, with a planar mechanism's angles and plane normal found for it;
* ``strokes(res, motion, mech, solver)``: each slider's travel along a sweep, its ends, and a
  whole-turn crank's time ratio.

Units: m, rad, s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...errors import ScrewkinError, UsageError
from ...model.state import KinematicState, loop_coordinate_cuts
from ...model.kernel.stacks import tree_kinematics
from .planar import LinkAngles
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.model.mechanism import Coordinate
    from screwkin.tolerances import Tolerances

__all__ = ["Point", "link_motions", "point_motions", "MotionAlong", "motion_along", "sweep_motion", "moving_links",
           "Stroke", "strokes"]


@dataclass(frozen=True)
class Point:
    """A point fixed on a link: ``local`` [m] in the link's frame."""

    name: str
    link: str
    local: tuple


def moving_links(mech: Mechanism) -> tuple:
    """The links that move (those with a frame of their own not welded to the ground), in file order."""
    out = []
    for link in mech.spec.links:
        try:
            fid = mech.link_frame(link)
        except UsageError:  # a link merged away (massless, inside a compound joint): no frame of its own
            continue
        if mech.model.frames[fid].parentJoint != 0:
            out.append(link)
    return tuple(out)


def link_motions(state: KinematicState, angles: dict | None=None, normal: np.ndarray | None = None, along: dict | None=None) -> dict:
    """Every moving link's absolute motion at a state: ``position`` (and, with rates, ``velocity``,
    ``acceleration``) of its frame origin [m, m/s, m/s^2], ``omega`` and ``alpha`` [rad/s, rad/s^2];
    planar mechanisms (``normal`` given): ``angle`` [rad] from ``angles`` (the vector-loop angles of
    LinkAngles) with ``angle_along``, the two points it is measured along (``along``: LinkAngles.along),
    and omega, alpha as numbers about the plane's normal, else 3-vectors (world axes)."""
    out = {}
    for link in moving_links(state.mech):
        d = state.link_motion(link)
        if normal is not None:
            if angles is not None and link in angles:
                d["angle"] = angles[link]
                if along and link in along:
                    d["angle_along"] = list(along[link])
            if "omega" in d:
                d["omega"], d["alpha"] = float(d["omega"] @ normal), float(d["alpha"] @ normal)
        out[link] = d
    return out


def point_motions(state: KinematicState, points: tuple) -> dict:
    """name -> {link, position, velocity, acceleration} of each Point (velocity and acceleration
    only when the state has rates)."""
    out = {}
    for p in points:
        m = state.point(p.link, p.local)
        d = {"link": p.link, "local": list(p.local), "position": m.position}
        if m.velocity is not None:
            d.update(velocity=m.velocity, acceleration=m.acceleration)
        out[p.name] = d
    return out


@dataclass(frozen=True)
class MotionAlong:
    """Absolute motion at every step of a motion (arrays over the steps, first axis)."""

    loop_joints: dict  # cut joint -> (steps,) values [rad or m]
    loop_rates: dict
    loop_accelerations: dict
    links: dict  # link -> {angle?, omega, alpha, position, velocity, acceleration}: (steps,) or (steps, 3)
    points: dict  # name -> {link, local, position, velocity, acceleration}: (steps, 3)
    angular_loop: tuple  # loop joints whose coordinate is an angle
    normal: tuple | None = None  # planar mechanisms: the plane's normal omega and alpha are about


def motion_along(mech: Mechanism, Q: np.ndarray, V: np.ndarray, A: np.ndarray, points: tuple | list=(), angles: LinkAngles | None = None, normal: np.ndarray | None = None) -> MotionAlong:
    """The absolute motion at each configuration Q[k] with rates V[k] and accelerations A[k];
    ``angles``: a callable q -> link angles (LinkAngles) for planar mechanisms, with ``normal``.

    The quantities of KinematicState (link_motions, point_motions, loop_value, loop_rate,
    loop_acceleration) for every step: one Pinocchio pass a step gives the frames' placements,
    velocities and classical accelerations, and the formulas run on the stacks."""
    model = mech.model
    cuts = loop_coordinate_cuts(mech)
    links = moving_links(mech)
    link_f = [mech.link_frame(link) for link in links]
    point_f = [mech.link_frame(p.link) for p in points]
    frames = list(dict.fromkeys(link_f + point_f + [f for c in cuts for f in (c.frame1, c.frame2)]))
    col = {f: i for i, f in enumerate(frames)}
    tree = tree_kinematics(mech) if len(Q) else None
    R, t, tw, ac = (tree.motions(Q, V, A, frames) if tree is not None
                    else _frame_motions(model, mech.scratch_data(), frames, Q, V, A))
    named = None
    if angles is not None and normal is not None:
        named = angles.batch(Q) if hasattr(angles, "batch") else {
            link: np.array([a[link] for a in map(angles, Q)]) for link in (angles(Q[0]) if len(Q) else ())}
    out_links = {}
    along = angles.along() if named is not None and hasattr(angles, "along") else {}
    for link, f in zip(links, link_f):
        i = col[f]
        d = {"position": t[:, i].copy(), "velocity": tw[:, i, :3].copy(), "acceleration": ac[:, i, :3].copy(),
             "omega": tw[:, i, 3:].copy(), "alpha": ac[:, i, 3:].copy()}
        if normal is not None:
            if named is not None and link in named:
                d["angle"] = np.asarray(named[link], float)
                if link in along:
                    d["angle_along"] = list(along[link])
            d["omega"], d["alpha"] = d["omega"] @ normal, d["alpha"] @ normal
        out_links[link] = d
    pts = {}
    for p, f in zip(points, point_f):
        i = col[f]
        r = R[:, i] @ np.asarray(p.local, float)
        w, al = tw[:, i, 3:], ac[:, i, 3:]
        pts[p.name] = {"link": p.link, "local": list(p.local), "position": t[:, i] + r,
                       "velocity": tw[:, i, :3] + np.cross(w, r),
                       "acceleration": ac[:, i, :3] + np.cross(al, r) + np.cross(w, np.cross(w, r))}

    def dot(x: np.ndarray, y: np.ndarray):
        return np.einsum("ij,ij->i", x, y)

    loops, loop_rates, loop_accs = {}, {}, {}
    for c in cuts:
        i1, i2 = col[c.frame1], col[c.frame2]
        R1, R2 = R[:, i1], R[:, i2]
        axis = R1 @ np.asarray(c.axis, float)
        axis = axis / np.linalg.norm(axis, axis=1, keepdims=True)
        (v1, w1), (v2, w2) = (tw[:, i1, :3], tw[:, i1, 3:]), (tw[:, i2, :3], tw[:, i2, 3:])
        (a1, al1), (a2, al2) = (ac[:, i1, :3], ac[:, i1, 3:]), (ac[:, i2, :3], ac[:, i2, 3:])
        da = np.cross(w1, axis)  # d axis / dt
        dda = np.cross(al1, axis) + np.cross(w1, da)
        if c.type == "prismatic":
            r = t[:, i2] - t[:, i1]
            loops[c.name] = dot(r, axis)
            loop_rates[c.name] = dot(v2 - v1, axis) + dot(r, np.cross(w1, axis))
            loop_accs[c.name] = dot(a2 - a1, axis) + 2.0 * dot(v2 - v1, da) + dot(r, dda)
        else:  # R = F2 in F1, a rotation about the axis: sin from its antisymmetric part, cos from its trace
            Rr = R1.transpose(0, 2, 1) @ R2
            a = np.asarray(c.axis, float) / np.linalg.norm(c.axis)
            anti = np.stack([Rr[:, 2, 1] - Rr[:, 1, 2], Rr[:, 0, 2] - Rr[:, 2, 0], Rr[:, 1, 0] - Rr[:, 0, 1]], axis=1)
            loops[c.name] = np.arctan2(0.5 * anti @ a, 0.5 * (np.trace(Rr, axis1=1, axis2=2) - (Rr @ a) @ a))
            loop_rates[c.name] = dot(w2 - w1, axis)
            loop_accs[c.name] = dot(al2 - al1, axis) + dot(w2 - w1, da)
    return MotionAlong(loops, loop_rates, loop_accs, out_links, pts,
                       tuple(c.name for c in cuts if c.type != "prismatic"),
                       None if normal is None else tuple(float(x) for x in normal))


def sweep_motion(mech: Mechanism, res, points: tuple=()) -> MotionAlong:
    """The absolute motion along a sweep ``res`` (analysis.motion.sweep.SweepResult): a planar
    mechanism's (its topology at the first step) with the vector-loop angles of LinkAngles, omega and
    alpha about the plane's normal; a spatial one's as vectors.  What ``sweep`` and ``report`` show."""
    angles = None
    if len(res.q):
        topo = mech.topology(res.q[0])
        if topo.motion_space == "planar" and topo.normal is not None:
            angles = LinkAngles(mech, topo)
    return motion_along(mech, res.q, res.rates, res.accelerations, points, angles,
                        None if angles is None else angles.n)




def _frame_motions(model: pin.Model, data: pin.Data, frames: list, Q: np.ndarray, V: np.ndarray, A: np.ndarray) -> tuple:
    """Placements (R (N, F, 3, 3), t (N, F, 3)), velocities (v, w) and classical accelerations
    (a, alpha) of the frames' origins in world axes (N, F, 6) -- what pin.getFrameVelocity and
    pin.getFrameClassicalAcceleration give in LOCAL_WORLD_ALIGNED -- from one forwardKinematics a
    step, the joints' placements, spatial velocities and accelerations read once and the frames'
    placed on the stacks."""
    parents = [model.frames[f].parentJoint for f in frames]
    joints = sorted(set(parents) - {0})
    N, J = len(Q), len(joints)
    Rj, pj, vj, aj = np.empty((N, J, 3, 3)), np.empty((N, J, 3)), np.empty((N, J, 6)), np.empty((N, J, 6))
    for k in range(N):
        pin.forwardKinematics(model, data, Q[k], V[k], A[k])
        for i, j in enumerate(joints):
            M = data.oMi[j]
            Rj[k, i], pj[k, i], vj[k, i], aj[k, i] = M.rotation, M.translation, data.v[j].vector, data.a[j].vector
    F = len(frames)
    R, t = np.empty((N, F, 3, 3)), np.empty((N, F, 3))
    tw, ac = np.zeros((N, F, 6)), np.zeros((N, F, 6))
    for i, (f, j) in enumerate(zip(frames, parents)):
        X = model.frames[f].placement
        if j == 0:  # on the ground
            R[:, i], t[:, i] = X.rotation, X.translation
            continue
        c = joints.index(j)
        Rc, x = Rj[:, c], X.translation
        R[:, i], t[:, i] = Rc @ X.rotation, pj[:, c] + Rc @ x
        v, w, a, al = vj[:, c, :3], vj[:, c, 3:], aj[:, c, :3], aj[:, c, 3:]
        vo = v + np.cross(w, x)  # the frame origin's velocity, joint axes
        ao = a + np.cross(al, x) + np.cross(w, vo)  # its classical acceleration
        for out, (lin, ang) in ((tw, (vo, w)), (ac, (ao, al))):
            out[:, i, :3] = np.einsum("nij,nj->ni", Rc, lin)
            out[:, i, 3:] = np.einsum("nij,nj->ni", Rc, ang)
    return R, t, tw, ac


LOCATE_XTOL = 1e-12  # singular points and a slider's ends are located to this in the input [rad or m]


@dataclass(frozen=True)
class Stroke:
    """A slider's travel along a motion: ``stroke`` = largest - smallest coordinate [m], the input values
    at its two ends, and, for a crank that turned a whole turn, the time ratio of the two strokes at a
    constant crank speed (the larger crank angle over the smaller; 1 for a centred slider-crank)."""

    coordinate: str
    stroke: float
    low_at: float
    high_at: float
    time_ratio: float | None
    crank_angles: tuple | None  # (forward, return) crank angles [rad] when time_ratio is known


def _extrema(x: np.ndarray, p: np.ndarray, dp: np.ndarray, tol: Tolerances) -> list:
    """(input value, coordinate) at each zero of dp/dx along the samples: the cubic Hermite
    interpolant of p on each bracket whose slope changes sign (accurate to O(h^4)), its vertex."""
    out = []
    for k in range(len(x) - 1):
        if not (dp[k] == 0.0 or dp[k] * dp[k + 1] < 0):
            continue
        h = x[k + 1] - x[k]
        p0, p1, m0, m1 = p[k], p[k + 1], dp[k] * h, dp[k + 1] * h
        # p(t) = (2t^3 - 3t^2 + 1) p0 + (t^3 - 2t^2 + t) m0 + (-2t^3 + 3t^2) p1 + (t^3 - t^2) m1, t in [0, 1]
        a = 6 * p0 + 3 * m0 - 6 * p1 + 3 * m1
        b = -6 * p0 - 4 * m0 + 6 * p1 - 2 * m1
        roots = np.roots([a, b, m0]) if abs(a) > 0 else np.array([-m0 / b]) if b else np.array([0.0])
        t = next((float(r.real) for r in roots
                  if abs(r.imag) < tol.zero and -tol.equal <= r.real <= 1 + tol.equal), 0.5)
        value = ((2 * t**3 - 3 * t**2 + 1) * p0 + (t**3 - 2 * t**2 + t) * m0 + (-2 * t**3 + 3 * t**2) * p1
                 + (t**3 - t**2) * m1)
        out.append((float(x[k] + t * h), float(value)))
    return out


def _stroke_end(solver, res, name: str, coordinate: Coordinate, x: np.ndarray, guess: tuple) -> tuple:
    """(input, coordinate) at a slider's end between the samples x[k], x[k + 1] of a sweep: the zero of
    its rate located by Brent's method on the mechanism itself (each trial closed by damped Newton
    from the sample before it), not on an interpolant; ``guess`` (the interpolant's) when that fails."""
    from scipy.optimize import brentq

    k = int(np.clip(np.searchsorted(x, guess[0]) - 1, 0, len(x) - 2))
    mech, q0, cache = solver.mech, res.q[k], {}

    def at(v: float) -> float:
        a = solver.track({res.input: v}, q0)
        qd = solver.rates(a.q, mech.closure.jacobian(a.q), {res.input: 1.0})
        if coordinate is not None:
            cache[v] = float(a.q[coordinate.idx_q])
            return float(qd[coordinate.idx_v])
        state = KinematicState(mech, a.q, qd)
        cache[v] = float(state.loop_joints[name])
        return float(state.loop_rates[name])

    try:
        lo, hi = float(x[k]), float(x[k + 1])
        if at(lo) * at(hi) > 0:
            return guess
        v = brentq(at, lo, hi, xtol=LOCATE_XTOL * max(1.0, abs(hi)), rtol=4 * np.finfo(float).eps)
        at(v)
        return float(v), cache[v]
    except (ScrewkinError, ValueError, RuntimeError):
        return guess


def strokes(res, motion: MotionAlong, mech: Mechanism, solver=None) -> list:
    """A Stroke for each slider coordinate (prismatic tree joint or prismatic loop joint) of a sweep
    ``res`` (analysis.motion.sweep.SweepResult) with its MotionAlong.  With the sweep's ``solver``
    (analysis.position.position.PositionSolver) each end is located on the mechanism (Brent's method on
    the slider's rate); without, on the cubic interpolant of the samples (O(h^4))."""
    series = []
    for k, name in enumerate(res.names):
        c = next((c for c in mech.coordinates if c.joint == name), None)
        if c is not None and c.nv == 1 and mech.translational[c.idx_v]:
            series.append((name, res.joints[:, k], res.rates[:, k], c))
    for name, v in motion.loop_joints.items():
        if name not in motion.angular_loop:
            series.append((name, v, motion.loop_rates[name], None))
    x = np.asarray(res.values, float)
    tol = mech.tolerances
    turned = res.unit == "rad" and res.stopped_at is None and abs(x[-1] - x[0]) >= 2 * np.pi * (1 - tol.equal)
    out = []
    for name, values, rates, coordinate in series:
        values, slope = np.asarray(values, float), np.asarray(rates, float) / (res.rate or 1.0)
        inner = _extrema(x, values, slope, tol)
        if solver is not None and res.q is not None and len(res.q) == len(x):
            inner = [_stroke_end(solver, res, name, coordinate, x, e) for e in inner]
        ends = [(float(x[0]), float(values[0])), (float(x[-1]), float(values[-1]))] + inner
        lo, hi = min(ends, key=lambda e: e[1]), max(ends, key=lambda e: e[1])
        ratio = angles = None
        if turned:
            z = [a for a, _ in inner if a < x[0] + 2 * np.pi * (1 - tol.zero)]  # one turn
            if len(z) == 2:
                d = abs(z[1] - z[0])
                mid = int(np.clip(np.searchsorted(x, (z[0] + z[1]) / 2), 0, len(x) - 1))
                fwd, back = (d, 2 * np.pi - d) if slope[mid] > 0 else (2 * np.pi - d, d)
                angles = (fwd, back)
                ratio = max(fwd, back) / min(fwd, back)
        out.append(Stroke(name, hi[1] - lo[1], lo[0], hi[0], ratio, angles))
    return out

