"""Plane and point geometry on plain arrays: bases of a plane, circle and line
intersections, angles between vectors and lines.

Functions take ndarrays of points or vectors of shape (..., 2) or (..., 3) and broadcast
over the leading axes where they say so; lengths in the caller's unit (m), angles in rad.
Nothing here knows of mechanisms.
"""

from __future__ import annotations

import numpy as np

__all__ = ["perpendicular_basis", "plane_basis", "cross2", "cross_last", "circle_circle", "circle_intersections", "line_foot",
           "line_circle", "vector_angle", "line_angle", "cross3", "skew", "skews", "skews_batch", "wrap_angle",
           "quaternion_matrix", "quaternion_product", "stack_mm", "stack_mv", "stack_cross",
           "nearest_turn", "lines_point"]

#: Division guard: the distance between two circles' centres is taken at least this [m].
TINY = 1e-300  # division guard
#: A normal's projection of a world axis shorter than this is not used as the plane's first axis [-].
AXIS_IN_PLANE = 1e-6


def perpendicular_basis(a: np.ndarray) -> tuple:
    """Two unit vectors (b1, b2) completing the unit vector ``a`` to a right-handed basis
    (b1, b2, a): b1 = a x h / |a x h| with h the world x axis (y when a is near x), b2 = a x b1.

    >>> [v.tolist() for v in perpendicular_basis([0.0, 0.0, 1.0])]
    [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]
    """
    a = np.asarray(a, float)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    b1 = np.cross(a, helper)
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(a, b1)
    return b1, b2


