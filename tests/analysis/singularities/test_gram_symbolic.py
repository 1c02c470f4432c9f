"""singularities --symbolic (issue 25 item 5): each planar loop's Gram cofactors in the symbols of
screwkin equations, checked against the numeric cofactors of analysis.singular.gram_cofactors (an SVD-free
determinant of the twist matrix from Pinocchio's Jacobians) at solved configurations, and against the
four-bar's textbook fact that its rocker is stationary when crank and coupler are collinear."""

from __future__ import annotations

import json

import pytest
import sympy as sp

from conftest import DATA, ROBOTS
from screwkin import load
from screwkin.analysis.course.vector_loops import VectorLoops
from screwkin.analysis.singularities.gram_symbolic import symbolic_gram
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.singular import gram_cofactors
from screwkin.cli import main

CASES = [(ROBOTS / "fourbar_crank_rocker.urdf", "crank_joint", (0.4, 1.9, -2.2)),
         (ROBOTS / "slider_crank_offset.urdf", "crank_joint", (0.3, 2.0, -1.0)),
         (DATA / "student" / "rrpr.urdf", "A", (0.5, 1.4, -2.5))]


@pytest.mark.parametrize("path,inp,values", CASES, ids=lambda c: getattr(c, "stem", None))
def test_symbolic_cofactors_equal_the_numeric_ones(path, inp, values):
    mech = load(str(path))
    q0 = mech.assemble().q
    (loop,) = symbolic_gram(mech, q0, [inp])
    solver = PositionSolver(mech, [inp])
    vl = VectorLoops(mech, q0, [inp])  # the symbols' conventions are those of the configuration they were written at
    for v in values:
        q = solver.solve({inp: v}).solutions[0].q
        symbols = {**{n: s.value for n, s in vl.symbol_info.items()}, **vl.values(q)}
        (num,) = gram_cofactors(mech, q)
        sliding = {n for n in num.joints if mech.coordinate_names.count(n) and
                   mech.translational[mech.coordinate_names.index(n)]} | {c.name for c in mech.cuts if c.type == "prismatic"}
        L = mech.length
        expected = {}
        for name, text in loop.cofactors.items():
            value = float(sp.sympify(text).subs({sp.Symbol(k): x for k, x in symbols.items()}))
            others = sum(1 for n in loop.joints if n != name and n in sliding)
            expected[name] = value * L ** (2 * others - 4)  # the numeric S is dimensionless (see GramLoop)
        total = sum(expected.values())
        for name in loop.joints:
            assert expected[name] / total == pytest.approx(num.relative[name], abs=1e-9), (path.name, v, name)


def test_four_bar_rocker_is_stationary_where_crank_and_coupler_are_collinear(capsys):
    path = str(ROBOTS / "fourbar_crank_rocker.urdf")
    assert main(["singularities", path, "--symbolic", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    (loop,) = d["gram_symbolic"]
    assert sp.simplify(sp.sympify(loop["cofactors"]["rocker_joint"])
                       - sp.sympify("r2**2*r3**2*sin(theta2 - theta3)**2")) == 0
    assert any("sin(theta2 - theta3) = 0" in c for c in loop["zero_when"]["rocker_joint"])
    assert main(["singularities", path, "--symbolic"]) == 0
    out = capsys.readouterr().out
    assert "Gram cofactors in symbols" in out and "rocker_joint" in out


def test_symbolic_needs_a_planar_mechanism(capsys):
    assert main(["singularities", str(ROBOTS / "bennett.urdf"), "--symbolic"]) == 2
    assert "planar" in capsys.readouterr().err
