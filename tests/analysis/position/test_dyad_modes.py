"""Every assembly mode of a planar mechanism made of dyads, in closed form (analysis.position.dyad_modes):
the same modes as the homotopy continuation it stands in for (analysis.position.certified.certified_modes,
an independent method: monodromy and the trace test on the polynomial closure), the same counts of
real and complex solutions, and the textbook's closed forms written here (the slider-crank's
circle-line intersection, the non-Grashof four-bar's limit positions by the law of cosines)."""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.analysis.position import certified
from screwkin.analysis.position.position import PositionSolver
from screwkin.cli import main
from screwkin.errors import AssemblyError

#: The non-Grashof four-bar (ground d = 0.10, input a = 0.08, coupler b = 0.09, output c = 0.075 m,
#: drawn with the input at 70 deg): the input link's angle phi from the ground line, at which the
#: coupler and the output are in line, |B - D| = b + c, satisfies the law of cosines
#: (b + c)^2 = a^2 + d^2 - 2 a d cos(phi).  The input joint's value is phi - 70 deg.
PHI = np.arccos((0.08 ** 2 + 0.1 ** 2 - 0.165 ** 2) / (2 * 0.08 * 0.1))
LIMITS = (PHI - np.radians(70), -PHI - np.radians(70))


def solver_of(name):
    return PositionSolver(screwkin.load(ROBOTS / f"{name}.urdf"))


def values_of(solver, value, others=None):
    """The first input at ``value``, the others at the reference's values (or ``others``)."""
    ref = solver.mech.joint_values(solver.reference())
    return {n: value if k == 0 else (others or {}).get(n, ref[n]) for k, n in enumerate(solver.inputs)}


def assert_same_modes(solver, a, b):
    """Every mode of a is one of b and back (joint centres and output: PositionSolver.signature)."""
    tol = 1e-6 * max(solver.mech.length, 1.0)  # Tolerances.geometry, as solve tells modes apart
    A = [solver.signature(m[0]) for m in a.modes]
    B = [solver.signature(m[0]) for m in b.modes]
    assert len(A) == len(B)
    assert all(min(np.abs(x - y).max() for y in B) < tol for x in A)
    assert all(min(np.abs(x - y).max() for y in A) < tol for x in B)


CASES = [
    ("fourbar_crank_rocker", 0.5, None),
    ("fourbar_crank_rocker", -2.0, None),
    ("slider_crank_offset", 1.3, None),
    ("five_bar", 0.3, {"motor2": 2.4}),  # the held motor away from the reference: q0 does not close
    ("fourbar_non_grashof", LIMITS[0], None),  # a limit position: one double root
    ("fourbar_non_grashof", LIMITS[1], None),
    ("fourbar_non_grashof", 1.5, None),  # past the limit: two complex solutions, none real
    pytest.param("watt_sixbar", 0.7, None, marks=pytest.mark.slow),
    pytest.param("watt_sixbar", -3.1, None, marks=pytest.mark.slow),  # one dyad real, the other not
    pytest.param("stephenson_sixbar", -1.0, None, marks=pytest.mark.slow),
    pytest.param("stephenson_sixbar", 3.0, None, marks=pytest.mark.slow),
    pytest.param("strider", 2.0, None, marks=pytest.mark.slow),  # 16 modes (the trace test does not close)
]


@pytest.mark.parametrize("name,value,others", CASES)
def test_the_closed_form_finds_the_homotopys_modes(name, value, others):
    solver = solver_of(name)
    values = values_of(solver, value, others)
    closed = certified.closed_form(solver, values)
    homotopy = certified.certified_modes(solver, values)
    assert not isinstance(closed, str), closed
    c, h = closed.count, homotopy.count
    assert c.complete and c.method == "closed form (dyads)" and c.certificate.startswith("closed form")
    assert (c.real, c.complex, c.found) == (h.real, h.complex, h.found), (c, h)
    assert_same_modes(solver, closed, homotopy)
    assert sorted(n for _, _, n, _ in closed.modes) == sorted(n for _, _, n, _ in homotopy.modes)  # a double root: 2
    for q, a, _, _ in closed.modes:
        assert a.residual < 1e-12 and np.abs(solver.mech.closure.residual(q)).max() < 1e-12


