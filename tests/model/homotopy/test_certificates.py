"""A certificate is checked before it is given (issue 41, section 1): Stewart-Gough platforms written
with one leg in the tree and with the platform on a floating joint give the same set of platform poses,
with the counts of an outside solver, each pose checked independently (every leg's length from the
geometry alone, poses distinct).

Outside references: Dietmaier's platform with 40 real poses and PHCpack's 40 solutions of it
(tests/data/stewgou40.json, from PHCpack's src/Demo/stewgou40); 40, the most for any geometry
(Raghavan 1993; Wampler 1996); Bertini 2's total-degree solves (tests/oracles/bertini_stewart.py, run
in a virtual environment of its own; its counts and real poses recorded in
tests/data/bertini_stewart.json with how they were produced): Dietmaier 40 / 40 real, the general
geometry 40 / 2, the planar one 40 / 4, the bundled 6-UPS 28 / 8.  The platforms are built in the tests from their geometry
(tests/stewart_forms.py).
"""

import json
import shutil
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

import screwkin
import stewart_forms as sf
from conftest import ROBOTS
from screwkin.analysis.position import certified
from screwkin.analysis.position.position import PositionSolver
from screwkin.files import generic_cache

ZERO = {f"leg{k}": 0.0 for k in range(1, 7)}
SHIPPED = sf.DATA / "generic"
#: Bertini 2's answers for these geometries, and how they were produced (tests/oracles/bertini_stewart.py).
BERTINI = json.loads((sf.DATA / "bertini_stewart.json").read_text())["geometries"]


def _bertini(name):
    """(poses, real, real poses (R, t)) of Bertini 2's total-degree solve of a geometry."""
    b = BERTINI[name]
    return b["poses"], b["real"], [(np.array(p["R"]), np.array(p["t"])) for p in b["real_poses"]]


class _Every:
    """What the tests read of the search for every mode (certified.search, as solve --all runs it):
    ``modes`` the ModeCount, ``solutions`` the real modes' (q, Assembly)."""

    def __init__(self, mech, values):
        found = certified.search(PositionSolver(mech), values)
        self.modes, self.solutions = found.count, [(q, a) for _, q, a in found.found]


def _solve(tmp_path, base, plat, R, t, form, values=ZERO):
    path = tmp_path / f"stewart_{form}.urdf"
    path.write_text(sf.urdf(base, plat, R, t, form))
    mech = screwkin.load(path)
    return mech, _Every(mech, values)


def _poses(mech, res, R_drawn, plat):
    return [sf.pose_of(mech, q, R_drawn, plat) for q, _ in res.solutions]


def _check_poses(poses, base, plat, lengths):
    """Every pose keeps every leg at its length (from the geometry alone, not the file) and the poses
    are distinct."""
    for Rg, tg in poses:
        np.testing.assert_allclose(sf.leg_lengths(base, plat, Rg, tg), lengths, rtol=0, atol=1e-10)
        np.testing.assert_allclose(Rg @ Rg.T, np.eye(3), atol=1e-10)
    for i in range(len(poses)):
        for j in range(i):
            assert _distance(poses[i], poses[j]) > 1e-6


def _distance(a, b):
    return max(np.abs(a[0] - b[0]).max(), np.abs(a[1] - b[1]).max())


def _same_sets(P, Q, tol):
    assert len(P) == len(Q)
    for p in P:
        assert min(_distance(p, q) for q in Q) < tol


def _certified(c, found, real):
    assert (c.found, c.real, c.complex, c.complete) == (found, real, found - real, True)
    check = c.check
    assert check["checked"] and check["failed_paths"] == 0 and check["distinct_poses"] == found <= check["bound"] == 40


@pytest.fixture
def shipped_cache(tmp_path, monkeypatch):
    """A cache folder holding the generic set of Dietmaier's architecture (tests/data/generic)."""
    folder = tmp_path / "cache"
    shutil.copytree(SHIPPED, folder)
    monkeypatch.setenv("SCREWKIN_CACHE", str(folder))
    return folder