def plane_basis(normal: np.ndarray | list | tuple) -> tuple:
    """(e1, e2, n): e1 the world x axis projected into the plane (the world y axis when x is
    normal to it), e2 = n x e1, so angles from e1 are counterclockwise seen from +n.

    >>> [v.tolist() for v in plane_basis([0.0, 0.0, 2.0])]
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    for axis in np.eye(3):
        e1 = axis - (axis @ n) * n
        if np.linalg.norm(e1) > AXIS_IN_PLANE:
            e1 /= np.linalg.norm(e1)
            return e1, np.cross(n, e1), n
    raise ValueError("degenerate normal")  # pragma: no cover


def cross2(u: np.ndarray | list, w: np.ndarray | list) -> float:
    """The z component of u x w for plane vectors (..., 2): > 0 when w turns counterclockwise from u."""
    u, w = np.asarray(u, float), np.asarray(w, float)
    return u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0]


def circle_circle(p: np.ndarray | list, r: float, c: np.ndarray | list | tuple, s: float, side: np.ndarray | float) -> tuple:
    """The intersection of the circle (centre p, radius r) and the circle (c, s) in the plane
    on the ``side`` (+1: left of the line p -> c, -1: right), broadcast over points (..., 2):
    (X, h2), h2 the squared distance of X from the line p -> c; h2 < 0 where the circles do
    not meet (X is then the point of that line the intersections would straddle).

    >>> X, h2 = circle_circle([0.0, 0.0], 5.0, [8.0, 0.0], 5.0, 1)
    >>> X.tolist(), float(h2)
    ([4.0, 3.0], 9.0)
    """
    p, c = np.asarray(p, float), np.asarray(c, float)
    w = c - p
    d = np.hypot(w[..., 0], w[..., 1])
    d = np.where(d < TINY, TINY, d)
    u = w / d[..., None]
    n = np.stack([-u[..., 1], u[..., 0]], axis=-1)
    along = (r * r - s * s + d * d) / (2 * d)
    h2 = r * r - along * along
    h = np.sqrt(np.maximum(h2, 0.0))
    return p + along[..., None] * u + (side * h)[..., None] * n, h2


def circle_intersections(p: np.ndarray | list, r: float, c: np.ndarray | list, s: float, slack: float = 0.0, concentric: float = 0.0) -> list:
    """The points where the circles (p, r) and (c, s) in the plane meet: [left of p -> c,
    right], the same point twice where they touch, [] where they do not meet (the centres
    closer than ``concentric``, or farther than r + s + slack, or nearer than |r - s| - slack).

    >>> [X.tolist() for X in circle_intersections([0.0, 0.0], 5.0, [8.0, 0.0], 5.0)]
    [[4.0, 3.0], [4.0, -3.0]]
    """
    p, c = np.asarray(p, float), np.asarray(c, float)
    d = np.linalg.norm(c - p)
    if d < concentric or d > r + s + slack or d < abs(r - s) - slack:
        return []
    return [circle_circle(p, r, c, s, side)[0] for side in (1.0, -1.0)]


def line_foot(x: np.ndarray | list, point: np.ndarray | list, direction: np.ndarray | list) -> np.ndarray:
    """The point of the line through ``point`` along the unit vector ``direction`` nearest x.

    >>> line_foot([3.0, 4.0], [0.0, 1.0], [1.0, 0.0]).tolist()
    [3.0, 1.0]
    """
    x, point, direction = (np.asarray(v, float) for v in (x, point, direction))
    return point + ((x - point) @ direction) * direction


def line_circle(point: np.ndarray | list, direction: np.ndarray, centre: np.ndarray | list, radius: float) -> list:
    """The points where the line through ``point`` along the unit vector ``direction`` meets the
    circle (sphere) (centre, radius): [behind, ahead] along ``direction`` (the foot twice where it
    touches), [] where it passes farther than the radius.

    >>> [X.tolist() for X in line_circle([0.0, 3.0], [1.0, 0.0], [0.0, 0.0], 5.0)]
    [[-4.0, 3.0], [4.0, 3.0]]
    """
    direction = np.asarray(direction, float)
    foot = line_foot(centre, point, direction)
    h2 = radius * radius - float(np.sum((foot - np.asarray(centre, float)) ** 2))
    if h2 < 0:
        return []
    h = np.sqrt(h2)
    return [foot - h * direction, foot + h * direction]


def lines_point(points: list | np.ndarray, directions: np.ndarray | list, tol: float) -> tuple:
    """(c, d): the point c nearest, in least squares, the 3-D lines through ``points`` along
    ``directions`` (sum (I - u u^T) (c - p) = 0, u the unit directions), and the largest distance d
    of a line from it; (None, inf) where the lines are parallel (that system's rank, by ``tol``,
    below 3).

    >>> c, d = lines_point([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [[1.0, 0.0, 0.0], [0.0, 1.0, 1.0]], 1e-12)
    >>> [round(float(x), 12) + 0.0 for x in c], round(float(d), 12)
    ([1.0, 0.0, 0.0], 0.0)
    """
    A, b, projections = np.zeros((3, 3)), np.zeros(3), []
    for p, d in zip(points, directions):
        u = np.asarray(d, float) / np.linalg.norm(d)
        P = np.eye(3) - np.outer(u, u)
        projections.append((P, np.asarray(p, float)))
        A += P
        b += P @ np.asarray(p, float)
    if np.linalg.matrix_rank(A, tol=tol) < 3:  # the lines are parallel: no common point
        return None, np.inf
    c = np.linalg.solve(A, b)
    return c, max(np.linalg.norm(P @ (c - p)) for P, p in projections)


def _cross_norm(u: np.ndarray, w: np.ndarray) -> np.ndarray | float:
    if u.shape[-1] == 2:
        return np.abs(cross2(u, w))
    return np.linalg.norm(np.cross(u, w), axis=-1)


def wrap_angle(a: np.ndarray | float, upper: bool = False) -> np.ndarray | float:
    """An angle [rad] brought into [-pi, pi), or into (-pi, pi] with ``upper`` (where atan2 and
    Pinocchio's continuous joints put it); a float for a number, an array for an array.

    >>> wrap_angle(3 * np.pi / 2) == -np.pi / 2, wrap_angle(np.pi), wrap_angle(-np.pi, upper=True)
    (True, -3.141592653589793, 3.141592653589793)
    """
    a = np.asarray(a, float)
    w = np.pi - np.mod(np.pi - a, 2 * np.pi) if upper else np.mod(a + np.pi, 2 * np.pi) - np.pi
    return float(w) if w.ndim == 0 else w


def nearest_turn(angle: np.ndarray | float, ref: np.ndarray | float) -> np.ndarray | float:
    """``angle`` [rad] moved by the whole turns that bring it nearest ``ref`` (within half a turn;
    exactly half a turn away, the even number of turns), broadcast; a float for numbers.

    >>> nearest_turn(0.5, 13.0) == 0.5 + 4 * np.pi
    True
    """
    a = np.asarray(angle, float)
    w = a - 2 * np.pi * np.round((a - np.asarray(ref, float)) / (2 * np.pi))
    return float(w) if w.ndim == 0 else w


def vector_angle(u: np.ndarray | tuple, w: np.ndarray | tuple) -> float:
    """The angle between vectors u and w, in [0, pi] [rad] (atan2 of |u x w| and u . w: exact
    near 0 and pi, where arccos of the cosine is not).

    >>> float(vector_angle([1.0, 0.0], [0.0, 2.0]))  # doctest: +ELLIPSIS
    1.5707963...
    """
    u, w = np.asarray(u, float), np.asarray(w, float)
    return np.arctan2(_cross_norm(u, w), np.sum(u * w, axis=-1))


def line_angle(u: np.ndarray | tuple, w: np.ndarray) -> np.ndarray | float:
    """The angle between the lines along u and w, in [0, pi/2] [rad].

    >>> float(line_angle([1.0, 0.0], [-1.0, 1.0]))  # doctest: +ELLIPSIS
    0.785398...
    """
    u, w = np.asarray(u, float), np.asarray(w, float)
    return np.arctan2(_cross_norm(u, w), np.abs(np.sum(u * w, axis=-1)))


# ------------------------------------------------------------------ cross products, fast
def cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of two 3-vectors (numpy.cross costs about 35 us a call here: it was
    70% of a sweep step in a profile; this costs about 1 us)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def cross_last(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b over the last axis (of length 3) of arrays broadcast together: numpy.cross's value without its
    axis moves (numpy.cross's overhead on small arrays was most of the time of a long loop's local
    analysis: analysis/loop_series.ad); stack_cross is the same over the leading axis."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def skew(a: np.ndarray) -> np.ndarray:
    """The cross-product matrix [a]x of a 3-vector (a x b = [a]x b)."""
    return a[_SKEW_INDEX] * _SKEW_SIGN


_SKEW_INDEX = np.array([[0, 2, 1], [2, 0, 0], [1, 0, 0]])
_SKEW_SIGN = np.array([[0.0, -1.0, 1.0], [1.0, 0.0, -1.0], [-1.0, 1.0, 0.0]])


def _skew_table(k: int, m: int | None=None) -> tuple:
    """Index and sign tables that turn the columns of a 3 x k matrix, flattened column by
    column, into their stacked cross-product matrices (3k x 3); with m, columns j and m + j
    side by side (3m x 6)."""
    table = _SKEW_TABLES.get((k, m))
    if table is None:
        index = (_SKEW_INDEX[None] + 3 * np.arange(k)[:, None, None]).reshape(3 * k, 3)
        sign = np.tile(_SKEW_SIGN, (k, 1))
        if m is not None:
            index = np.hstack([index[:3 * m], index[3 * m:]])
            sign = np.hstack([sign[:3 * m], sign[3 * m:]])
        table = _SKEW_TABLES[(k, m)] = (index, sign)
    return table


_SKEW_TABLES = {}


def skews(U: np.ndarray, m: int | None=None) -> np.ndarray:
    """The cross-product matrices of the columns of U (3 x k), stacked (3k x 3); with m,
    columns j and m + j side by side ((3m x 6): [[u_j]x, [u_m+j]x])."""
    index, sign = _skew_table(U.shape[1], m)
    return U.T.ravel()[index] * sign


def skews_batch(U: np.ndarray, m=None) -> np.ndarray:
    """skews for a stack: U (n, 3, k) -> (n, 3k, 3), or (n, 3m, 6) with m."""
    n, _, k = U.shape
    index, sign = _skew_table(k, m)
    return U.transpose(0, 2, 1).reshape(n, 3 * k)[:, index] * sign


# -- stacks of small complex matrices, the stack's axes last (model.kernel.algebraic) --------------------------

def quaternion_matrix(q: np.ndarray) -> np.ndarray:
    """Q(q) for quaternions q (..., 4) in Pinocchio's order (x, y, z, w): the homogeneous quadratic
    form, (q.q) times the rotation of q / |q|; (..., 3, 3)."""
    x, y, z, w = (q[..., k] for k in range(4))
    return np.stack([
        np.stack([w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z], -1)], -2)


def stack_mm(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """3 x 3 products over the trailing (stack) axes: A (3, 3, ...), B (3, 3, ...)."""
    return A[:, 0, None] * B[None, 0] + A[:, 1, None] * B[None, 1] + A[:, 2, None] * B[None, 2]


def stack_mv(A: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A (3, 3, ...) times v (3, ...)."""
    return A[:, 0] * v[0] + A[:, 1] * v[1] + A[:, 2] * v[2]


def stack_cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b over the leading axis (3, ...)."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def quaternion_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products a b of stacks (P, 4) of quaternions in (x, y, z, w) order (real or complex)."""
    ax, ay, az, aw = a.T
    bx, by, bz, bw = b.T
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), np.result_type(a, b))  # (no stack of temporaries)
    out[:, 0] = aw * bx + ax * bw + ay * bz - az * by
    out[:, 1] = aw * by + ay * bw + az * bx - ax * bz
    out[:, 2] = aw * bz + az * bw + ax * by - ay * bx
    out[:, 3] = aw * bw - ax * bx - ay * by - az * bz
    return out
