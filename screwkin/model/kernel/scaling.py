"""The one dimensionless scaling of the closure rows' and the output's Jacobians.

A Jacobian mixes units: a row that is a length (a position row of a cut joint, a coupling of a
rolling or screw pair) is in metres, the others are angles or alignments; a sliding joint's column
moves in metres, a turning joint's in radians.  With the mechanism's characteristic length L
(model.lengths) the matrix becomes dimensionless: the length rows divided by L, the sliding
columns multiplied by L.  Ranks, condition numbers, null spaces and singular values taken on the
scaled matrix do not depend on the unit of length (``Tolerances`` compares them with pure numbers).

Written once here; every analysis that needs a dimensionless Jacobian (the singularity measures,
the local analysis, the redundancy, the workspace grids, the loci) calls it, and the kernels'
contract (model.kernel.contract.ClosureKernel.dimensionless) hands it each backend's row mask.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["dimensionless", "dimensionless_rows", "dimensionless_twists", "sliding_columns"]

Array = NDArray[Any]


def dimensionless(K: Array, length_rows: Array | slice, sliding: Array, length: float) -> Array:
    """A dimensionless copy of the Jacobian K (..., m, nv): the rows ``length_rows`` (a mask (m,) or
    indices or a slice over the second-last axis: rows in metres) divided by ``length`` [m], the
    columns ``sliding`` (velocity indices of prismatic joints) multiplied by it.  Any leading axes
    (a stack of configurations) are kept."""
    K = np.array(K, float)
    K[..., length_rows, :] /= length
    K[..., sliding] *= length
    return K


def dimensionless_rows(r: Array, length_rows: Array | slice, length: float) -> Array:
    """A dimensionless copy of the residual rows r (..., m): the rows ``length_rows`` divided by
    ``length`` (the same rows as ``dimensionless`` divides in K)."""
    r = np.array(r, float)
    r[..., length_rows] /= length
    return r


def dimensionless_twists(J: Array, sliding: Array, length: float) -> Array:
    """A dimensionless copy of a frame Jacobian J (..., 6, nv) in (linear, angular) order: its
    linear rows (the first three) divided by ``length``, the sliding columns multiplied by it
    (``dimensionless`` with the first three rows as the length rows)."""
    return dimensionless(J, slice(0, 3), sliding, length)


def sliding_columns(model: Any) -> Array:
    """Mask (nv,) of a Pinocchio model's velocity columns that are lengths [m]: prismatic joints, the
    translations of planar, translation and free-flyer joints; the others are angles."""
    mask = np.zeros(model.nv, bool)
    for j in range(1, model.njoints):
        short, iv, nv = model.joints[j].shortname(), model.idx_vs[j], model.nvs[j]
        if nv <= 0:
            continue
        if "JointModelP" in short and "Planar" not in short:
            mask[iv:iv + nv] = True
        elif short in ("JointModelPlanar",):
            mask[iv:iv + 2] = True
        elif short in ("JointModelTranslation", "JointModelFreeFlyer"):
            mask[iv:iv + 3] = True
    return mask
