"""Pinocchio calls whose Python results change shape with the model.

Pinocchio's bindings return a frame Jacobian of a one-coordinate model as a
6-vector instead of a 6 x 1 matrix; these give (6, nv) always.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def frame_jacobian(model: pin.Model, data: pin.Data, frame: int, reference: pin.ReferenceFrame, placement=None) -> np.ndarray:
    """pinocchio.getFrameJacobian as a (6, nv) matrix (after computeJointJacobians); with ``placement``
    (a pinocchio.SE3) ``frame`` is a joint id and the frame the one at ``placement`` in that joint.
    Pinocchio 4.1's getFrameJacobian crashes the process (signal 11) for a model without
    joint coordinates (nv = 0): its Jacobian is then the empty 6 x 0 matrix."""
    if model.nv == 0:
        return np.zeros((6, 0))
    where = (frame,) if placement is None else (frame, placement)
    return pin.getFrameJacobian(model, data, *where, reference).reshape(6, model.nv)


def compute_frame_jacobian(model: pin.Model, data: pin.Data, q: np.ndarray, frame: int, reference: pin.ReferenceFrame) -> np.ndarray:
    """pinocchio.computeFrameJacobian as a (6, nv) matrix."""
    return pin.computeFrameJacobian(model, data, q, frame, reference).reshape(6, model.nv)


#: Frame types in the order a bare name is taken when several frames share it (a URDF
#: may name a joint like a link: Pinocchio then has a JOINT and a BODY frame of that name).
FRAME_PREFERENCE = (pin.FrameType.BODY, pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT, pin.FrameType.OP_FRAME,
                    pin.FrameType.SENSOR)


def frame_id(model: pin.Model, name: str, prefer: tuple=FRAME_PREFERENCE):
    """Id of the frame named ``name`` (None when there is none).  When several frames
    share the name, the first of the types in ``prefer`` wins -- by default the BODY
    frame (the link), where ``model.getFrameId(name)`` raises "Several frames match"."""
    matches = [k for k, f in enumerate(model.frames) if f.name == name]
    if not matches:
        return None
    if len(matches) > 1:
        for t in prefer:
            for k in matches:
                if model.frames[k].type == t:
                    return k
    return matches[0]


def joint_axis(joint: pin.JointModel) -> np.ndarray:
    """The axis of a one-coordinate revolute or prismatic joint model in its own frame: x, y or z for
    the aligned models (RX, RUBZ, PY ...), the model's own axis for the unaligned ones."""
    short = joint.shortname()
    for tail, axis in (("X", (1.0, 0.0, 0.0)), ("Y", (0.0, 1.0, 0.0)), ("Z", (0.0, 0.0, 1.0))):
        if short.endswith(("R" + tail, "RUB" + tail, "P" + tail)):
            return np.array(axis)
    return np.asarray(joint.extract().axis, float)