@pytest.mark.parametrize("form", ["tree", "floating"])
def test_dietmaier_has_40_real_poses_in_both_forms(tmp_path, shipped_cache, form):
    """Dietmaier's platform (40 real assembly modes): all 40, real, certified, in either form, and they
    are PHCpack's 40 (each within 1e-4: PHCpack's system has its coefficients rounded to 10 digits, and
    some poses are ill-conditioned)."""
    base, plat, lengths, phc = sf.dietmaier()
    R, t = phc[0]
    mech, res = _solve(tmp_path, base, plat, R, t, form, {f"leg{k + 1}": float(lengths[k] - d) for k, d in
                                                          enumerate(sf.leg_lengths(base, plat, R, t))})
    _certified(res.modes, 40, 40)
    assert res.modes.detail["generic_set_reused"]
    poses = _poses(mech, res, R, plat)
    _check_poses(poses, base, plat, lengths)
    _same_sets(poses, phc, 1e-4)  # PHC: coefficients rounded to 10 digits, some poses ill-conditioned
    found, real, bertini = _bertini("dietmaier")
    assert (found, real) == (res.modes.found, res.modes.real)
    _same_sets(poses, bertini, 1e-7)


def test_new_leg_lengths_reuse_the_generic_set(tmp_path, shipped_cache):
    """Other leg lengths of a known architecture: 40 paths from the cached set, certified; tree and
    floating forms give the same poses."""
    base, plat, lengths, phc = sf.dietmaier()
    R, t = phc[0]
    values = dict(ZERO, leg1=0.05, leg3=-0.04)
    got = {}
    for form in ("tree", "floating"):
        mech, res = _solve(tmp_path, base, plat, R, t, form, values)
        c = res.modes
        assert c.complete and c.check["paths"] == 40 and c.detail["generic_set_reused"]
        assert c.found <= 40 and c.check["checked"]
        new = sf.leg_lengths(base, plat, R, t) + [0.05, 0, -0.04, 0, 0, 0]
        got[form] = _poses(mech, res, R, plat)
        _check_poses(got[form], base, plat, new)
    _same_sets(got["tree"], got["floating"], 1e-8)


def test_a_malformed_cache_file_is_not_read(tmp_path, shipped_cache):
    """The cache is read as untrusted input: another version, fields of another type or shape, numbers
    not finite, a set cut short (its digest), a file that is no JSON, a huge file, a name that is no
    hash -- each is ignored."""
    (name,) = list(shipped_cache.glob("*.json"))
    key, data = name.stem, json.loads(name.read_text())
    c0, X, how, _ = generic_cache.read(key, 7, 6)
    assert X.shape == (40, 7) and c0.shape == (6,) and "published bound" in how
    for bad in ({"version": 99}, {"key": "b" * 64}, {"roots": "x"}, {"roots": [[[1, 2, 3]]]},
                {"c0": [[float("nan"), 0]] * 6}, {"certified_by": 3}, {"roots": data["roots"][:39]},
                {"digest": "0" * 64}):
        name.write_text(json.dumps({**data, **bad}))
        assert generic_cache.read(key, 7, 6) is None
    name.write_text("[" * 10)
    assert generic_cache.read(key, 7, 6) is None
    name.write_text(" " * (2 << 20))
    assert generic_cache.read(key, 7, 6) is None
    assert generic_cache.read("../../etc/passwd", 7, 6) is None


@pytest.mark.slow  # the generic set computed again: about 5 s of CPU
def test_the_solver_refuses_a_cached_root_that_is_no_root(tmp_path, shipped_cache):
    """A cached root moved off the system: the set is recomputed (not reused), the answer unchanged."""
    (name,) = list(shipped_cache.glob("*.json"))
    data = json.loads(name.read_text())
    data["roots"][3][0][0] += 1e-3
    data["digest"] = generic_cache._digest(data["c0"], data["roots"], data["certified_by"])  # passes the reader
    name.write_text(json.dumps(data))
    assert generic_cache.read(name.stem, 7, 6) is not None
    base, plat, lengths, phc = sf.dietmaier()
    R, t = phc[0]
    mech, res = _solve(tmp_path, base, plat, R, t, "floating", {f"leg{k + 1}": float(lengths[k] - d) for k, d in
                                                                 enumerate(sf.leg_lengths(base, plat, R, t))})
    assert not res.modes.detail["generic_set_reused"]
    _certified(res.modes, 40, 40)


