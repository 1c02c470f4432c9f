"""Where a view's camera stands: the picture's size, the field of view, the direction from the
mechanism to the camera (a flat mechanism seen mostly from its normal) and the framing that fits
the mechanism's points into the picture.
"""

from __future__ import annotations

import numpy as np

__all__ = ["BACKGROUND", "PICTURE", "FOV", "VIEW", "view_direction", "fit_camera"]

#: The page a picture is taken of: a neutral background (light grey, faintly graded), 900 x 700 pixels
BACKGROUND = {"top_color": [0.97, 0.97, 0.97], "bottom_color": [0.85, 0.85, 0.86]}
PICTURE = (900, 700)
FOV = 75.0  # meshcat's default camera: vertical field of view [deg]
VIEW = np.array([1.0, -1.0, 0.7])  # default direction from the mechanism to the camera (world, z up)


def view_direction(bounds) -> np.ndarray:
    """The direction (world, unit) from the mechanism to the camera: VIEW, or, for a flat mechanism
    (its box thinner than a fifth of its size along one axis), mostly along that axis, tilted a
    little so that the world's z stays the picture's up."""
    ext = np.ptp(np.asarray(bounds, float), axis=0)
    d = VIEW / np.linalg.norm(VIEW)
    k = int(np.argmin(ext))
    if ext[k] < 0.2 * ext.max():
        n = np.zeros(3)
        n[k] = 1.0 if d[k] >= 0 else -1.0
        side = d - (d @ n) * n
        d = n + 0.45 * side / np.linalg.norm(side)
    return d / np.linalg.norm(d)


def fit_camera(points, direction, fov_deg=FOV, aspect=PICTURE[0] / PICTURE[1], fill: float = 0.7) -> tuple:
    """Target and position (world) of a perspective camera looking along -direction, z up, at
    which the points fill the fraction ``fill`` of the frame along its tighter dimension: the
    target is moved (a few fixed-point steps) until the points' projected extent is centred, and
    the distance is the smallest for which every point lies within ``fill`` of the half-frame."""
    P = np.atleast_2d(np.asarray(points, float))
    u = np.asarray(direction, float) / np.linalg.norm(direction)
    up = np.array([0.0, 0.0, 1.0])
    right = np.cross(-u, up)
    if np.linalg.norm(right) < 1e-9:  # looking along z: any right will do
        right = np.array([1.0, 0.0, 0.0])
    right /= np.linalg.norm(right)
    cam_up = np.cross(right, -u)
    tan_v = np.tan(np.radians(fov_deg) / 2)
    tan_h = tan_v * aspect
    t = 0.5 * (P.min(axis=0) + P.max(axis=0))
    x, y = (P - t) @ right, (P - t) @ cam_up
    t = t + right * 0.5 * (x.max() + x.min()) + cam_up * 0.5 * (y.max() + y.min())  # centred, seen from afar

    def distance(t) -> tuple:
        """(x, y, z) of the points about target t, and the smallest distance that fits them."""
        x, y, z = (P - t) @ right, (P - t) @ cam_up, (P - t) @ u
        D = float(np.max(z + np.maximum(np.abs(x) / (fill * tan_h), np.abs(y) / (fill * tan_v))))
        return x, y, z, max(D, 1e-3, 1.05 * float(z.max()))

    for _ in range(20):  # then centred in perspective: the near side looks bigger
        x, y, z, D = distance(t)
        sx, sy = x / (D - z), y / (D - z)  # tangents of the angles off the axis
        mx, my = 0.5 * (sx.max() + sx.min()), 0.5 * (sy.max() + sy.min())
        if abs(mx) < 1e-4 * tan_h and abs(my) < 1e-4 * tan_v:
            break
        t = t + right * mx * D + cam_up * my * D
    D = distance(t)[3]
    return t, t + D * u
