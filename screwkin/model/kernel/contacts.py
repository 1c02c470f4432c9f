"""The rows of sliding contacts (model.cuts.ContactRow: a point or circle on a line, two circles
touching), evaluated in a Pinocchio Data that holds the placements: the row, its Jacobian, and its
acceleration term -- the higher pairs' part of model.kernel.closure's rows."""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from .._pin import frame_jacobian
from ..geometry import cross3

__all__ = ["contact_row", "contact_bias"]

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def contact_row(model: Any, data: Any, e: Any, jacobian: bool) -> tuple[float, np.ndarray | None]:
    """(value, Jacobian row (nv,) or None) of a ContactRow (model.cuts) at the placements in ``data``."""
    M1, M2 = data.oMf[e.frame1], data.oMf[e.frame2]
    J1: Any = frame_jacobian(model, data, e.frame1, LWA) if jacobian else None
    J2: Any = frame_jacobian(model, data, e.frame2, LWA) if jacobian else None
    if "line" in (e.shape1, e.shape2):
        # s = (o_a - o_b) . m_b, the line on frame b (its normal m_b turns with it), the other at a
        on2 = e.shape2 == "line"
        Ma, Mb = (M1, M2) if on2 else (M2, M1)
        Ja, Jb = (J1, J2) if on2 else (J2, J1)
        m = Mb.rotation @ np.asarray(e.normal)
        delta = Ma.translation - Mb.translation
        s = float(delta @ m)
        point = (e.shape1 if on2 else e.shape2) == "point"
        sign = 1.0 if point or s >= 0 else -1.0
        value = sign * s - (0.0 if point else e.target())
        if not jacobian:
            return value, None
        return value, sign * (m @ (Ja[:3] - Jb[:3]) + cross3(m, delta) @ Jb[3:])
    delta = M2.translation - M1.translation
    dist = float(np.sqrt(delta @ delta))
    value = dist - e.target()
    if not jacobian:
        return value, None
    return value, (delta / max(dist, 1e-300)) @ (J2[:3] - J1[:3])

def contact_bias(model: Any, data: Any, e: Any) -> float:
    """d2/dt2 of a ContactRow along the motion in ``data`` (velocities, classical accelerations)."""
    M = (data.oMf[e.frame1], data.oMf[e.frame2])
    V = [pin.getFrameVelocity(model, data, f, LWA) for f in (e.frame1, e.frame2)]
    A = [pin.getFrameClassicalAcceleration(model, data, f, LWA) for f in (e.frame1, e.frame2)]
    if "line" in (e.shape1, e.shape2):
        a, b = (0, 1) if e.shape2 == "line" else (1, 0)
        m = M[b].rotation @ np.asarray(e.normal)
        w, al = V[b].angular, A[b].angular
        delta = M[a].translation - M[b].translation
        dd = V[a].linear - V[b].linear
        ddd = A[a].linear - A[b].linear
        md = cross3(w, m)
        mdd = cross3(al, m) + cross3(w, md)
        s2 = ddd @ m + 2 * dd @ md + delta @ mdd
        point = (e.shape1 if b == 1 else e.shape2) == "point"
        return s2 if point or delta @ m >= 0 else -s2
    delta = M[1].translation - M[0].translation
    dd = V[1].linear - V[0].linear
    ddd = A[1].linear - A[0].linear
    d = float(np.sqrt(delta @ delta))
    return (ddd @ delta + dd @ dd) / d - (delta @ dd) ** 2 / d**3
