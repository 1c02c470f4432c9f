"""Numerical rank and null spaces with the tolerances of screwkin.Tolerances."""

from __future__ import annotations

import numpy as np
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.tolerances import Tolerances

__all__ = ["rank", "null_space", "singular_values", "complement"]


def _square(A: np.ndarray):
    """A matrix with the singular values and right singular vectors of A: A itself, or for a
    tall A (m > 2n rows) the triangular factor R of its QR factorization (A^T A = R^T R),
    several times cheaper to decompose than A (the idle-motion rows of a 500-joint chain:
    6000 x 500)."""
    if A.shape[0] > 2 * A.shape[1] and A.shape[1] > 0:
        return np.linalg.qr(A, mode="r")
    return A


def singular_values(A: np.ndarray) -> np.ndarray:
    """Singular values of A, largest first (none for an empty matrix)."""
    A = np.asarray(A, float)
    if A.size == 0:
        return np.zeros(0)
    return np.linalg.svd(_square(A), compute_uv=False)


def rank(A: np.ndarray, tol: Tolerances) -> int:
    """Numerical rank: singular values above ``tol.rank_rtol * sigma_max`` and ``tol.rank_atol``."""
    s = singular_values(A)
    if s.size == 0 or s[0] <= tol.rank_atol:
        return 0
    return int(np.sum(s > max(tol.rank_rtol * s[0], tol.rank_atol)))


def null_space(A: np.ndarray, tol: Tolerances, n: int | None = None) -> np.ndarray:
    """Orthonormal basis (columns) of the null space of A (A has n columns)."""
    A = np.asarray(A, float)
    n = A.shape[1] if n is None else n
    if A.size == 0:
        return np.eye(n)
    # a tall matrix's thin SVD has every right singular vector; the full one would also build an
    # m x m U (seconds for the thousands of geometry rows of a 100-link robot)
    A = _square(A)
    _, s, vt = np.linalg.svd(A, full_matrices=A.shape[0] < A.shape[1])
    if s.size == 0 or s[0] <= tol.rank_atol:
        return np.eye(n)
    r = int(np.sum(s > max(tol.rank_rtol * s[0], tol.rank_atol)))
    return vt[r:].T.copy()


def complement(n: int, idx) -> np.ndarray:
    """The indices 0 .. n-1 not in ``idx``, ascending: numpy.setdiff1d(numpy.arange(n), idx), without
    numpy.unique (its first call imports numpy.ma: 15 ms of a command's time)."""
    keep = np.ones(n, bool)
    keep[np.asarray(idx, int).ravel()] = False
    return np.flatnonzero(keep)
