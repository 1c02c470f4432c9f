"""Measures over many configurations at once: arrays of q in, arrays out.

Pinocchio computes each Jacobian (about a microsecond from Python); the linear
algebra on the whole stack is one numpy call, not one Python call per number.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

__all__ = ["frame_jacobians", "singular_values", "smallest_singular_values"]


def frame_jacobians(model, frame_id: int, Q, reference=pin.ReferenceFrame.WORLD, data=None) -> np.ndarray:
    """(N, 6, nv) frame Jacobians for the configurations in the rows of Q (N, nq)."""
    Q = np.atleast_2d(np.asarray(Q, float))
    if Q.shape[1] != model.nq:
        raise ValueError(f"expected configurations of shape (..., {model.nq}), got {Q.shape}")
    data = data or model.createData()
    out = np.empty((len(Q), 6, model.nv))
    for k, q in enumerate(Q):
        out[k] = pin.computeFrameJacobian(model, data, q, frame_id, reference)
    return out


def singular_values(J) -> np.ndarray:
    """(N, min(m, n)) singular values of a stack of matrices (N, m, n), largest first."""
    return np.linalg.svd(np.asarray(J), compute_uv=False)


def smallest_singular_values(J, scale_translation: float = 1.0) -> np.ndarray:
    """(N,) smallest singular value of each Jacobian in the stack, translations divided by a
    characteristic length ``scale_translation`` [m] so that the values are dimensionless."""
    J = np.array(J, float)
    J[:, :3, :] /= scale_translation
    return singular_values(J)[:, -1]
