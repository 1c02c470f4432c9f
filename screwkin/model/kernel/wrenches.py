"""What each minimal closure row exerts: the constraint wrenches of screw theory, row by row, on the
two bodies a cut joint (or a contact) joins -- what statics and the redundancy analysis read."""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from ..cuts import CouplingRow
from ..geometry import cross3

__all__ = ["row_wrenches"]


def row_wrenches(model: Any, data: Any, cuts: list, plans: list, extra: list, q: np.ndarray
                ) -> list[tuple[Any, Any, Any, Any]]:
    """What a unit force in each minimal row exerts, row by row: (frame a, wrench on a's body,
    frame b, wrench on b's body), each wrench (force, moment) at the frame's origin in world
    axes, so that the row's Jacobian is w_a^T J_a + w_b^T J_b (J: LOCAL_WORLD_ALIGNED frame
    Jacobians) -- the constraint wrenches of screw theory; or (None, coupling row) for a
    coupling of coordinates (a force between joints inside a higher pair's virtual chain).  model,
    data: Pinocchio's (placed at q here); cuts, plans, extra: a ClosureSystem's cut joints, their row
    plans and higher-pair rows."""
    pin.framesForwardKinematics(model, data, q)
    out: list[tuple[Any, Any, Any, Any]] = []
    zero = np.zeros(3)

    def pair(f1: Any, w1: Any, f2: Any, w2: Any) -> None:
        out.append((f1, np.asarray(w1, float), f2, np.asarray(w2, float)))

    for cut, (P, pairs, _, rotation) in zip(cuts, plans):
        M1, M2 = data.oMf[cut.frame1], data.oMf[cut.frame2]
        R1, R2 = M1.rotation, M2.rotation
        d = M2.translation - M1.translation
        for e in P @ R1.T:  # e . d, e fixed in F1: d(e . d) = e . (v2 - v1) + (e x d) . w1
            pair(cut.frame1, np.r_[-e, cross3(e, d)], cut.frame2, np.r_[e, zero])
        if rotation:  # log3(R1^T R2): Jlog3 R2^T (w2 - w1)
            C = pin.Jlog3(R1.T @ R2) @ R2.T
            for c in C:
                pair(cut.frame1, np.r_[zero, -c], cut.frame2, np.r_[zero, c])
            continue
        for u, w in pairs:  # u . w: (w x u) . (w2 - w1)
            c = cross3(R2 @ w, R1 @ u)
            pair(cut.frame1, np.r_[zero, -c], cut.frame2, np.r_[zero, c])
    for e in extra:
        if isinstance(e, CouplingRow):
            out.append((None, e, None, None))
            continue
        M1, M2 = data.oMf[e.frame1], data.oMf[e.frame2]
        if "line" in (e.shape1, e.shape2):
            on2 = e.shape2 == "line"
            (fa, Ma), (fb, Mb) = ((e.frame1, M1), (e.frame2, M2)) if on2 else ((e.frame2, M2), (e.frame1, M1))
            m = Mb.rotation @ np.asarray(e.normal)
            delta = Ma.translation - Mb.translation
            point = (e.shape1 if on2 else e.shape2) == "point"
            sign = 1.0 if point or delta @ m >= 0 else -1.0
            pair(fa, sign * np.r_[m, zero], fb, sign * np.r_[-m, cross3(m, delta)])
            continue
        delta = M2.translation - M1.translation
        u = delta / max(float(np.linalg.norm(delta)), 1e-300)
        pair(e.frame1, np.r_[-u, zero], e.frame2, np.r_[u, zero])
    return out
