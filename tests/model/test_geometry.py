"""model/geometry.py against values worked out by hand (3-4-5 triangles, unit axes)."""

import numpy as np
import pytest

from screwkin.model.geometry import (circle_circle, circle_intersections, cross2, line_angle, line_circle, line_foot,
                                     lines_point, nearest_turn, perpendicular_basis, plane_basis, vector_angle,
                                     wrap_angle)


@pytest.mark.parametrize("a", [(0, 0, 1), (1, 0, 0), (0, 1, 0), (1, 1, 1), (0.95, -0.1, 0.3)])
def test_perpendicular_basis_is_right_handed_and_orthonormal(a):
    a = np.asarray(a, float) / np.linalg.norm(a)
    b1, b2 = perpendicular_basis(a)
    np.testing.assert_allclose(np.array([b1, b2, a]) @ np.array([b1, b2, a]).T, np.eye(3), atol=1e-15)
    np.testing.assert_allclose(np.cross(b1, b2), a, atol=1e-15)


def test_perpendicular_basis_hand_values():
    # a = z: h = x, b1 = z x x = y, b2 = z x y = -x
    b1, b2 = perpendicular_basis([0.0, 0.0, 1.0])
    np.testing.assert_array_equal(b1, [0, 1, 0])
    np.testing.assert_array_equal(b2, [-1, 0, 0])
    # a = x: h = y, b1 = x x y = z, b2 = x x z = -y
    b1, b2 = perpendicular_basis([1.0, 0.0, 0.0])
    np.testing.assert_array_equal(b1, [0, 0, 1])
    np.testing.assert_array_equal(b2, [0, -1, 0])


def test_plane_basis_hand_values():
    e1, e2, n = plane_basis([0, 0, -3.0])  # seen from -z, counterclockwise is clockwise from +z
    np.testing.assert_array_equal(e1, [1, 0, 0])
    np.testing.assert_array_equal(e2, [0, -1, 0])
    np.testing.assert_array_equal(n, [0, 0, -1])
    e1, e2, n = plane_basis([1.0, 0, 0])  # x is the normal: e1 is the world y axis
    np.testing.assert_array_equal(e1, [0, 1, 0])
    np.testing.assert_array_equal(e2, [0, 0, 1])
    e1, _, _ = plane_basis([0, 1.0, 1.0])  # x lies in the plane
    np.testing.assert_array_equal(e1, [1, 0, 0])


def test_circle_circle_three_four_five():
    # radii 5 and 5, centres 8 apart: the chord is at x = 4, half-chord 3
    X, h2 = circle_circle([1.0, 2.0], 5.0, [9.0, 2.0], 5.0, 1)
    np.testing.assert_allclose(X, [5.0, 5.0], atol=1e-15)
    assert h2 == pytest.approx(9.0, abs=1e-14)
    X, _ = circle_circle([1.0, 2.0], 5.0, [9.0, 2.0], 5.0, -1)
    np.testing.assert_allclose(X, [5.0, -1.0], atol=1e-15)
    # radii 3 and 4 about (0,0) and (5,0) (a right angle at the intersection): (9/5, +-12/5)
    X, _ = circle_circle(np.zeros((2, 2)), 3.0, [5.0, 0.0], 4.0, np.array([1.0, -1.0]))
    np.testing.assert_allclose(X, [[1.8, 2.4], [1.8, -2.4]], atol=1e-15)
    # too far apart: h2 < 0
    _, h2 = circle_circle([0.0, 0.0], 1.0, [3.0, 0.0], 1.0, 1)
    assert h2 < 0


def test_circle_intersections_cases():
    left, right = circle_intersections([0.0, 0.0], 3.0, [0.0, 5.0], 4.0)  # along +y: left of it is -x
    np.testing.assert_allclose(left, [-2.4, 1.8], atol=1e-15)
    np.testing.assert_allclose(right, [2.4, 1.8], atol=1e-15)
    assert circle_intersections([0.0, 0.0], 1.0, [3.0, 0.0], 1.0) == []  # apart
    assert circle_intersections([0.0, 0.0], 5.0, [1.0, 0.0], 1.0) == []  # one inside the other
    assert circle_intersections([0.0, 0.0], 1.0, [0.0, 0.0], 1.0, concentric=1e-15) == []  # concentric
    touch = circle_intersections([0.0, 0.0], 1.0, [2.0 + 1e-13, 0.0], 1.0, slack=1e-12)
    assert len(touch) == 2 and np.allclose(touch[0], [1.0, 0.0], atol=1e-12)


