"""Inverse kinematics of a six-revolute serial arm whose last three axes meet at a point (a spherical
wrist), in closed form (Pieper 1968): the wrist centre's position gives the first three joints, the
orientation the last three, each with its branches.

Screw coordinates at the file's configuration: joint i turns about the world line (w_i, r_i); the
output frame is at M0.  For a target T, g = T M0^-1 = exp(xi_1 t1) ... exp(xi_6 t6) and the wrist centre
c0 (left alone by joints 4-6) goes to c = g c0 = exp(xi_1 t1) exp(xi_2 t2) exp(xi_3 t3) c0.  Joint 1 turns
about its axis, which keeps the height along w1 and the distance from a point r1 of the axis:

    w1 . (p - r1) = w1 . (c - r1),    |p - r1|^2 = |c - r1|^2,      p = exp(xi_2 t2) exp(xi_3 t3) c0.

Both are linear in (cos t2, sin t2): the 2-D vector z = Rot(t2) (x, y) ((x, y): the part of
exp(xi_3 t3) c0 - r2 across axis 2) satisfies M z = b(t3) with M constant, and |z|^2 = x^2 + y^2 leaves
one trigonometric polynomial of degree 2 in t3: a quartic in e^{i t3} (its roots on the unit circle are
the real t3; the others are complex solutions).  Then t2 from z, t1 by subproblem 1, and the wrist
R(w4, t4) R(w5, t5) R(w6, t6) = R by subproblem 2 and 1 (model.subproblems.run_angles): two sets.
At most 4 x 2 = 8 solutions (the PUMA's 8).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...model._pin import joint_axis
from ...model.geometry import lines_point
from ...model.state import KinematicState
from ...model.subproblems import rotation, rotation_to, run_angles
from ...tolerances import DEFAULT, Tolerances
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["Wrist", "wrist_arm", "pieper", "arm_positions"]

BOUND = 8  # real and complex solutions of a 6R arm with a spherical wrist (Pieper 1968)
TINY = 1e-12  # scale guard: the size of a matrix's rows, never zero


@dataclass(frozen=True)
class Wrist:
    """A 6R arm with a spherical wrist: joint ids from the ground, their world axes and points at the
    file's configuration, the wrist centre c0 and the output frame's placement M0 (a pinocchio.SE3)."""

    joints: tuple
    axes: np.ndarray
    points: np.ndarray
    centre: np.ndarray
    M0: object


def wrist_arm(mech: Mechanism, out_frame: int, placement: pin.SE3) -> Wrist | None:
    """The Wrist of the arm whose output frame is on the joint ``out_frame``'s parent chain at
    ``placement`` (pinocchio.SE3 in the last joint's frame), or None when the mechanism is not a serial
    6R arm whose last three axes meet (the model's joint screws at the file's configuration)."""
    model = mech.model
    if mech.cuts or mech.couplings or getattr(mech, "extra_rows", None):
        return None
    path, j = [], out_frame
    while j > 0:
        path.append(j)
        j = model.parents[j]
    path = path[::-1]
    moving = [j for j in range(1, model.njoints) if model.joints[j].nv > 0]
    if path != moving or len(path) != 6:
        return None
    if any(model.joints[j].nv != 1 or not model.joints[j].shortname().startswith("JointModelR") for j in path):
        return None
    state = KinematicState(mech, pin.neutral(model))
    placements = [state.joint_placement(j) for j in path]
    axes = np.array([M.rotation @ joint_axis(model.joints[j]) for M, j in zip(placements, path)])
    points = np.array([M.translation for M in placements])
    scale = max(mech.length, 1e-3)
    c0, off = lines_point(points[3:], axes[3:], TINY)
    if c0 is None or off > mech.tolerances.closed_form * scale:
        return None
    return Wrist(tuple(path), axes, points, c0, placements[-1] * placement)


def pieper(arm: Wrist, T: pin.SE3, tol: Tolerances = DEFAULT) -> tuple:
    """(sets, complex, why, stretched): every real joint solution (t1, ..., t6) placing the output frame at
    T (a pinocchio.SE3), how many of the 8 are complex, why the closed form does not answer ("" when it
    does: the wrist centre on axis 1 or 2 -- a continuum -- or a degenerate first pair of axes leave it
    to the general method), and for each set whether the wrist is stretched there (its first and last axes
    in line: joints 4 and 6 free with their sum fixed, a continuum, given with joint 4 at 0; it stands for
    two of the 8).  ``tol``: closed_form, closed_check, unit_circle, newton_step, equal and zero decide."""
    w, r = arm.axes, arm.points
    g = T * arm.M0.inverse()
    c = g.act(arm.centre)
    scale = max(float(np.abs(r).max()), float(np.abs(c).max()), 1e-3)
    positions, n_complex, why = arm_positions(w[:3], r[:3], arm.centre, c, tol, scale)
    if why == "the first two axes are one line":
        return [], 0, why
    sets, stretched = [], []
    for t1, t2, t3 in positions:
        R3 = rotation(w[0], t1) @ rotation(w[1], t2) @ rotation(w[2], t3)
        wrist = run_angles(list(w[3:]), R3.T @ g.rotation) or _stretched(w[3:], R3.T @ g.rotation, tol)
        for ts in wrist:
            sets.append(tuple(float(np.angle(np.exp(1j * t))) for t in (t1, t2, t3) + tuple(0.0 if t is None else t
                                                                                           for t in ts)))
            stretched.append(ts[0] is None)
        if not wrist:
            why = "the wrist cannot take the orientation (numerically degenerate)"
    return sets, n_complex * 2, ("" if sets else why), stretched


def arm_positions(w: np.ndarray, r: np.ndarray, centre: np.ndarray, c: np.ndarray, tol: Tolerances = DEFAULT,
                  scale: float | None = None) -> tuple:
    """(positions, complex, why): every real (t1, t2, t3) of three revolutes about the world lines (w[i], r[i])
    at their zero that takes the point ``centre`` to ``c`` (the position stage of :func:`pieper`: a quartic in
    e^{i t3}), how many of its roots are complex, and why some are left out ("" when none: a point on
    axis 1 or 2 -- a continuum --, or "the first two axes are one line").  ``scale``: the lengths the
    tolerances are relative to (default: the largest coordinate of r and c)."""
    r1, r2 = _closest(r[0], w[0], r[1], w[1], tol.closed_form)
    delta = r2 - r1
    e1 = np.cross(w[1], _perp(w[1]))
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(w[1], e1)
    M = np.array([[w[0] @ e1, w[0] @ e2], [delta @ e1, delta @ e2]])
    h1, h2 = float(w[0] @ (c - r1)), float((c - r1) @ (c - r1))
    if scale is None:
        scale = max(float(np.abs(r).max()), float(np.abs(c).max()), 1e-3)

    def parts(t3) -> tuple:
        q3 = r[2] + rotation(w[2], t3) @ (centre - r[2])
        v = q3 - r2  # from the point of axis 2 that delta reaches
        vpar = w[1] * (w[1] @ v)
        xy = np.array([(v - vpar) @ e1, (v - vpar) @ e2])
        b = np.array([h1 - w[0] @ delta - w[0] @ vpar, (h2 - delta @ delta - v @ v - 2 * delta @ vpar) / 2])
        return q3, xy, b

    det = float(np.linalg.det(M))
    norms = np.linalg.norm(M, axis=1)
    if abs(det) > tol.closed_form * max(norms.max(), TINY) * scale:
        Minv = np.linalg.inv(M)

        def F(t3):
            _, xy, b = parts(t3)
            z = Minv @ b
            return z @ z - xy @ xy
        degree = 2
    elif norms.max() > tol.closed_form * scale:  # one row a multiple of the other: one equation in t3 alone
        k = int(np.argmax(norms))
        lam = float(M[1 - k] @ M[k] / (M[k] @ M[k]))

        def F(t3):
            b = parts(t3)[2]
            return b[1 - k] - lam * b[k]
        degree = 1
    else:
        return [], 0, "the first two axes are one line"
    t3s, n_complex = _trig_roots(F, degree, tol)
    positions = []  # (t1, t2, t3)
    why = ""
    for t3 in t3s:
        q3, xy, b = parts(t3)
        rho2 = float(xy @ xy)
        if rho2 < (tol.closed_form * scale) ** 2:
            why = "the wrist centre lies on the second axis (a continuum)"
            continue
        if degree == 2:
            zs = [Minv @ b]
        else:
            m = M[k]
            foot = b[k] / (m @ m) * m
            s2 = rho2 - foot @ foot
            if s2 < -tol.closed_form * scale * scale:
                n_complex += 2
                continue
            across = np.array([-m[1], m[0]]) / np.linalg.norm(m) * np.sqrt(max(s2, 0.0))
            zs = [foot + across, foot - across]
        for z in zs:
            t2 = float(np.arctan2(z[1], z[0]) - np.arctan2(xy[1], xy[0]))
            p = r2 + rotation(w[1], t2) @ (q3 - r2)
            t1 = rotation_to(w[0], p - r1, c - r1)
            if t1 is None:
                why = "the wrist centre lies on the first axis (a continuum)"
                continue
            if np.linalg.norm(rotation(w[0], t1) @ (p - r1) - (c - r1)) > tol.closed_check * scale:
                continue
            positions.append((t1, t2, t3))
    return positions, n_complex, why


def _stretched(axes: list, R: np.ndarray, tol: Tolerances) -> list:
    """A stretched wrist (its last axis turned onto its first: joints 4 and 6 turn about one line, only their
    sum is fixed): [(None, t5, t6)] for each t5 that turns w6 onto +-w4, t6 with joint 4 at 0, else []."""
    w4, w5, w6 = axes
    if np.linalg.norm(np.cross(R @ w6, w4)) > tol.closed_check:
        return []
    out = []
    for sign in (1.0, -1.0):
        if abs(w5 @ w6 - sign * (w5 @ w4)) > tol.closed_form:
            continue
        t5 = rotation_to(w5, w6, sign * w4)
        if t5 is None or np.linalg.norm(rotation(w5, t5) @ w6 - sign * w4) > tol.closed_form:
            continue
        t6 = run_angles([w6], rotation(w5, t5).T @ R)
        if t6:
            out.append((None, t5, t6[0][0]))
    return out


def _trig_roots(F, degree: int, tol: Tolerances) -> tuple:
    """The real roots in (-pi, pi] of the trigonometric polynomial F of the given degree (from 8
    samples: the polynomial in e^{it} of degree 2 * degree, its roots on the unit circle, refined by
    Newton) and how many roots are complex."""
    n = 8
    ts = 2 * np.pi * np.arange(n) / n
    k = np.arange(n)  # the discrete Fourier transform of 8 samples (numpy.fft's first import: 2 ms)
    f = np.exp(-2j * np.pi * np.outer(k, k) / n) @ np.array([F(t) for t in ts], complex) / n
    coeffs = np.array([f[k % n] for k in range(-degree, degree + 1)])  # coefficient of e^{ikt}, k = -d..d
    big = np.abs(coeffs).max()
    if big == 0:
        return [], 0
    poly = coeffs[::-1]  # numpy: highest power first; z^d F(z) = sum_k c_k z^{k + d}
    while len(poly) > 1 and abs(poly[0]) < tol.zero * big:
        poly = poly[1:]
    roots = np.roots(poly) if len(poly) > 1 else np.zeros(0)
    real, n_complex = [], 0
    for z in roots:
        if abs(abs(z) - 1.0) < tol.unit_circle:
            t = float(np.angle(z))
            ks = np.arange(-degree, degree + 1)
            for _ in range(3):  # Newton on F itself, its derivative from the coefficients
                d = float(np.real(np.sum(1j * ks * coeffs * np.exp(1j * ks * t))))
                if d == 0:
                    break
                step = F(t) / d
                t -= step
                if abs(step) < tol.newton_step:
                    break
            if not any(abs(np.angle(np.exp(1j * (t - u)))) < tol.equal for u in real):
                real.append(float(np.angle(np.exp(1j * t))))
        else:
            n_complex += 1
    return real, n_complex


def _closest(p1: np.ndarray, w1: np.ndarray, p2: np.ndarray, w2: np.ndarray, parallel: float) -> tuple:
    """Points of the two lines nearest each other (the foot of p2 on line 1 where they are parallel: the
    sine of their angle below ``parallel``)."""
    n = np.cross(w1, w2)
    if n @ n < parallel ** 2:
        return p1 + w1 * (w1 @ (p2 - p1)), p2
    A = np.array([[w1 @ w1, -(w1 @ w2)], [w1 @ w2, -(w2 @ w2)]])
    s, t = np.linalg.solve(A, [w1 @ (p2 - p1), w2 @ (p2 - p1)])
    return p1 + s * w1, p2 + t * w2


def _perp(w: np.ndarray):
    e = np.eye(3)[int(np.argmin(np.abs(w)))]
    return e - w * (w @ e)