def test_no_cache_write_under_a_file_size_limit(tmp_path):
    """RLIMIT_FSIZE set: nothing is written (the set is just computed); an unwritable folder too."""
    code = ("import resource, numpy as np, sys; resource.setrlimit(resource.RLIMIT_FSIZE, (1 << 30, 1 << 30));"
            "from screwkin.files import generic_cache as g;"
            "print(g.write('a' * 64, np.zeros(6), np.zeros((2, 7)), 'test'))")
    env = {"SCREWKIN_CACHE": str(tmp_path / "c"), "PATH": "/usr/bin:/bin", "PYTHONPATH": str(sf.DATA.parent.parent)}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert out.stdout.strip() == "None" and not (tmp_path / "c").exists()
    blocker = tmp_path / "file"
    blocker.write_text("x")
    env["SCREWKIN_CACHE"] = str(blocker / "below")
    code = code.replace("resource.setrlimit(resource.RLIMIT_FSIZE, (1 << 30, 1 << 30));", "")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert out.stdout.strip() == "None"


def test_cache_folder_follows_xdg_and_can_be_turned_off(monkeypatch, tmp_path):
    monkeypatch.delenv("SCREWKIN_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert generic_cache.folder() == tmp_path / "screwkin" / "generic"
    monkeypatch.setenv("SCREWKIN_CACHE", "off")
    assert generic_cache.folder() is None and generic_cache.write("a" * 64, np.zeros(6), np.zeros((1, 7)), "x") is None


def test_modes_json_has_the_certificate_check(tmp_path, shipped_cache, capsys):
    """The JSON keeps its keys and adds the checked certificate beside them."""
    base, plat, lengths, phc = sf.dietmaier()
    R, t = phc[0]
    path = tmp_path / "d.urdf"
    path.write_text(sf.urdf(base, plat, R, t, "floating"))
    sets = ",".join(f"leg{k + 1}={lengths[k] - d:.17g}" for k, d in enumerate(sf.leg_lengths(base, plat, R, t)))
    from screwkin.cli import main
    assert main(["solve", str(path), "--set", sets, "--all", "--json"]) == 0
    m = json.loads(capsys.readouterr().out)["modes"]
    assert {"found", "complete", "method", "real", "complex", "certificate", "reason", "search"} <= set(m)
    check = m["certificate_check"]
    assert check["checked"] is True and check["paths"] == 40 and check["failed_paths"] == 0
    assert check["bound"] == 40 and check["distinct_poses"] == 40 and m["search"]["generic_set"].startswith(str(shipped_cache))


@pytest.mark.slow  # a first solve of two architectures in two forms: about 20 s of CPU
@pytest.mark.parametrize("seed,planar", [(3, False), (4, True)])
def test_tree_and_floating_forms_agree_from_scratch(tmp_path, monkeypatch, seed, planar):
    """A general and a planar (base and platform) 6-6 geometry, no cache: 40 poses in either form,
    certified, the same real poses, each closing every leg to 1e-10."""
    monkeypatch.setenv("SCREWKIN_CACHE", str(tmp_path / "cache"))
    base, plat, R, t = sf.random_geometry(seed, planar)
    lengths = sf.leg_lengths(base, plat, R, t)
    got = {}
    for form in ("tree", "floating"):
        mech, res = _solve(tmp_path, base, plat, R, t, form)
        _certified(res.modes, 40, res.modes.real)
        got[form] = _poses(mech, res, R, plat)
        _check_poses(got[form], base, plat, lengths)
    _same_sets(got["tree"], got["floating"], 1e-8)
    name = "planar" if planar else "general"
    found, real, bertini = _bertini(name)
    assert (res.modes.found, res.modes.real) == (found, real)
    _same_sets(got["tree"], bertini, 1e-7)
    if planar:  # base and platform planar: a pose's mirror through the base plane is one too
        for Rg, tg in got["tree"]:
            M = np.diag([1.0, 1.0, -1.0])
            assert min(_distance((M @ Rg @ M, M @ tg), p) for p in got["tree"]) < 1e-8


@pytest.mark.slow
@pytest.mark.parametrize("seed", [11, 12])
def test_random_geometries_agree(tmp_path, monkeypatch, seed):
    monkeypatch.setenv("SCREWKIN_CACHE", str(tmp_path / "cache"))
    base, plat, R, t = sf.random_geometry(seed)
    got = {}
    for form in ("tree", "floating"):
        mech, res = _solve(tmp_path, base, plat, R, t, form)
        assert res.modes.complete and res.modes.found == 40
        got[form] = _poses(mech, res, R, plat)
    _same_sets(got["tree"], got["floating"], 1e-8)


@pytest.mark.slow  # the trace test on a special architecture: about 20 s of CPU
def test_bundled_six_ups_has_28_certified_by_the_trace_test(tmp_path, monkeypatch):
    """The bundled 6-UPS (semi-regular hexagons): 28 poses, 8 real -- Bertini 2's count for this
    geometry -- certified by the trace test where the general platform's set is not to be had (the
    fallback of model.homotopy.parameter.generic_set: monodromy, then the trace test)."""
    from screwkin.model.homotopy import parameter

    monkeypatch.setenv("SCREWKIN_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(generic_cache, "SHIPPED", tmp_path / "none")  # computed here, not the shipped set
    monkeypatch.setattr(parameter, "general_set", lambda rng, tol: None)
    mech = screwkin.load(ROBOTS / "gough_stewart_6ups.urdf")
    res = _Every(mech, ZERO)
    assert not res.modes.detail["generic_set_reused"]
    _certified(res.modes, 28, 8)
    assert "trace test" in res.modes.certificate
    assert all(a.residual < 1e-12 for _, a in res.solutions)
    found, real, bertini = _bertini("six_ups")
    assert (found, real) == (28, 8)
    data = mech.model.createData()
    poses = []
    for q, _ in res.solutions:  # the pose of the platform's joint frame, as Bertini's geometry has it
        pin.forwardKinematics(mech.model, data, q)
        M = data.oMi[mech.model.getJointId("ball1_z")]
        poses.append((M.rotation, M.translation))
    _same_sets(poses, bertini, 1e-7)


def test_bundled_six_ups_from_its_shipped_generic_set():
    """The bundled 6-UPS's generic set ships with screwkin (screwkin/files/generic_sets): 28 poses, 8
    real, certified, in a second -- Bertini 2's 28 and 8 for this geometry."""
    mech = screwkin.load(ROBOTS / "gough_stewart_6ups.urdf")
    res = _Every(mech, ZERO)
    _certified(res.modes, 28, 8)
    assert res.modes.detail["generic_set_reused"] and "generic_sets" in res.modes.detail["generic_set"]
    assert (BERTINI["six_ups"]["poses"], BERTINI["six_ups"]["real"]) == (28, 8)



def test_a_failed_path_is_no_certificate(tmp_path, shipped_cache):
    """Paths cut short (a tracker allowed 10 steps): the count is not called certified, and the reason
    says how many paths failed -- the certificate is checked, not assumed."""
    base, plat, lengths, phc = sf.dietmaier()
    R, t = phc[0]
    path = tmp_path / "d.urdf"
    path.write_text(sf.urdf(base, plat, R, t, "floating"))
    solver = PositionSolver(screwkin.load(path))
    short = screwkin.Tolerances(track_max_steps=10)
    got = certified.certified_modes(solver, ZERO, tolerances=short)
    c = got.count
    assert not c.complete and c.certificate is None and not c.check["checked"]
    assert c.check["failed_paths"] > 0 and f"{c.check['failed_paths']} of 40 paths failed" in c.reason


def test_a_certificate_that_misses_the_drawn_root_is_taken_back(capsys):
    """The spherical four-bar's rocker frame sits at the sphere's centre, where every joint axis meets
    (robots/spherical_fourbar.urdf), so every configuration of its one-degree-of-freedom motion puts it
    there: ik of that point is a whole circle of real solutions.  The homotopy's trace test closed on two
    complex roots of its square system and was printed as a certificate beside an 'unreachable' error;
    the drawn configuration, a root it did not hold, now takes the certificate back and the continuum is
    said."""
    from screwkin.cli import main
    code = main(["ik", str(ROBOTS / "spherical_fourbar.urdf"), "--output", "rocker", "--position", "0,0,0",
                 "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(out)
    modes = d["modes"]
    assert modes["complete"] is False and modes["certificate"] is None
    assert "not among them" in modes["reason"] and "positive-dimensional" in modes["reason"]
    assert d["free_dofs"] == 1  # the crank turns the whole mechanism about the centre
    assert len(d["solutions"]) >= 1
