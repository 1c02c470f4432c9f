"""The joint vocabulary (info --joint-types) and the Gram-matrix cofactors of a loop's joint twists,
whose zero marks a stationary joint (issue 17 part 6)."""

import json

import numpy as np
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.singular import STATIONARY, classify, gram_cofactors, loop_twists
from screwkin.cli import main
from screwkin.files.description import CUT_JOINT_DOF
from screwkin.model.joint_types import JOINT_TYPES, joint_type

# Degrees of freedom of each pair, from the textbooks (Reuleaux's lower pairs; Gruebler's J1 / J2 for the
# planar higher pairs: a gear or rolling pair removes two of the plane's three freedoms, a cam one)
TEXTBOOK = {"revolute": 1, "continuous": 1, "prismatic": 1, "helical (screw pair)": 1, "cylindrical": 2,
            "universal (Hooke)": 2, "spherical (ball)": 3, "planar": 3, "floating": 6, "fixed": 0,
            "rolling (friction wheels)": 3 - 2, "gear pair": 3 - 2, "rack and pinion": 3 - 2,
            "cam (sliding contact)": 3 - 1, "pin in slot": 3 - 1}


def test_joint_types_table_against_the_textbook():
    assert {t.name: t.dof for t in JOINT_TYPES} == TEXTBOOK
    lower = {t.name for t in JOINT_TYPES if t.pair == "lower"}
    assert lower == {"revolute", "continuous", "prismatic", "helical (screw pair)", "cylindrical",
                     "universal (Hooke)", "spherical (ball)", "planar"}
    assert all(t.contact == "surface" for t in JOINT_TYPES if t.pair == "lower")
    assert all(t.contact in ("line", "point") for t in JOINT_TYPES if t.pair == "higher")
    screw = joint_type("helical")
    assert (screw.dof, screw.pair, screw.contact) == (1, "lower", "surface") and "helical" in screw.motion
    for t in JOINT_TYPES:  # screwkin's own count of each type it reads as a loop joint agrees
        if t.type in CUT_JOINT_DOF:
            assert CUT_JOINT_DOF[t.type] == t.dof, t.name


def test_info_joint_types_cli(capsys):
    assert main(["info", "--joint-types"]) == 0
    out = capsys.readouterr().out
    for t in JOINT_TYPES:
        assert t.name in out
    assert main(["info", "--joint-types", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert [e["name"] for e in d["joint_types"]] == [t.name for t in JOINT_TYPES]
    assert {e["name"]: e["dof"] for e in d["joint_types"]} == TEXTBOOK
    with pytest.raises(SystemExit) as e:  # no FILE and no --joint-types: a usage error
        code = main(["info"])
        raise SystemExit(code)
    assert e.value.code == 2
    assert "FILE" in capsys.readouterr().err


def _root(f, a, b, n=80):
    fa = f(a)
    for _ in range(n):
        m = 0.5 * (a + b)
        fm = f(m)
        if np.sign(fm) == np.sign(fa):
            a, fa = m, fm
        else:
            b = m
    return 0.5 * (a + b)


def _check_ratios(mech, q, stationary):
    """The cofactors against the null space of S from an SVD, and the zero where expected."""
    (g,) = gram_cofactors(mech, q)
    assert g.nullity == 1
    names, S, _ = loop_twists(mech, q, mech.cuts[0])
    v = np.linalg.svd(S)[2][-1]
    assert np.linalg.norm(S @ v) < 1e-8
    C = np.array([g.cofactors[n] for n in names])
    # adj(G) = c v v^T: C_ii = c v_i^2 with c the product of G's nonzero eigenvalues
    c = np.prod(np.sort(np.linalg.eigvalsh(S.T @ S))[1:])
    np.testing.assert_allclose(C, c * v ** 2, rtol=1e-6, atol=1e-12 * c)
    big = [i for i, n in enumerate(names) if n != stationary]
    for i in big:
        for j in big:
            assert C[i] / C[j] == pytest.approx(v[i] ** 2 / v[j] ** 2, rel=1e-6)
    assert g.zero == (stationary,)
    assert g.relative[stationary] < STATIONARY ** 2
    assert min(g.relative[n] for n in names if n != stationary) > 1e-3
    return g


def test_slider_crank_dead_centre_slider_cofactor_is_zero():
    mech = screwkin.load(ROBOTS / "slider_crank_offset.urdf")
    solver = PositionSolver(mech, ["crank_joint"])

    def slider_rate(th):
        s = solver.solve({"crank_joint": th}, rates={"crank_joint": 1.0}).solutions[0]
        return s.rates["slider_joint"]

    ths = np.linspace(0, 2 * np.pi, 73)
    r = [slider_rate(t) for t in ths]
    k = next(i for i in range(72) if np.sign(r[i]) != np.sign(r[i + 1]))
    th = _root(slider_rate, ths[k], ths[k + 1])  # a dead centre: the slider stops
    s = solver.solve({"crank_joint": th}, rates={"crank_joint": 1.0}).solutions[0]
    g = _check_ratios(mech, s.q, "slider_joint")
    # a second method: the position solver's rates; C_ii / C_jj = (theta_i' / theta_j')^2
    rates = s.rates
    assert g.cofactors["crank_joint"] / g.cofactors["rod_joint"] == pytest.approx(
        (rates["crank_joint"] / rates["rod_joint"]) ** 2, rel=1e-6)
    # and at a generic crank angle no cofactor is zero
    s0 = solver.solve({"crank_joint": 0.7}).solutions[0]
    (g0,) = gram_cofactors(mech, s0.q)
    assert g0.zero == () and min(g0.relative.values()) > 1e-4


def test_fourbar_rocker_at_its_limit_is_stationary_and_the_cli_reports_it(capsys):
    mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    solver = PositionSolver(mech, ["crank_joint"])

    def rocker_rate(th):
        return solver.solve({"crank_joint": th}, rates={"crank_joint": 1.0}).solutions[0].rates["rocker_joint"]

    ths = np.linspace(0, 2 * np.pi, 73)
    r = [rocker_rate(t) for t in ths]
    k = next(i for i in range(72) if np.sign(r[i]) != np.sign(r[i + 1]))
    th = _root(rocker_rate, ths[k], ths[k + 1])
    q = solver.solve({"crank_joint": th}).solutions[0].q
    _check_ratios(mech, q, "rocker_joint")
    rep = classify(mech, q)
    assert "rocker_joint" in rep.stationary_joints  # the same verdict as the null space of K
    near = ",".join(f"{n}={v!r}" for n, v in mech.joint_values(q).items())
    args = ["singularities", str(ROBOTS / "fourbar_crank_rocker.urdf"), f"--set=crank_joint={float(th)!r}",
            "--near", near]
    assert main(args + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["gram_loop"] == "coupler_rocker" and d["gram_zero"] == ["rocker_joint"]
    assert set(d["gram_cofactors"]) == {"crank_joint", "coupler_joint", "rocker_joint", "coupler_rocker"}
    assert "stationary_joints" in d and "sigmas" in d  # the keys that were there stay
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "loop closed by coupler_rocker" in out and "YES (C_ii = 0)" in out


def test_two_freedom_loop_says_what_it_computes():
    mech = screwkin.load(ROBOTS / "five_bar.urdf")
    (g,) = gram_cofactors(mech, mech.assemble().q)
    assert g.nullity == 2 and g.cofactors == {} and "identically" in g.note
