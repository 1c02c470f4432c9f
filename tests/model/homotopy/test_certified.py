"""Every assembly mode with a certificate (issue 35): the complexified closure against Pinocchio, the
homotopy's root counts against published counts and an independent total-degree homotopy, and what
solve, ik and the JSON say about completeness."""

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.analysis.position import certified
from screwkin.analysis.position.ik import inverse_kinematics
from screwkin.analysis.position.position import PositionSolver
from screwkin.cli import main
from screwkin.model.homotopy import tracking
from screwkin.model.kernel.algebraic import PolynomialClosure
from screwkin.model.homotopy.symmetry import find_symmetries

FILES = ["fourbar_crank_rocker", "slider_crank_offset", "planar_3rpr", "bennett", "tsai_3upu", "sarrus",
         "gough_stewart_6ups", "rssr", "delta_parallelogram", "spherical_fourbar"]


def closure_of(name, eliminate=True, compiled=False):
    mech = screwkin.load(ROBOTS / f"{name}.urdf")
    solver = PositionSolver(mech)
    q = mech.generic_configurations()[0].q
    pc = PolynomialClosure(mech.model, mech.cuts, solver.frozen, mech.length, points=solver._points,
                           compiled=compiled, eliminate=eliminate)
    pc.set_inputs(q)
    return mech, solver, pc, q


# ------------------------------------------------------------------ the polynomial closure
@pytest.mark.parametrize("name", FILES)
def test_rows_vanish_where_pinocchio_closes_and_only_there(name):
    """At the assembled configuration every polynomial row vanishes (Pinocchio's closure is the
    reference) and every frame is where Pinocchio puts it; at random real configurations, where
    Pinocchio's residual does not vanish, the rows do not either."""
    mech, _, pc, q = closure_of(name, eliminate=False)
    x = pc.from_q(q)
    assert np.abs(pc.residual_all(x[None])).max() < 1e-12
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    kin = pc.kinematics(x[None], jacobian=False)
    for k, f in enumerate(pc.frames):
        np.testing.assert_allclose(kin["fp"][:, k, 0].real * pc.L, data.oMf[f].translation, rtol=0, atol=1e-12)
        np.testing.assert_allclose(kin["fR"][:, :, k, 0].real, data.oMf[f].rotation, rtol=0, atol=1e-12)
    rng = np.random.default_rng(4)
    for _ in range(3):
        qr = mech.random_configuration(rng)
        assert np.abs(mech.closure.residual(qr)).max() > 1e-6
        assert np.abs(pc.residual_all(pc.from_q(qr)[None])).max() > 1e-6


@pytest.mark.parametrize("name", FILES)
def test_jacobian_is_the_derivative_along_the_variety(name):
    """The rows' Jacobian in tangent coordinates against central differences along the same steps
    (model.kernel.algebraic.PolynomialClosure.retract) at random complex points."""
    _, _, pc, _ = closure_of(name)
    rng = np.random.default_rng(2)
    X = pc.random_points(rng, 3)
    _, J = pc.rows(X)
    h = 1e-6
    for v in range(pc.nt):
        E = np.zeros((3, pc.nt))
        E[:, v] = h
        fd = (pc.rows(pc.retract(X, E), False)[0] - pc.rows(pc.retract(X, -E), False)[0]) / (2 * h)
        np.testing.assert_allclose(J[:, :, v], fd, rtol=0, atol=1e-7 * (1 + np.abs(J).max()))


@pytest.mark.parametrize("name", FILES)
def test_the_compiled_kernel_gives_the_numpy_numbers(name):
    pytest.importorskip("numba")  # (CI installs it: conftest.CI_MODULES)
    _, _, a, q = closure_of(name)
    mech, _, b, _ = closure_of(name, compiled=True)
    X = a.random_points(np.random.default_rng(1), 7)
    ra, Ja = a.rows(X)
    rb, Jb = b.rows(X)
    np.testing.assert_allclose(rb, ra, rtol=0, atol=1e-12 * (1 + np.abs(ra).max()))
    np.testing.assert_allclose(Jb, Ja, rtol=0, atol=1e-12 * (1 + np.abs(Ja).max()))


def test_the_legs_that_are_distances_are_eliminated():
    """A U-P-S leg (the 6-UPS's five closing legs), an S-S coupler (RSSR) and the Delta's rods become
    one distance row each; their angles are no unknowns."""
    for name, legs, nt in (("gough_stewart_6ups", 5, 5), ("rssr", 1, 1), ("delta_parallelogram", 5, 6)):
        _, _, pc, _ = closure_of(name)
        assert (len(pc.legs), pc.nt) == (legs, nt)


