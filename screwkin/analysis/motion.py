"""Absolute motion in the user's quantities: links, named points and loop-joint coordinates.

Read from :class:`~screwkin.model.state.KinematicState` -- one state per configuration -- for
one solution (``solve``) or every step of a motion (``sweep``):

* ``link_motions(state, angles, normal)``: each moving link's frame origin (position, velocity,
  acceleration), its angular velocity and acceleration; planar mechanisms: the vector-loop angle
  and omega, alpha as numbers about the plane's normal;
* ``point_motions(state, points)``: the points people name, ``NAME=LINK:x,y,z`` (coordinates in the
  link's frame): position, velocity, acceleration in world axes;
* ``motion_along(mech, Q, V, A, points, angles, normal)``: the same for every step of a sweep,
  as arrays, with the loop joints' coordinates.

Units: m, rad, s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import UsageError
from ..model.state import KinematicState, loop_coordinate_cuts

__all__ = ["Point", "link_motions", "point_motions", "MotionAlong", "motion_along", "moving_links", "Stroke",
           "strokes"]


@dataclass(frozen=True)
class Point:
    """A point fixed on a link: ``local`` [m] in the link's frame."""

    name: str
    link: str
    local: tuple


def moving_links(mech) -> tuple:
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


def link_motions(state, angles=None, normal=None) -> dict:
    """Every moving link's absolute motion at a state: ``position`` (and, with rates, ``velocity``,
    ``acceleration``) of its frame origin [m, m/s, m/s^2], ``omega`` and ``alpha`` [rad/s, rad/s^2];
    planar mechanisms (``normal`` given): ``angle`` [rad] from ``angles`` (the vector-loop angles of
    LinkAngles) and omega, alpha as numbers about the plane's normal, else 3-vectors (world axes)."""
    out = {}
    for link in moving_links(state.mech):
        d = state.link_motion(link)
        if normal is not None:
            if angles is not None and link in angles:
                d["angle"] = angles[link]
            if "omega" in d:
                d["omega"], d["alpha"] = float(d["omega"] @ normal), float(d["alpha"] @ normal)
        out[link] = d
    return out


def point_motions(state, points) -> dict:
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


def motion_along(mech, Q, V, A, points=(), angles=None, normal=None) -> MotionAlong:
    """The absolute motion at each configuration Q[k] with rates V[k] and accelerations A[k];
    ``angles``: a callable q -> link angles (LinkAngles) for planar mechanisms, with ``normal``."""
    cuts = loop_coordinate_cuts(mech)
    steps = []
    for q, v, a in zip(Q, V, A):
        st = KinematicState(mech, q, v, a)
        steps.append((st, link_motions(st, angles(q) if angles is not None else None, normal),
                      point_motions(st, points)))

    def stack(values):
        return np.array(values, float)

    loops = {c.name: stack([s.loop_value(c) for s, _, _ in steps]) for c in cuts}
    loop_rates = {c.name: stack([s.loop_rate(c) for s, _, _ in steps]) for c in cuts}
    loop_accs = {c.name: stack([s.loop_acceleration(c) for s, _, _ in steps]) for c in cuts}
    links = {}
    for link in (steps[0][1] if steps else {}):
        links[link] = {key: stack([m[link][key] for _, m, _ in steps]) for key in steps[0][1][link]}
    pts = {}
    for p in points:
        first = steps[0][2][p.name] if steps else {}
        pts[p.name] = {"link": p.link, "local": list(p.local),
                       **{key: stack([m[p.name][key] for _, _, m in steps]) for key in first
                          if key not in ("link", "local")}}
    return MotionAlong(loops, loop_rates, loop_accs, links, pts,
                       tuple(c.name for c in cuts if c.type != "prismatic"))


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


def _extrema(x, p, dp, tol):
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


def strokes(res, motion, mech) -> list:
    """A Stroke for each slider coordinate (prismatic tree joint or prismatic loop joint) of a sweep
    ``res`` (analysis.sweep.SweepResult) with its MotionAlong."""
    series = []
    for k, name in enumerate(res.names):
        c = next((c for c in mech.coordinates if c.joint == name), None)
        if c is not None and c.nv == 1 and mech.translational[c.idx_v]:
            series.append((name, res.joints[:, k], res.rates[:, k]))
    for name, v in motion.loop_joints.items():
        if name not in motion.angular_loop:
            series.append((name, v, motion.loop_rates[name]))
    x = np.asarray(res.values, float)
    tol = mech.tolerances
    turned = res.unit == "rad" and res.stopped_at is None and abs(x[-1] - x[0]) >= 2 * np.pi * (1 - tol.equal)
    out = []
    for name, values, rates in series:
        values, slope = np.asarray(values, float), np.asarray(rates, float) / (res.rate or 1.0)
        ends = [(float(x[0]), float(values[0])), (float(x[-1]), float(values[-1]))] + _extrema(x, values, slope, tol)
        lo, hi = min(ends, key=lambda e: e[1]), max(ends, key=lambda e: e[1])
        ratio = angles = None
        if turned:
            z = [a for a, _ in _extrema(x, values, slope, tol) if a < x[0] + 2 * np.pi * (1 - tol.zero)]  # one turn
            if len(z) == 2:
                d = abs(z[1] - z[0])
                mid = int(np.clip(np.searchsorted(x, (z[0] + z[1]) / 2), 0, len(x) - 1))
                fwd, back = (d, 2 * np.pi - d) if slope[mid] > 0 else (2 * np.pi - d, d)
                angles = (fwd, back)
                ratio = max(fwd, back) / min(fwd, back)
        out.append(Stroke(name, hi[1] - lo[1], lo[0], hi[0], ratio, angles))
    return out

