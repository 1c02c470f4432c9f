"""A new Stewart-Gough architecture's generic set carried from the general platform's (issue 41: the
first solve of a new architecture): one coefficient-parameter homotopy in the points A, B and the
squared lengths together (Morgan and Sommese 1989), from the 40 poses of a platform with random
complex points (shipped in screwkin/files/generic_sets), instead of monodromy and the trace test.

Outside references: 40, the most for any geometry and reached by a general one (Raghavan 1993;
Wampler 1996); Bertini 2's total-degree count for the bundled 6-UPS, 28 poses of which 8 real
(tests/data/bertini_stewart.json); the rows' rate along the segment against central differences;
each shipped pose checked by the distance equations written here from the quaternion's rotation.
"""

import shutil

import numpy as np
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.analysis.position import certified
from screwkin.analysis.position.position import PositionSolver
from screwkin.files import generic_cache
from screwkin.model.distances import SixDistances
from screwkin.model.homotopy import parameter
from screwkin.tolerances import Tolerances

ZERO = {f"leg{k}": 0.0 for k in range(1, 7)}


def _rotation(q):
    """The rotation of a quaternion (x, y, z, w) on q.q = 1, written out (complex entries allowed)."""
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def test_the_shipped_general_platform_has_its_40_simple_poses():
    (A0, B0, c0), X, path = parameter.general_set(np.random.default_rng(0), Tolerances())
    assert path is not None and path.parent == generic_cache.SHIPPED and len(X) == 40
    assert np.abs(A0.imag).min() > 0 and np.abs(c0.imag).min() > 0  # generic: complex points and lengths
    for x in X:
        q = x[3:]
        assert abs(q @ q - 1) < 1e-10
        R = _rotation(q)
        rows = [np.sum((x[:3] + R @ B0[k] - A0[k]) ** 2) for k in range(6)]
        np.testing.assert_allclose(rows, c0, rtol=0, atol=1e-9)
    _, J = SixDistances(A0, B0).equations(X)
    assert np.linalg.svd(J, compute_uv=False)[:, -1].min() > 1e-6  # every pose simple
    for i in range(40):  # distinct, q and -q one pose
        for j in range(i):
            assert min(np.abs(X[i] - X[j]).max(), np.abs(X[i] - X[j] * [1, 1, 1, -1, -1, -1, -1]).max()) > 1e-6


def test_the_segments_rate_is_its_finite_difference():
    rng = np.random.default_rng(5)
    A0, B0 = rng.normal(size=(2, 6, 3)) + 1j * rng.normal(size=(2, 6, 3))
    A1, B1 = rng.normal(size=(2, 6, 3))
    system = SixDistances(A1, B1)
    seg = parameter.GeometrySegment(system, (A0, B0, rng.normal(size=6) + 0j), (A1, B1, rng.normal(size=6)))
    X, T, h = system.random_points(rng, 3), np.array([0.3, 0.5 + 0.1j, 0.9]), 1e-6
    numeric = (seg.evaluate(X, T + h, None, False)[0] - seg.evaluate(X, T - h, None, False)[0]) / (2 * h)
    np.testing.assert_allclose(seg.dt(X, T, None), numeric, rtol=0, atol=1e-7)
    # at t = 1 it is the platform's own system
    np.testing.assert_allclose(seg.evaluate(X, np.ones(3), None, False)[0], system.offsets(X) - np.asarray(seg.a[2] + seg.d[2]),
                               atol=1e-12)


def test_a_new_architecture_is_carried_from_the_general_platform(tmp_path, monkeypatch):
    """The bundled 6-UPS as a new architecture (its own shipped set hidden, the general platform's
    kept): 40 paths give its 28 poses, 8 real -- Bertini 2's counts --, certified by the parameter
    homotopy; the set is kept, and the next solve reuses it."""
    shipped = tmp_path / "shipped"
    shipped.mkdir()
    shutil.copy(generic_cache.SHIPPED / f"{parameter.GENERAL}.json", shipped)
    monkeypatch.setattr(generic_cache, "SHIPPED", shipped)
    monkeypatch.setenv("SCREWKIN_CACHE", str(tmp_path / "cache"))
    mech = screwkin.load(ROBOTS / "gough_stewart_6ups.urdf")
    got = certified.search(PositionSolver(mech), ZERO).count
    assert (got.found, got.real, got.complete) == (28, 8, True)
    assert "general platform's 40 poses" in got.check["generic_set_certified_by"] and "12 at infinity" in got.certificate
    assert not got.detail["generic_set_reused"] and got.detail["generic_set"].startswith(str(tmp_path / "cache"))
    again = certified.search(PositionSolver(mech), ZERO).count
    assert (again.found, again.real, again.complete) == (28, 8, True) and again.detail["generic_set_reused"]


@pytest.mark.slow  # monodromy on the general platform: about 3 s of CPU, then 40 paths
def test_without_the_shipped_set_the_general_platform_is_solved_once(tmp_path, monkeypatch):
    monkeypatch.setattr(generic_cache, "SHIPPED", tmp_path / "none")
    monkeypatch.setenv("SCREWKIN_CACHE", str(tmp_path / "cache"))
    (A0, B0, c0), X, path = parameter.general_set(np.random.default_rng(1), Tolerances())
    assert len(X) == 40 and path == tmp_path / "cache" / f"{parameter.GENERAL}.json"
    assert parameter.general_set(np.random.default_rng(2), Tolerances())[2] == path  # read back, not solved again
