"""model.krawczyk: every root of two trigonometric polynomials on the torus, proved, against roots in closed form;
a curve of roots (no isolated root to prove) left undecided and said so."""

import numpy as np
import pytest

from screwkin.model.krawczyk import TrigPoly, bounds, torus_roots


def _wrapped(x):
    return (np.asarray(x) + np.pi) % (2 * np.pi) - np.pi


def _closed_form(a: float, b: float) -> np.ndarray:
    """The roots of cos u + cos w = a, sin(u - w) = b: with s = (u + w) / 2, d = u - w, 2 cos s cos(d / 2) = a
    and sin d = b, so d = asin b or pi - asin b, and s = +-acos(a / (2 cos(d / 2))) (+ pi with d + 2 pi)."""
    out = []
    for d0 in (np.arcsin(b), np.pi - np.arcsin(b)):
        for d in (d0, d0 + 2 * np.pi):  # d and d + 2 pi: the same point on the torus only after (u, w) wrap
            c = a / (2 * np.cos(d / 2))
            if abs(c) > 1:
                continue
            for s in (np.arccos(c), -np.arccos(c)):
                p = _wrapped([s + d / 2, s - d / 2])
                if not any(np.abs(_wrapped(p - o)).max() < 1e-12 for o in out):
                    out.append(p)
    return np.array(out)


@pytest.mark.parametrize("a,b", [(0.5, 0.2), (1.9, -0.7), (-0.3, 0.95), (0.0, 0.3)])
def test_the_roots_are_the_closed_forms(a, b):
    f1 = TrigPoly.fit(lambda u, w: np.cos(u) + np.cos(w) - a, (1, 1))
    f2 = TrigPoly.fit(lambda u, w: np.sin(u - w) - b, (1, 1))
    got = torus_roots((f1, f2))
    assert got.complete
    want = _closed_form(a, b)
    assert len(got.points) == len(want), (got.points, want)
    for p in want:
        assert min(np.abs(_wrapped(p - g)).max() for g in got.points) < 1e-13
    # each proved in its box: the root is there, the box's half-widths given
    assert np.all(got.radii > 0) and len(got.radii) == len(got.points)


def test_only_the_roots_inside_the_constraints_are_given():
    f1 = TrigPoly.fit(lambda u, w: np.cos(u) + np.cos(w) - 0.5, (1, 1))
    f2 = TrigPoly.fit(lambda u, w: np.sin(u - w) - 0.2, (1, 1))
    u_positive = TrigPoly.fit(lambda u, w: np.sin(u), (1, 0))
    got = torus_roots((f1, f2), within=((u_positive, 0.0, 2.0),))
    want = [p for p in _closed_form(0.5, 0.2) if np.sin(p[0]) > 0]
    assert len(want) == 1 and len(got.points) == 1
    assert np.abs(_wrapped(got.points[0] - want[0])).max() < 1e-13


def test_a_curve_of_roots_is_left_undecided_not_counted():
    """f1 = cos u - cos w and f2 = sin u - sin w vanish along the whole line u = w: no box about a point of it
    holds one root only, so the boxes there are left undecided and the roots are not complete."""
    f1 = TrigPoly.fit(lambda u, w: np.cos(u) - np.cos(w), (1, 1))
    f2 = TrigPoly.fit(lambda u, w: np.sin(u) - np.sin(w), (1, 1))
    got = torus_roots((f1, f2), start=(8, 8), max_boxes=20_000)
    assert not got.complete and len(got.undecided)
    assert not len(got.points)  # no root proved: none is isolated
    for c, r in got.undecided:  # each box left is at the line (those not examined when the count ran out, next to it)
        assert abs(_wrapped(c[0] - c[1])) <= 4 * (r[0] + r[1])


def test_the_enclosure_holds_the_values_and_the_degree_is_checked():
    rng = np.random.default_rng(3)
    f = TrigPoly.fit(lambda u, w: np.cos(3 * u - w) * np.sin(u + 2 * w) + 0.3 * np.cos(w), (4, 3))
    c, r = rng.uniform(-3, 3, (50, 2)), rng.uniform(0, 0.3, (50, 2))
    v, e = bounds(f, c, r)
    for ci, ri, vi, ei in zip(c, r, v, e):
        u, w = ci[:, None] + ri[:, None] * rng.uniform(-1, 1, (2, 200))
        x = np.cos(3 * u - w) * np.sin(u + 2 * w) + 0.3 * np.cos(w)
        assert np.all(np.abs(x - vi) <= ei)
    with pytest.raises(ValueError, match="not a trigonometric polynomial of degree"):
        TrigPoly.fit(lambda u, w: np.cos(3 * u), (2, 2))


def test_three_angles_every_root_of_a_closed_form():
    """sin t0 = a, sin t1 = b, cos(t0 + t1 + t2) = c: t0 in {asin a, pi - asin a}, t1 the same with b, and
    t2 = +-acos c - t0 - t1 -- eight roots, each found once and to round-off."""
    a, b, c = 0.3, -0.6, 0.45
    F = (TrigPoly.fit(lambda u, v, w: np.sin(u) - a, (1, 0, 0)), TrigPoly.fit(lambda u, v, w: np.sin(v) - b, (0, 1, 0)),
         TrigPoly.fit(lambda u, v, w: np.cos(u + v + w) - c, (1, 1, 1)))
    got = torus_roots(F)
    assert got.complete and len(got.points) == 8
    want = [(u, v, s * np.arccos(c) - u - v) for u in (np.arcsin(a), np.pi - np.arcsin(a))
            for v in (np.arcsin(b), np.pi - np.arcsin(b)) for s in (1, -1)]
    for p in want:
        assert min(np.abs(_wrapped(np.array(p) - g)).max() for g in got.points) < 1e-13


def test_value_and_gradient_in_one_pass_against_finite_differences():
    """with_gradient (one contraction of the stacked coefficients) against the closed form and central
    differences of it, in three angles."""
    def f(a, b, c):
        return np.cos(2 * a + 3 * b - c) + 0.5 * np.sin(a) * np.cos(4 * b) * np.sin(2 * c) - 0.2

    p = TrigPoly.fit(f, (2, 4, 2))
    rng = np.random.default_rng(3)
    t = rng.uniform(-np.pi, np.pi, (3, 50))
    V = p.with_gradient(*t)
    assert np.abs(V[0] - f(*t)).max() < 1e-12
    h = 1e-6
    for j in range(3):
        e = np.zeros((3, 1))
        e[j] = h
        assert np.abs(V[1 + j] - (f(*(t + e)) - f(*(t - e))) / (2 * h)).max() < 1e-8
