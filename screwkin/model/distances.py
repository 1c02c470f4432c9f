"""Two rigid bodies joined by six distances (a Stewart-Gough platform), in the platform's own pose:
the system a coefficient-parameter homotopy tracks (model.homotopy.parameter), the same whether
the file writes the platform on a floating joint or carried by one leg in the tree.

Unknowns x = (t / L, q): the translation of the platform's frame and its quaternion (Pinocchio's
order x, y, z, w) on q.q = 1 (q and -q are one pose: a sign symmetry).  Rows, one per leg:

    G_k(x) = |t + Q(q) B_k - A_k|^2 / L^2            (A_k on the ground, B_k on the platform)

and the family G(x) = c: c_k = r_k^2 / L^2 the legs' squared lengths.  These are exactly the linear
offsets of model.homotopy.monodromy, so the family's generic solution set (monodromy at a random
complex c0, certified by the trace test or the published count) is carried to any leg lengths by
one straight segment in c (Morgan and Sommese 1989).  A step moves the platform in tangent
coordinates: a translation and a rotation vector d in the world (q -> exp(d / 2) q), as
model.kernel.algebraic moves a free flyer.

``chain_angles``: the joint angles of a leg that carries the platform (two revolutes meeting at the
ground point, inputs, three revolutes meeting at the platform point) that put the platform at a
given pose -- Paden-Kahan subproblems (model.subproblems), every real solution (up to four).
"""

from __future__ import annotations

import numpy as np

from .geometry import quaternion_matrix, quaternion_product
from .subproblems import rotation, run_angles, two_rotations

__all__ = ["SixDistances", "chain_angles", "rotated", "rotations"]

_SERIES = 1e-8


def rotations(X: np.ndarray) -> np.ndarray:
    """(P, 3, 3, 1) the rotations of the quaternions X[:, 3:7] (model.geometry.quaternion_matrix: the
    polynomial form, so the rows stay polynomial off the unit sphere), a trailing axis for the legs."""
    return quaternion_matrix(np.asarray(X)[:, 3:7])[..., None]


def rotated(R: np.ndarray, B: np.ndarray) -> np.ndarray:
    """(P, 3, 6): R B_k for the stack R of ``rotations`` and points B (6, 3), or one set per rotation
    (P, 6, 3)."""
    cols = [B[..., j] if B.ndim == 2 else B[:, None, :, j] for j in range(3)]
    return R[:, :, 0] * cols[0] + R[:, :, 1] * cols[1] + R[:, :, 2] * cols[2]