def test_sign_symmetries_of_the_six_ups():
    """Five universal joints flipped (leg spun by pi about its axis) and the ball's other Euler set:
    2^6 sign maps of the 6-UPS written as revolutes; with leg 1's flip (the ball compensates, not a
    sign map) each pose is reached by 128 joint-angle sets."""
    _, _, pc, _ = closure_of("gough_stewart_6ups", eliminate=False)
    assert find_symmetries(pc, np.random.default_rng(0)).size == 64


# ------------------------------------------------------------------ counts
def test_four_bar_has_two_modes_certified():
    """A crank-rocker four-bar at 30 deg: two modes, certified by the trace test (the homotopy itself:
    solve places a mechanism made of dyads in closed form, tests/analysis/position/test_dyad_modes.py compares the two)."""
    solver = PositionSolver(screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf"))
    c = certified.certified_modes(solver, {"crank_joint": np.radians(30)}).count
    assert c.complete and c.certificate == "trace test" and c.method == "monodromy"
    assert (c.real, c.complex, c.found) == (2, 0, 2)


def _total_degree_roots(pc):
    """Every isolated root of the four-bar's polynomial system in (c3, s3, c4, s4) by a total-degree
    homotopy with the gamma trick: start system x_i^d_i - 1 (d = 2, 2 for the circles, 1, 1 for the
    rows, which are linear in each joint's cosine and sine), its 4 roots of unity; Jacobian by
    central differences.  Independent of monodromy and of the trace test."""
    m = pc.m
    deg = np.array([2, 2] + [1] * m)

    def f(X):
        return np.concatenate([pc.constraints(X), pc.rows(X, False)[0]], 1)

    gamma = np.exp(0.7j)
    starts = np.array([[np.exp(2j * np.pi * k / 2), np.exp(2j * np.pi * l / 2), 1, 1] for k in range(2) for l in range(2)])

    class TD:
        n = 4

        def evaluate(self, X, T, index, jacobian=True):
            T = np.asarray(T)[:, None]
            H = (1 - T) * gamma * (X ** deg - 1) + T * f(X)
            if not jacobian:
                return H, None
            J = np.empty((len(X), 4, 4), complex)
            for v in range(4):
                E = np.zeros(4)
                E[v] = 1e-7
                J[:, :, v] = ((1 - T) * gamma * ((X + E) ** deg - (X - E) ** deg) + T * (f(X + E) - f(X - E))) / 2e-7
            return H, J

        def dt(self, X, T, index):
            return f(X) - gamma * (X ** deg - 1)

        def retract(self, X, dT):
            return X + dT

    res = tracking.track(TD(), starts.astype(complex))
    return res.X[res.ok]


@pytest.mark.slow  # about 11.7 s on 2 shared cores: out of the fast subset
def test_monodromy_agrees_with_a_total_degree_homotopy():
    mech, solver, pc, q = closure_of("fourbar_crank_rocker", eliminate=False)
    td = _total_degree_roots(pc)
    td = td[np.abs(pc.residual_all(td)).max(axis=1) < 1e-8]
    got = certified.certified_modes(solver, {"crank_joint": float(q[mech.coordinate("crank_joint").idx_q])})
    assert got.count.complete and got.count.found == len(td) == 2 and got.count.method == "monodromy"
    got = sorted(float(q[mech.coordinate("rocker_joint").idx_q]) for q, _, _, _ in got.modes)
    want = sorted(float(pc.to_q(x, q)[mech.coordinate("rocker_joint").idx_q]) for x in td)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)


@pytest.mark.slow  # about 2.0 s on 2 shared cores: out of the fast subset
def test_bundled_gough_stewart_planar_hexagons():
    """The bundled 6-UPS has its base and platform points in planes (semi-regular hexagons): at its
    drawn leg lengths 28 complex poses, 8 of them real, below the 40 of a general geometry
    (Raghavan 1993, Wampler 1996) -- and Bertini 2's 28 for this geometry; with base and platform
    planar the poses come in mirror pairs through the base plane (the reflection keeps every leg
    length), so the count is even and a real pose's mirror is one too.  Every pose polished to
    round-off; certified since the architecture's generic solution set has 28 poses, complete by the
    trace test (issue 41: the count says what it rests on)."""
    mech = screwkin.load(ROBOTS / "gough_stewart_6ups.urdf")
    solver = PositionSolver(mech)
    res = solver.solve({n: 0.0 for n in solver.inputs})
    c = res.modes
    assert (c.real, c.complex, c.complete) == (8, 20, True)
    assert "trace test" in c.certificate and c.check["distinct_poses"] == 28
    assert all(s.residual < 1e-12 and not s.singular for s in res.solutions)
    # the mirror pairs: reflect each real pose's platform through z = 0
    poses = []
    for s in res.solutions:
        data = mech.model.createData()
        pin.framesForwardKinematics(mech.model, data, s.q)
        poses.append(data.oMf[mech.link_frame("platform")].translation)
    for p in poses:
        assert min(np.linalg.norm(p * [1, 1, -1] - o) for o in poses) < 1e-9


