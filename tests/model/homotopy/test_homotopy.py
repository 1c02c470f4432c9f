"""The homotopy's room (model/homotopy/, issue 42 item 2): its settings are Tolerances fields, and its
Newton steps are the project's one Newton iteration (model.kernel.newton.iterate) on complex stacks.

Outside references: the square roots of complex numbers (closed form), and Newton's own iteration
written out here by hand."""

import ast
import dataclasses
from pathlib import Path

import numpy as np

from screwkin import Tolerances
from screwkin.model.kernel import newton as one_newton
from screwkin.model.homotopy import tracking

ROOM = Path(__file__).resolve().parents[3] / "screwkin" / "model" / "homotopy"


class _Squares:
    """H(z, t) = z^2 - (a + t (b - a)) per path, in C^1: its roots at t are +-sqrt(a + t (b - a))."""

    n = 1

    def __init__(self, a, b):
        self.a, self.b = np.asarray(a, complex), np.asarray(b, complex)

    def _c(self, T, index):
        return self.a[index] + np.asarray(T) * (self.b[index] - self.a[index])

    def evaluate(self, X, T, index, jacobian=True):
        H = X[:, :1] ** 2 - self._c(T, index)[:, None]
        return H, (2 * X[:, :1, None] if jacobian else None)

    def dt(self, X, T, index):
        return -(self.b[index] - self.a[index])[:, None]

    def retract(self, X, dT):
        return X + dT


def test_the_homotopys_settings_are_tolerances_fields():
    """No dataclass of the room holds a numeric setting (the 31 option fields of TrackerOptions and
    MonodromyOptions are Tolerances' track_ and homotopy_ fields); a Tolerances field reaches the tracker."""
    for path in ROOM.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef) and any("dataclass" in ast.unparse(d) for d in node.decorator_list):
                numeric = [ast.unparse(s.target) for s in node.body if isinstance(s, ast.AnnAssign) and s.value is not None
                           and isinstance(s.value, ast.Constant) and isinstance(s.value.value, (int, float))]
                assert not numeric, f"{path.name}: {node.name} holds settings {numeric}: they belong in Tolerances"
    names = {f.name for f in dataclasses.fields(Tolerances)}
    assert {"track_max_steps", "track_tol", "track_endgame", "homotopy_budget", "homotopy_trace_tol",
            "homotopy_same"} <= names
    hom = _Squares([1.0, 4.0], [1j, 4j])
    X0 = np.array([[1.0], [2.0]], complex)
    got = tracking.track(hom, X0)
    assert got.ok.all()
    np.testing.assert_allclose(got.X[:, 0], np.sqrt([1j, 4j]), rtol=1e-14)
    assert not tracking.track(hom, X0, tol=Tolerances(track_max_steps=2)).ok.any()  # too few steps: failed


def test_newton_is_the_one_iteration_on_complex_stacks(monkeypatch):
    """tracking.newton runs model.kernel.newton.iterate (no loop of its own), on complex points: it lands on
    the square roots of complex numbers (closed form), step for step as Newton's iteration written out
    by hand."""
    calls = []
    real_iterate = one_newton.iterate

    def counting(*args, **kwargs):
        calls.append(np.iscomplexobj(args[1]))
        return real_iterate(*args, **kwargs)

    monkeypatch.setattr(one_newton, "iterate", counting)
    c = np.array([2 + 1j, -3 + 0.5j, 1j])
    hom = _Squares(c, c)
    X0 = (np.sqrt(c) * (1 + 0.05 * np.array([1, -1j, 1 + 1j])))[:, None]
    T, index = np.zeros(3), np.arange(3)
    end = tracking.newton(hom, X0, T, index, 6)
    assert calls == [True]
    np.testing.assert_allclose(end.X[:, 0], np.sqrt(c), rtol=1e-15, atol=0)
    assert end.kept.all() and (end.residual < 1e-12).all()
    z = X0[:, 0].copy()  # Newton's iteration by hand: z <- z - (z^2 - c) / (2 z)
    for _ in range(3):
        before = np.abs(z * z - c)
        z = z - (z * z - c) / (2 * z)
    three = tracking.newton(hom, X0, T, index, 3)
    np.testing.assert_allclose(three.X[:, 0], z, rtol=1e-14, atol=0)
    np.testing.assert_allclose(three.residual, before, rtol=1e-12)
    # the trace test's damped Newton: steps capped, a point whose step is not finite dropped (z = 0: J = 0)
    far = tracking.newton(hom, np.array([[3.0 + 0j], [0j], [1.0 + 0j]]), T, index, 40,
                          tracking.capped_newton_step(0.5), tracking.every_finite_step)
    assert list(far.kept) == [True, False, True]
    np.testing.assert_allclose(far.X[[0, 2], 0] ** 2, c[[0, 2]], rtol=1e-14)


def test_the_real_iteration_is_unchanged_by_complex_support():
    """model.kernel.newton.iterate on a real stack stays real (the closure solvers' path)."""
    def evaluate(Q, which, jacobian):
        r = Q[:, :1] ** 2 - 2.0
        return r, (2 * Q[:, :1, None] if jacobian else None)

    out = one_newton.iterate(evaluate, np.array([[1.0], [3.0]]), np.arange(1), Tolerances(), lambda Q, dQ: Q + dQ)
    assert out.q.dtype == float and out.converged.all()
    np.testing.assert_allclose(out.q[:, 0], np.sqrt(2.0), rtol=1e-10)
