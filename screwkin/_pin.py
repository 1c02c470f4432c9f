"""Pinocchio calls whose Python results change shape with the model.

Pinocchio's bindings return a frame Jacobian of a one-coordinate model as a
6-vector instead of a 6 x 1 matrix; these give (6, nv) always.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def frame_jacobian(model, data, frame: int, reference):
    """pinocchio.getFrameJacobian as a (6, nv) matrix (after computeJointJacobians).
    Pinocchio 4.1's getFrameJacobian crashes the process (signal 11) for a model without
    joint coordinates (nv = 0): its Jacobian is then the empty 6 x 0 matrix."""
    if model.nv == 0:
        return np.zeros((6, 0))
    return pin.getFrameJacobian(model, data, frame, reference).reshape(6, model.nv)


def compute_frame_jacobian(model, data, q, frame: int, reference):
    """pinocchio.computeFrameJacobian as a (6, nv) matrix."""
    return pin.computeFrameJacobian(model, data, q, frame, reference).reshape(6, model.nv)
