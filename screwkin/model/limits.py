"""Which configurations lie within the joint limits the file gives (``<limit>``, MJCF ``range``): for
one configuration (the joints outside, by name) and for a stack (a mask).  An angle may sit in its
range modulo a turn.  The limits themselves are Mechanism.limited_coordinates.
"""

from __future__ import annotations

import numpy as np

from .leg_chains import respell
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["outside_limits", "within_limits", "spelled_within_limits"]


def outside_limits(mech: Mechanism, q: np.ndarray) -> tuple:
    """Joints whose value lies outside the position limits of the file."""
    names = mech.limited_coordinates()[0]
    if not names:
        return ()
    out = _outside(mech, np.asarray(q)[None])[0]
    return tuple(n for n, o in zip(names, out) if o)


def within_limits(mech: Mechanism, Q: np.ndarray):
    """(N,) True where every joint of the configurations Q (N, nq) is within its limits (an
    angle may sit in its range modulo a turn): outside_limits for a stack."""
    Q = np.atleast_2d(np.asarray(Q, float))
    if not mech.limited_coordinates()[0]:
        return np.ones(len(Q), bool)
    return ~_outside(mech, Q).any(axis=1)


def _outside(mech: Mechanism, Q: np.ndarray) -> np.ndarray:
    """(N, limited joints) True where a joint lies outside its limits."""
    _, idx, lo, hi, angle = mech.limited_coordinates()
    v = Q[:, idx]
    out = (v < lo) | (v > hi)
    if out.any():  # an angle may sit in the range modulo a turn
        shifted = v + 2 * np.pi * np.ceil((lo - v) / (2 * np.pi))
        out &= ~(angle & (lo <= shifted) & (shifted <= hi))
    return out


def spelled_within_limits(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """q, or where joints of q lie outside the file's limits, the angle set of the same pose within them
    where one exists: a universal joint's flipped set (a, b) -> (a + pi, pi - b) with its leg spun about
    its own line, a spherical joint's other Euler set (model.leg_chains.respell: the legs of a
    platform).  Every joint centre stays where it was; "within the limits" is a property of the pose,
    not of one of its spellings.  The one place solutions are written in their angle sets."""
    if not outside_limits(mech, q):
        return q
    q2 = respell(mech, q)
    return q2 if len(outside_limits(mech, q2)) < len(outside_limits(mech, q)) else q
