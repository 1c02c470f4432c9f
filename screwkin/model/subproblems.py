"""Paden-Kahan subproblems: the closed-form pieces of inverse kinematics in screw coordinates.

Rotations about axes through the origin (unit vectors w); R(w, t) turns by t about w (right hand).

* ``rotation_to(w, p, q)`` (subproblem 1): the angle t with R(w, t) p = q (p and q at the same
  height along w and distance from it);
* ``two_rotations(w1, w2, p, q)`` (subproblem 2): every (t1, t2) with R(w1, t1) R(w2, t2) p = q,
  axes not parallel: two, one (tangent) or none (the real ones; ``complex`` says when the two are
  complex);
* ``run_angles(axes, R)``: a rotation R written as R(w1, t1) ... R(wk, tk) about k = 1, 2 or 3 axes
  through one point (a revolute, a universal joint, a spherical joint or wrist written as revolutes):
  every real set, [] when R is not of that form.

Reference: Murray, Li, Sastry, A Mathematical Introduction to Robotic Manipulation (1994), 3.3.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..tolerances import DEFAULT

__all__ = ["rotation", "rotation_to", "two_rotations", "run_angles"]


def rotation(w: np.ndarray, t: float) -> np.ndarray:
    """R(w, t) (w a unit vector)."""
    return pin.exp3(np.asarray(w, float) * float(t))


def rotation_to(w: np.ndarray, p: np.ndarray, q: np.ndarray, tol: float = DEFAULT.closed_form) -> float | None:
    """The angle t in (-pi, pi] with R(w, t) p = q (subproblem 1), None when p lies on the axis
    (any angle: a continuum)."""
    w = np.asarray(w, float)
    pp = p - w * (w @ p)
    qq = q - w * (w @ q)
    if np.linalg.norm(pp) <= tol * max(np.linalg.norm(p), 1.0):
        return None
    return float(np.arctan2(w @ _cross(pp, qq), pp @ qq))


def two_rotations(w1: np.ndarray, w2: np.ndarray, p: np.ndarray, q: np.ndarray, tol: float = DEFAULT.closed_form) -> tuple:
    """(solutions, complex): every real (t1, t2) with R(w1, t1) R(w2, t2) p = q (subproblem 2:
    z = R(w2, t2) p = R(w1, -t1) q lies on both circles), and whether the pair is complex (the
    circles miss).  A solution whose intermediate point lies on an axis (a continuum) is left out."""
    w1, w2 = np.asarray(w1, float), np.asarray(w2, float)
    c = float(w1 @ w2)
    n = _cross(w1, w2)
    nn = float(n @ n)
    if nn < tol:
        return [], False
    a = (c * (w2 @ p) - w1 @ q) / (c * c - 1.0)
    b = (c * (w1 @ q) - w2 @ p) / (c * c - 1.0)
    g2 = (p @ p - a * a - b * b - 2 * a * b * c) / nn
    scale = max(float(p @ p), 1e-300)
    if g2 < -tol * scale:
        return [], True
    g = np.sqrt(max(g2, 0.0))
    out = []
    for s in ((1.0, -1.0) if g > np.sqrt(tol * scale) else (1.0,)):
        z = a * w1 + b * w2 + s * g * n
        t2 = rotation_to(w2, p, z)
        t1 = rotation_to(w1, z, q)
        if t1 is not None and t2 is not None:
            out.append((t1, t2))
    return out, False


def run_angles(axes: list, R: np.ndarray, tol: float = DEFAULT.closed_form) -> list:
    """Every real (t1, ..., tk) with R(w1, t1) ... R(wk, tk) = R for k = 1, 2, 3 unit axes (see the
    module); each set checked against R (a rotation not of that form gives []).  A continuum (a
    spherical wrist with its outer axes aligned) gives []: the caller says so."""
    axes = [np.asarray(w, float) for w in axes]
    R = np.asarray(R, float)
    k = len(axes)
    cands = []
    if k == 1:
        w = axes[0]
        p = _perpendicular(w)
        t = rotation_to(w, p, R @ p)
        cands = [] if t is None else [(t,)]
    elif k == 2:
        # the vector w2 is left alone by the last turn: R w2 = R(w1, t1) w2 fixes t1 ... unless w2
        # is turned by the second; the general way: R p = R(w1, t1) R(w2, t2) p for a p off both axes
        p = _perpendicular(axes[1]) + 0.5 * axes[1]
        sols, _ = two_rotations(axes[0], axes[1], p, R @ p, tol)
        cands = sols
    elif k == 3:
        w1, w2, w3 = axes
        sols, _ = two_rotations(w1, w2, w3, R @ w3, tol)
        for t1, t2 in sols:
            rest = (rotation(w1, t1) @ rotation(w2, t2)).T @ R
            p = _perpendicular(w3)
            t3 = rotation_to(w3, p, rest @ p)
            if t3 is not None:
                cands.append((t1, t2, t3))
    out = []
    for ts in cands:
        M = np.eye(3)
        for w, t in zip(axes, ts):
            M = M @ rotation(w, t)
        if np.max(np.abs(M - R)) <= 1e3 * tol + DEFAULT.closed_check:
            out.append(tuple(float(t) for t in ts))
    return out


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of two 3-vectors (np.cross costs ten times more at this size)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _perpendicular(w: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to w."""
    e = np.eye(3)[int(np.argmin(np.abs(w)))]
    v = _cross(w, e)
    return v / np.linalg.norm(v)