def stewart_urdf(seed=3):
    """A 6-6 Gough-Stewart platform of random (non-planar) geometry, U-P-S legs: leg 1 carries the
    platform through three revolutes (its ball), legs 2..6 close with spherical loop joints.  Drawn
    closed at its zero configuration."""
    rng = np.random.default_rng(seed)
    base = rng.uniform(-0.5, 0.5, (6, 3)) * [1, 1, 0.2]
    centre = np.array([0.02, -0.03, 0.7])
    plat = centre + rng.uniform(-0.3, 0.3, (6, 3)) * [1, 1, 0.3]

    def v(a):
        return " ".join(f"{x:.12g}" for x in a)

    inertial = '<inertial><mass value="0.3"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial>'
    out = ['<?xml version="1.0"?>', '<robot name="stewart_random">', f'<link name="base">{inertial}</link>',
           f'<link name="platform">{inertial}</link>']
    for k in range(6):
        d = plat[k] - base[k]
        d /= np.linalg.norm(d)
        a1 = np.cross(d, [0, 0, 1.0])
        a1 /= np.linalg.norm(a1)
        a2 = np.cross(d, a1)
        n = k + 1
        out += [f'<link name="u{n}"/>', f'<link name="cyl{n}">{inertial}</link>', f'<link name="pis{n}">{inertial}</link>',
                f'<joint name="u{n}a" type="revolute"><parent link="base"/><child link="u{n}"/><origin xyz="{v(base[k])}"/>'
                f'<axis xyz="{v(a1)}"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>',
                f'<joint name="u{n}b" type="revolute"><parent link="u{n}"/><child link="cyl{n}"/><origin xyz="0 0 0"/>'
                f'<axis xyz="{v(a2)}"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>',
                f'<joint name="leg{n}" type="prismatic"><parent link="cyl{n}"/><child link="pis{n}"/><origin xyz="0 0 0"/>'
                f'<axis xyz="{v(d)}"/><limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>',
                f'<transmission name="t{n}"><joint name="leg{n}"/></transmission>']
        if k == 0:
            out += ['<link name="b1"/>', '<link name="b2"/>']
            for name, axis, p, c in (("s1x", "1 0 0", "pis1", "b1"), ("s1y", "0 1 0", "b1", "b2"),
                                     ("s1z", "0 0 1", "b2", "platform")):
                xyz = v(plat[0] - base[0]) if p == "pis1" else "0 0 0"
                out.append(f'<joint name="{name}" type="continuous"><parent link="{p}"/>'
                           f'<child link="{c}"/><origin xyz="{xyz}"/><axis xyz="{axis}"/></joint>')
        else:
            out.append(f'<loop_joint name="s{n}" type="spherical"><link1 link="pis{n}" xyz="{v(plat[k] - base[k])}"/>'
                       f'<link2 link="platform" xyz="{v(plat[k] - plat[0])}"/></loop_joint>')
    out.append("</robot>")
    return "\n".join(out), base, plat


@pytest.mark.slow
def test_general_gough_stewart_has_40_certified(tmp_path):
    """A 6-6 platform of random geometry: 40 complex assembly modes (Raghavan 1993: 40 by
    continuation for a general geometry; Wampler 1996: never more), every one found and so
    certified by the published count; every real one closes Pinocchio's loops to round-off and
    keeps each leg's length (base point to platform point) at the drawn one."""
    text, base, plat = stewart_urdf()
    path = tmp_path / "stewart.urdf"
    path.write_text(text)
    mech = screwkin.load(path)
    solver = PositionSolver(mech)
    res = solver.solve({n: 0.0 for n in solver.inputs})
    c = res.modes
    assert c.complete and c.found == 40 and c.certificate.startswith("40 poses")
    assert c.real == len(res.solutions) >= 1
    lengths = np.linalg.norm(plat - base, axis=1)
    for s in res.solutions:
        assert np.abs(mech.closure.residual(s.q)).max() < 1e-12
        data = mech.model.createData()
        pin.framesForwardKinematics(mech.model, data, s.q)
        P = data.oMf[mech.link_frame("platform")]
        got = [np.linalg.norm(P.act(plat[k] - plat[0]) - base[k]) for k in range(6)]
        np.testing.assert_allclose(got, lengths, rtol=0, atol=1e-12)