class SixDistances:
    """The six distance rows in (t / L, q) (see the module); A (6, 3) ground points in the world,
    B (6, 3) platform points in the platform's frame, both already divided by L."""

    n, width = 6, 7

    def __init__(self, A, B) -> None:
        # real for a platform's own geometry; complex for the general platform's generic parameters
        kind = complex if np.iscomplexobj(A) or np.iscomplexobj(B) else float
        self.A = np.asarray(A, kind)
        self.B = np.asarray(B, kind)
        self.closure = self  # the trace test draws its random points from ``closure``

    def _v(self, X: np.ndarray, A: np.ndarray | None = None, B: np.ndarray | None = None) -> tuple:
        """(v, RB): per leg the vector from A_k to the platform point, and R B_k; each (P, 3, 6)
        (component-wise arithmetic on the stack of rotations: these stacks are small, numpy's calls
        dominate).  ``A``, ``B``: other points than the system's, (6, 3) or one per point (P, 6, 3)."""
        R = rotations(X)
        A = self.A if A is None else A
        B = self.B if B is None else B
        RB = rotated(R, B)
        v = X[:, :3, None] + RB - np.swapaxes(A, -1, -2)
        return v, RB

    def equations(self, X: np.ndarray, jacobian: bool = True, A: np.ndarray | None = None,
                  B: np.ndarray | None = None) -> tuple:
        """G (P, 6) and its Jacobian in tangent coordinates (P, 6, 6); ``A``, ``B`` as ``_v``'s."""
        X = np.asarray(X, complex)
        v, RB = self._v(X, A, B)
        v0, v1, v2 = v[:, 0], v[:, 1], v[:, 2]
        G = v0 * v0 + v1 * v1 + v2 * v2
        if not jacobian:
            return G, None
        J = np.empty(G.shape + (6,), complex)  # (filled column by column: no stack of temporaries)
        np.multiply(v.transpose(0, 2, 1), 2, out=J[:, :, :3])
        R0, R1, R2 = RB[:, 0], RB[:, 1], RB[:, 2]
        J[:, :, 3] = 2 * (R1 * v2 - R2 * v1)
        J[:, :, 4] = 2 * (R2 * v0 - R0 * v2)
        J[:, :, 5] = 2 * (R0 * v1 - R1 * v0)
        return G, J

    def moved(self, X: np.ndarray, dA: np.ndarray, dB: np.ndarray, A: np.ndarray | None = None,
              B: np.ndarray | None = None) -> np.ndarray:
        """(P, 6) the rows' rate as the points move at rates dA, dB (6, 3) (from A, B as ``_v``'s):
        d|v_k|^2 = 2 v_k . (R dB_k - dA_k)."""
        X = np.asarray(X, complex)
        v, _ = self._v(X, A, B)
        w = rotated(rotations(X), np.asarray(dB, complex)) - np.swapaxes(np.asarray(dA, complex), -1, -2)
        return 2 * (v[:, 0] * w[:, 0] + v[:, 1] * w[:, 1] + v[:, 2] * w[:, 2])

    def offsets(self, X: np.ndarray):
        return self.equations(X, jacobian=False)[0]

    def residual(self, X: np.ndarray, c):
        """(P,) the largest |G(x) - c|."""
        return np.abs(self.offsets(X) - np.asarray(c)).max(axis=1)

    def retract(self, X: np.ndarray, dT):
        X = np.array(X, complex)
        X[:, :3] += dT[:, :3]
        d = dT[:, 3:] * 0.5
        z = np.einsum("pi,pi->p", d, d)
        r = np.sqrt(z)
        small = np.abs(z) < _SERIES
        if small.any():
            safe = np.where(small, 1.0, r)
            sinc = np.where(small, 1 - z / 6, np.sin(safe) / safe)
        else:  # (the same numbers, in fewer operations)
            sinc = np.sin(r) / r
        e = np.empty((len(X), 4), complex)  # exp(d / 2) as a quaternion, (x, y, z, w)
        e[:, :3] = d * sinc[:, None]
        e[:, 3] = np.cos(r)
        qn = quaternion_product(e, X[:, 3:])
        X[:, 3:] = qn / np.sqrt(np.einsum("pi,pi->p", qn, qn))[:, None]
        return X

    def tangent(self, X: np.ndarray) -> np.ndarray:
        P = len(X)
        T = np.zeros((P, 7, 6), complex)
        T[:, np.arange(3), np.arange(3)] = 1.0
        x, y, z, w = (0.5 * X[:, 3 + k] for k in range(4))
        # d/dd_k of exp(d / 2) q at d = 0: the Hamilton product (e_k / 2) q, (x, y, z, w) order
        for k, column in enumerate(((w, -z, y, -x), (z, w, -x, -y), (-y, x, w, -z))):
            for i, value in enumerate(column):
                T[:, 3 + i, 3 + k] = value
        return T

    def constraints(self, X: np.ndarray):
        q = np.asarray(X)[:, 3:]
        return (np.einsum("pi,pi->p", q, q) - 1.0)[:, None]

    def on_variety(self, X: np.ndarray, tol: float = 1e-10) -> np.ndarray:
        return np.abs(self.constraints(X)[:, 0]) <= tol * (1.0 + np.abs(X).max(axis=1)) ** 2

    def random_points(self, rng: np.random.Generator, P: int) -> np.ndarray:
        q = rng.normal(size=(P, 4)) + 1j * rng.normal(size=(P, 4)) * 0.5
        q = q / np.sqrt(np.einsum("pi,pi->p", q, q))[:, None]
        t = (rng.normal(size=(P, 3)) + 1j * rng.normal(size=(P, 3))) * 0.5
        return np.c_[t, q]


def chain_angles(head_axes: list, tail_axes: list, A, p0, R0: np.ndarray, p, R: np.ndarray) -> list:
    """Every real (theta_head (2,), theta_tail (3,)) of a leg (see the module): world axes at the
    angles' zero (head through the ground point A, tail through the platform point, which is at p0
    with the platform at rotation R0), the platform point wanted at p and the platform's rotation R
    (model.subproblems: subproblem 2 for the head, the tail's rotation written about its three axes)."""
    w1, w2 = head_axes
    out = []
    for t1, t2 in two_rotations(w1, w2, p0 - A, p - A)[0]:
        H = rotation(w1, t1) @ rotation(w2, t2)
        for ts in run_angles(tail_axes, H.T @ R @ R0.T):
            out.append((np.array([t1, t2]), np.array(ts)))
    return out
