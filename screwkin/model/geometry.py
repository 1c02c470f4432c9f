"""Plane and point geometry on plain arrays: angles between vectors and lines.

Every function takes ndarrays of shape (..., 2) or (..., 3) and broadcasts over the
leading axes; angles are in radians.  Nothing here knows of mechanisms.
"""

from __future__ import annotations

import numpy as np

__all__ = ["vector_angle", "line_angle"]


def _cross_norm(u, w):
    if u.shape[-1] == 2:
        return np.abs(u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0])
    return np.linalg.norm(np.cross(u, w), axis=-1)


def vector_angle(u, w):
    """The angle between vectors u and w, in [0, pi] [rad] (atan2 of |u x w| and u . w: exact
    near 0 and pi, where arccos of the cosine is not).

    >>> float(vector_angle([1.0, 0.0], [0.0, 2.0]))  # doctest: +ELLIPSIS
    1.5707963...
    """
    u, w = np.asarray(u, float), np.asarray(w, float)
    return np.arctan2(_cross_norm(u, w), np.sum(u * w, axis=-1))


def line_angle(u, w):
    """The angle between the lines along u and w, in [0, pi/2] [rad].

    >>> float(line_angle([1.0, 0.0], [-1.0, 1.0]))  # doctest: +ELLIPSIS
    0.785398...
    """
    u, w = np.asarray(u, float), np.asarray(w, float)
    return np.arctan2(_cross_norm(u, w), np.abs(np.sum(u * w, axis=-1)))