def dh_urdf(seed=5):
    """A 6R serial chain of random Denavit-Hartenberg parameters (modified convention: joint i's
    origin Rx(alpha) Tx(a) Tz(d) from the link before, axis z)."""
    rng = np.random.default_rng(seed)
    inertial = '<inertial><mass value="0.3"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial>'
    out = ['<?xml version="1.0"?>', '<robot name="dh6r">'] + [f'<link name="l{i}">{inertial}</link>' for i in range(7)]
    for i in range(1, 7):
        a, d, alpha = rng.uniform(0.1, 0.5), rng.uniform(0.1, 0.5), rng.uniform(0.3, 2.8)
        out.append(f'<joint name="j{i}" type="continuous"><parent link="l{i - 1}"/><child link="l{i}"/>'
                   f'<origin xyz="{a:.12g} {-d * np.sin(alpha):.12g} {d * np.cos(alpha):.12g}" rpy="{alpha:.12g} 0 0"/>'
                   f'<axis xyz="0 0 1"/></joint>')
    out.append("</robot>")
    return "\n".join(out)


@pytest.mark.slow
def test_general_6r_inverse_kinematics_has_16(tmp_path):
    """The inverse kinematics of a 6R chain of random DH parameters: 16 solutions (Lee and Liang 1988;
    Raghavan and Roth 1993), every one found and so certified; every real one places the last link
    at the pose (Pinocchio's forward kinematics)."""
    path = tmp_path / "dh6r.urdf"
    path.write_text(dh_urdf())
    mech = screwkin.load(path)
    q = mech.random_configuration(np.random.default_rng(8))
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    pose = pin.SE3(data.oMf[mech.link_frame("l6")])
    res = inverse_kinematics(mech, "l6", pose)
    c = res.modes
    assert c.complete and c.detail["angle_sets"] == 16 and c.certificate.startswith("16 angle sets")
    for s in res.solutions:
        pin.framesForwardKinematics(mech.model, data, s.q)
        np.testing.assert_allclose(data.oMf[mech.link_frame("l6")].homogeneous, pose.homogeneous, rtol=0, atol=1e-12)


@pytest.mark.slow  # about 3.3 s on 2 shared cores: out of the fast subset
def test_planar_3rpr_counts():
    """The bundled 3-RPR at its drawn leg lengths: at most 6 complex solutions (Hunt 1983; Gosselin
    and Sefrioui 1991: a sextic); here 2 real and 2 complex, the other 2 of a general geometry at
    infinity -- every one of its finite solutions certified by the trace test (retried with other
    random choices: the test's witnesses may sit near infinity for one draw).  The homotopy itself:
    solve takes the closed form (tests/analysis/position/test_planar_three_distances.py)."""
    mech = screwkin.load(ROBOTS / "planar_3rpr.urdf")
    solver = PositionSolver(mech)
    for seed in range(3):
        got = certified.certified_modes(solver, {n: 0.0 for n in solver.inputs}, seed=seed)
        if got.count.complete:
            break
    c = got.count
    assert c.complete and (c.real, c.complex) == (2, 2) and c.detail["roots"] == 6
    for q, _, _, _ in got.modes:
        assert np.abs(mech.closure.residual(q)).max() < 1e-12


# ------------------------------------------------------------------ what solve says
def test_an_ill_conditioned_simple_root_is_not_singular(capsys):
    """The student slider-crank (crank 0.1, rod 0.2) just short of its outer dead centre, slider at
    0.3 - 1e-9 m: two simple roots, the crank at +-arccos((x^2 + a^2 - b^2) / (2 a x)) (law of
    cosines), each ill-conditioned (relative sigma below the old singular tolerance) but determined."""
    path = str(ROBOTS.parent / "tests" / "data" / "student" / "slider_crank.urdf")
    x = 0.3 - 1e-9
    assert main(["solve", path, "--set", f"slider_joint={x!r}", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    t = np.arccos((x**2 + 0.1**2 - 0.2**2) / (2 * 0.1 * x))
    got = sorted(s["joints"]["crank_joint"] for s in d["solutions"])
    np.testing.assert_allclose(got, [-t, t], rtol=0, atol=1e-9)
    for s in d["solutions"]:
        assert not s["singular"] and s["simple"] is not False and s["sigma_min"] < screwkin.Tolerances().singular
    assert main(["solve", path, "--set", f"slider_joint={x!r}"]) == 0
    assert "ill-conditioned (condition number" in capsys.readouterr().out


def test_not_polynomial_is_said_and_searched_as_before(capsys):
    """Rolling without slip is linear in the angles themselves: random starts, and why not certified."""
    assert main(["solve", str(ROBOTS / "friction_wheels.urdf"), "--set", "wheel2_joint=45deg", "--json"]) == 0
    m = json.loads(capsys.readouterr().out)["modes"]
    assert m["method"] == "random starts" and not m["complete"] and "rolling" in m["reason"]
    assert m["complex"] is None


def test_modes_json_keys(capsys):
    assert main(["solve", str(ROBOTS / "slider_crank_offset.urdf"), "--set", "crank_joint=20deg", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert {"found", "complete", "method", "real", "complex", "certificate"} <= set(d["modes"])
    assert all(s["residual"] < 1e-12 for s in d["solutions"])