def test_lines():
    # (3, 4, 5) . (0, 0.6, 0.8) = 6.4 along the line
    np.testing.assert_allclose(line_foot([3.0, 4.0, 5.0], [0.0, 0.0, 0.0], [0.0, 0.6, 0.8]), [0.0, 3.84, 5.12], atol=1e-15)
    behind, ahead = line_circle([0.0, 3.0], [1.0, 0.0], [0.0, 0.0], 5.0)
    np.testing.assert_allclose(behind, [-4.0, 3.0])
    np.testing.assert_allclose(ahead, [4.0, 3.0])
    assert line_circle([0.0, 6.0], [1.0, 0.0], [0.0, 0.0], 5.0) == []
    assert cross2([1.0, 0.0], [0.0, 1.0]) == 1.0 and cross2([0.0, 1.0], [1.0, 0.0]) == -1.0


@pytest.mark.parametrize("u, w, angle", [((1.0, 0.0), (0.0, 3.0), np.pi / 2), ((1.0, 0.0), (-1.0, 1e-9), np.pi - 1e-9),
                                         ((0.0, 0.0, 2.0), (0.0, 1.0, 1.0), np.pi / 4), ((3.0, 4.0), (4.0, 3.0), np.arctan2(7, 24))])
def test_vector_and_line_angles(u, w, angle):
    # (3, 4) and (4, 3): |u x w| = 7, u . w = 24
    assert abs(float(vector_angle(u, w)) - angle) < 1e-15
    assert abs(float(line_angle(u, w)) - min(angle, np.pi - angle)) < 1e-15


def test_wrap_angle_hand_values():
    # 270 deg is -90 deg; a half turn is -180 deg in [-pi, pi) and +180 deg in (-pi, pi] (atan2's interval)
    assert wrap_angle(3 * np.pi / 2) == pytest.approx(-np.pi / 2, abs=1e-15)
    assert wrap_angle(np.pi) == -np.pi and wrap_angle(-np.pi) == -np.pi
    assert wrap_angle(np.pi, upper=True) == np.pi and wrap_angle(-np.pi, upper=True) == np.pi
    assert wrap_angle(-7 * np.pi / 2, upper=True) == pytest.approx(np.pi / 2, abs=1e-15)  # -630 deg is 90 deg
    v = np.array([0.0, 2 * np.pi, -2 * np.pi, 5.0])
    np.testing.assert_allclose(wrap_angle(v), [0, 0, 0, 5 - 2 * np.pi], rtol=0, atol=1e-15)
    np.testing.assert_allclose(wrap_angle(v, upper=True), [0, 0, 0, 5 - 2 * np.pi], rtol=0, atol=1e-15)
    assert not np.signbit(wrap_angle(-0.0, upper=True))  # no negative zero
    # the two intervals agree away from the half turn, as atan2 of (cos, sin) does
    x = np.linspace(-20, 20, 4001)
    np.testing.assert_allclose(wrap_angle(x, upper=True), np.arctan2(np.sin(x), np.cos(x)), rtol=0, atol=1e-13)


def test_nearest_turn_hand_values():
    assert nearest_turn(0.5, 13.0) == pytest.approx(0.5 + 4 * np.pi, abs=1e-14)  # 13 rad is about 2.07 turns
    assert nearest_turn(-0.5, -6.0) == pytest.approx(-0.5 - 2 * np.pi, abs=1e-14)
    assert nearest_turn(0.0, np.pi) == 0.0 and nearest_turn(0.0, -np.pi) == 0.0  # exactly half a turn: 0 turns (even)
    # 1.5 turns above -pi: 0 and -2 pi are both half a turn from it; the even count of turns (2) gives -2 pi
    assert nearest_turn(2 * np.pi, -np.pi) == pytest.approx(-2 * np.pi, abs=1e-15)
    np.testing.assert_allclose(nearest_turn(np.array([0.0, 3.0]), np.array([7.0, -3.0])), [2 * np.pi, 3.0 - 2 * np.pi],
                               rtol=0, atol=1e-14)


def test_lines_point_hand_values():
    # three axes through (1, 2, 3) along x, y and z meet there
    c, d = lines_point([[0, 2, 3], [1, 0, 3], [1, 2, 0]], [[1, 0, 0], [0, 2, 0], [0, 0, -5]], 1e-12)
    np.testing.assert_allclose(c, [1, 2, 3], rtol=0, atol=1e-14)
    assert d == pytest.approx(0.0, abs=1e-14)
    # the x axis and the line through (0, 0, 1) along y: the midpoint of their common normal, 0.5 from each
    c, d = lines_point([[0, 0, 0], [0, 0, 1]], [[1, 0, 0], [0, 1, 0]], 1e-12)
    np.testing.assert_allclose(c, [0, 0, 0.5], rtol=0, atol=1e-14)
    assert d == pytest.approx(0.5, abs=1e-14)
    assert lines_point([[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [-2, 0, 0]], 1e-12) == (None, np.inf)  # parallel