def test_slider_crank_modes_are_the_circle_line_intersections():
    """Crank a = 0.05 at phi = 60 deg + theta, rod b = 0.15, slider pin on y = e = 0.02, x = 0.17318 m +
    slider_joint: x = a cos(phi) +- sqrt(b^2 - (e - a sin(phi))^2)."""
    solver = solver_of("slider_crank_offset")
    for theta in (0.0, 1.0, 2.5, -2.0):
        res = solver.solve({"crank_joint": theta})
        phi = np.radians(60) + theta
        root = np.sqrt(0.15 ** 2 - (0.02 - 0.05 * np.sin(phi)) ** 2)
        want = sorted(0.05 * np.cos(phi) + np.array([-root, root]) - 0.1731791173126931)
        got = sorted(s.joints["slider_joint"] for s in res.solutions)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
        assert res.modes.certificate == "closed form, 1 dyad (RRP), 2 branch vectors"


def test_at_a_limit_position_one_double_root_flagged_singular():
    solver = solver_of("fourbar_non_grashof")
    for value in LIMITS:
        res = solver.solve({"input_joint": value})
        (s,) = res.solutions
        assert s.singular and s.simple is False and s.angle_sets == 2
        assert res.modes.complete and (res.modes.real, res.modes.complex) == (1, 0)
        assert "2 meeting at a limit position" in res.modes.certificate
        # the coupler and the output in line: the coupler's pivot B that far from the output's pivot D
        model, data = solver.mech.model, solver.mech.model.createData()
        pin.forwardKinematics(model, data, s.q)
        b, d = (data.oMi[model.getJointId(j)].translation for j in ("coupler_joint", "output_joint"))
        assert abs(np.linalg.norm(b - d) - 0.165) < 1e-9


def test_where_the_loop_cannot_close_none_is_real_certified(capsys):
    solver = solver_of("fourbar_non_grashof")
    with pytest.raises(AssemblyError) as e:
        solver.solve({"input_joint": 1.5})
    assert "cannot assemble the mechanism: the inputs input_joint=1.5 cannot be reached: none of the 2 complex " \
           "solutions is real " \
           "(certified: closed form, 1 dyad (RRR), 2 branch vectors, 2 with a negative discriminant); nothing searched" \
           in str(e.value)
    # the certificate is the answer, and no start was tried: by the law of cosines the input's pivot B is
    # farther from the output's pivot D than coupler and output reach together
    phi = 1.5 + np.radians(70)
    assert np.sqrt(0.08 ** 2 + 0.1 ** 2 - 2 * 0.08 * 0.1 * np.cos(phi)) > 0.165 + 0.01
    assert e.value.starts is None and e.value.iterations == 0
    assert main(["solve", str(ROBOTS / "fourbar_non_grashof.urdf"), "--set", "input_joint=1.5"]) == 1
    assert "certified: closed form" in capsys.readouterr().err


def test_solve_says_closed_form_in_text_and_json(capsys):
    path = str(ROBOTS / "fourbar_crank_rocker.urdf")
    assert main(["solve", path, "--set", "crank_joint=30deg", "--json"]) == 0
    m = json.loads(capsys.readouterr().out)["modes"]
    assert (m["found"], m["complete"], m["method"], m["real"], m["complex"]) == (2, True, "closed form (dyads)", 2, 0)
    assert m["certificate"] == "closed form, 1 dyad (RRR), 2 branch vectors" and m["reason"] is None
    assert m["search"]["branch_vectors"] == 2 and m["search"]["dyads"] == 1
    assert main(["solve", path, "--set", "crank_joint=30deg"]) == 0
    assert "all 2 assembly modes (certified: closed form, 1 dyad (RRR), 2 branch vectors)" in capsys.readouterr().out


def test_mode_one_is_the_reference_and_spatial_loops_take_the_homotopy():
    """solve's rule: physical modes first, then nearest the reference configuration -- at the reference's
    own input value the first mode is the reference; a spatial loop (RSSR) is no dyad plan."""
    for name in ("fourbar_crank_rocker", "watt_sixbar", "strider"):
        solver = solver_of(name)
        ref = solver.reference()
        res = solver.solve(values_of(solver, solver.mech.joint_values(ref)[solver.inputs[0]]))
        assert res.modes.method == "closed form (dyads)"
        assert np.abs(solver.signature(res.solutions[0].q) - solver.signature(ref)).max() < 1e-9
    solver = solver_of("rssr")
    res = solver.solve(values_of(solver, solver.mech.joint_values(solver.reference())[solver.inputs[0]]))
    assert res.modes.method == "monodromy" and res.modes.detail["closed_form"] == "loop joint ball_C is a spherical joint"
