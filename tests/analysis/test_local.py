"""The local analysis at a configuration (analysis.local, analysis.loop_series): the loops' Taylor series
against Pinocchio along curves on the manifold, the second-order term against finite differences and
against Pinocchio's accelerations, and the kind of point against answers derived by hand."""

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from screwkin.analysis.local import local_analysis, words
from screwkin.analysis.loop_series import Series, _units, loop_system
from screwkin.cli import main
from screwkin.model.linalg import null_space
from screwkin.model.loader import rebuild
from screwkin.model.state import KinematicState, value_for_leg_length

ROOT = Path(__file__).resolve().parents[2]
ROBOTS = ROOT / "robots"
DATA = Path(__file__).resolve().parents[1] / "data" / "local"
FOURBAR = ROBOTS / "fourbar.urdf.xacro"
FOLDED = {"ground": 0.2, "crank": 0.1, "coupler": 0.2, "rocker": 0.1, "theta": 0.0}
FOLDED_ARGS = ["--arg", "ground=0.2", "--arg", "crank=0.1", "--arg", "coupler=0.2", "--arg", "rocker=0.1"]


def folded(theta=0.0):
    return screwkin.load(FOURBAR, args={**FOLDED, "theta": theta})


def unit_screws(mech, q, system):
    """Every tree unit's dimensionless screw at q, straight from Pinocchio (joint placements, motion subspaces)."""
    units = _units(mech, KinematicState(mech, q))[0]
    S = np.array([u[0] for u in units])
    S[:, :3] /= system.length
    return S * system.scale[np.array([u[1] for u in units])][:, None]


def direction(rates: dict, names) -> np.ndarray:
    v = np.array([rates[n] for n in names])
    return v / np.linalg.norm(v)


@pytest.mark.parametrize("path, replacements", [
    (ROBOTS / "bennett.urdf", ()),
    (ROBOTS / "tsai_3upu.urdf", ()),  # universal loop joints, prismatic legs
    (ROBOTS / "gripper_arm_mimic.urdf", ()),  # a Pinocchio mimic joint: a unit of its primary's column
    (ROBOTS / "fourbar_crank_rocker.urdf", (("rocker_joint", "SPHERICAL"), ("coupler_joint", "UJOINT_ZX"))),
])
def test_series_of_the_screws_matches_pinocchio_along_the_manifold(path, replacements):
    """S_u(t) = sum_k S_u[k] t^k (Lie brackets) against the screws Pinocchio gives at q(t) = integrate(q0, t x):
    the error of the order-5 series falls as t^6, to round-off (a ball joint's units carry each other, a
    universal joint's second unit is carried by its first)."""
    mech = screwkin.load(path)
    if replacements:
        spec = mech.spec
        spec.replacements = list(replacements)
        mech = rebuild(spec)
    q0 = mech.generic_configurations()[0].q
    system = loop_system(mech, q0, reduce=False)
    x = np.zeros(system.columns)
    x[:mech.nv] = np.random.default_rng(3).normal(size=mech.nv)
    s = Series(system, x)
    for _ in range(5):
        s.push(np.zeros(system.columns))
    tree = np.flatnonzero(system.column < mech.nv)
    for t in (2e-2, 1e-2):
        q = pin.integrate(mech.model, q0, t * x[:mech.nv] * system.scale[:mech.nv])
        exact = unit_screws(mech, q, system)
        series = sum(s.S[k][tree] * t**k for k in range(6))
        np.testing.assert_allclose(series, exact, rtol=0, atol=50 * t**6 + 1e-13)
        assert np.abs(exact - s.S[0][tree]).max() > 1e3 * np.abs(exact - series).max()  # the series does the work


def test_series_of_the_loops_matches_pinocchio_along_an_accelerated_curve():
    """Phi(t) = sum_k (A X[k] + R_k) t^k for x(t) = x0 + t x1 (Bennett: revolute joints, q(t) = q0 + t x0 +
    t^2 x1 / 2 exactly) against Pinocchio: each loop's relative twist J_F2 x - J_F1 x (WORLD frame
    Jacobians at q(t)) with the cut joint's freedom held still."""
    mech = screwkin.load(ROBOTS / "bennett.urdf")
    q0 = mech.generic_configurations()[0].q
    system = loop_system(mech, q0, reduce=False)
    rng = np.random.default_rng(5)
    x0, x1 = np.zeros(system.columns), np.zeros(system.columns)
    x0[:mech.nv], x1[:mech.nv] = rng.normal(size=mech.nv), rng.normal(size=mech.nv)
    A = system.jacobian
    s = Series(system, x0)
    phi = [A @ x0]
    for k in range(1, 6):
        xk = x1 if k == 1 else np.zeros(system.columns)
        phi.append(A @ xk + s.residual())
        s.push(xk)
    cut = mech.cuts[0]
    for t in (2e-2, 1e-2):
        q = q0 + t * x0[:mech.nv] + t * t / 2 * x1[:mech.nv]
        st = KinematicState(mech, q)
        v = x0[:mech.nv] + t * x1[:mech.nv]
        tw = (st.frame_jacobian(cut.frame2, pin.ReferenceFrame.WORLD) - st.frame_jacobian(cut.frame1, pin.ReferenceFrame.WORLD)) @ v
        tw[:3] /= system.length
        np.testing.assert_allclose(sum(p * t**k for k, p in enumerate(phi)), tw, rtol=0, atol=100 * t**6)


def test_second_order_term_three_ways_on_the_folded_fourbar():
    """The second-order condition on ker K at the folded four-bar, three ways, as quadratic forms on
    ker K (up to one factor each): (1) the Lie brackets (analysis.loop_series), (2) Pinocchio's classical
    accelerations (ClosureSystem.bias: K'q' at q' in ker K), (3) a central finite difference of the minimal
    residual along q(t) = integrate(q0, t v): lambda^T r(t) = t^2/2 lambda^T bias(v) + O(t^3), lambda the
    left null vector of K in the plane (the out-of-plane rows vanish identically).  By hand (the test
    below): the form is proportional to v3 (v3 + 2 v2), v2 the crank's and v3 the coupler's absolute rate."""
    mech = folded()
    q0 = mech.generic_configurations()[0].q
    K = mech.closure.jacobian(q0)
    N = null_space(K, mech.tolerances)
    assert N.shape[1] == 2
    rows = mech.closure.row_labels()
    lam = null_space(K.T, mech.tolerances)  # 4 left null vectors: 3 out of the plane, 1 in it
    assert lam.shape[1] == 4
    y_samples = [np.array([np.cos(a), np.sin(a)]) for a in np.linspace(0.1, 3.0, 7)]
    system = loop_system(mech, q0)
    A = system.jacobian
    U = np.linalg.svd(A)[0][:, np.linalg.matrix_rank(A, 1e-9):]
    assert U.shape[1] == 1

    def brackets(v):
        x = np.zeros(system.columns)
        x[:mech.nv] = v
        x[mech.nv:] = -np.linalg.lstsq(A[:, mech.nv:], A[:, :mech.nv] @ v, rcond=None)[0]  # the cut's rate
        return float(U[:, 0] @ Series(system, x).residual())

    def hand(v):
        v2, v3 = v[0], v[0] + v[1]  # absolute rates of crank and coupler
        return v3 * (v3 + 2 * v2)

    lie = np.array([brackets(N @ y) for y in y_samples])
    by_hand = np.array([hand(N @ y) for y in y_samples])
    # the in-plane left null vector: the combination of lambda that is not identically zero on ker K
    bias = np.array([[l @ mech.closure.bias(q0, N @ y) for l in lam.T] for y in y_samples])
    j = int(np.argmax(np.abs(bias).max(axis=0)))
    pinocchio = bias[:, j]
    t = 1e-4
    fd = np.array([lam[:, j] @ (mech.closure.residual(pin.integrate(mech.model, q0, t * N @ y))
                                + mech.closure.residual(pin.integrate(mech.model, q0, -t * N @ y))) / t**2
                   for y in y_samples])
    for other in (pinocchio, fd, by_hand):
        ratio = lie / other
        np.testing.assert_allclose(ratio, ratio[0], rtol=1e-6, atol=0)
    assert "pos" in rows[int(np.argmax(np.abs(lam[:, j])))]  # it is the in-plane position row


def test_folded_fourbar_is_a_change_point():
    """Ground 0.2, crank 0.1, coupler 0.2, rocker 0.1, drawn folded with crank and rocker along +x.
    The loop r2 e^{i th2} + r3 e^{i th3} - r4 e^{i th4} - r1 = 0 at th = 0 (absolute angles, rates v2 v3 v4):
    first order (imaginary part) 0.1 v2 + 0.2 v3 - 0.1 v4 = 0 and nothing from the real part, so ker K has
    dimension 2 (infinitesimal mobility 2, K of rank 1 against 2 elsewhere); second order (real part)
    0.1 v2^2 + 0.2 v3^2 - 0.1 v4^2 = 0 with v4 = v2 + 2 v3 gives -0.2 v3 (v3 + 2 v2) = 0: v3 = 0 (the
    parallelogram, v4 = v2) or v3 = -2 v2 (the anti-parallelogram, v4 = -3 v2).  In joint rates (crank =
    v2, coupler joint = v3 - v2, rocker = v4): (1, -1, 1) and (1, -3, -3).  Two lines, each a simple zero of
    the quadratic form: two branches of mobility 1 cross, decided at order 2."""
    mech = folded()
    la = local_analysis(mech, mech.generic_configurations()[0].q)
    assert (la.kind, la.infinitesimal_mobility, la.finite_mobility, la.order, la.certain) == ("bifurcation", 2, 1, 2, True)
    assert la.rank_drop == 1 and la.algebra == "se(2)"
    names = mech.coordinate_names
    found = sorted(tuple(np.round(direction(b.tangent, names) / direction(b.tangent, names)[0], 9)) for b in la.branches)
    assert found == sorted([(1.0, -1.0, 1.0), (1.0, -3.0, -3.0)])
    assert all(b.mobility == 1 and b.confirmed for b in la.branches)
    assert la.inputs_held == 1  # the crank held, the folded linkage still has an instantaneous motion
    assert words(la).startswith("a change point: two branches of mobility 1 cross here")


def test_shaky_triangle_is_finitely_rigid():
    """Bars 0.1 and 0.2 pinned at P and to a 0.3 ground: O1 = 0, O2 = (0.3, 0), P = (0.1, 0).  With th1,
    th2 the bars' absolute angles: 0.1 e^{i th1} + 0.2 e^{i th2} = 0.3.  First order at 0: 0.1 v1 + 0.2 v2 = 0
    (one instantaneous freedom, P moving along y); second order: 0.1 v1^2 + 0.2 v2^2 = 0, with v1 = -2 v2:
    0.6 v2^2 = 0, so v = 0: no real zero but 0 -- an isolated point, rigid (decided at order 2: the tangent
    cone lies in the zero set).  Gruebler says 0, the rank of K here says 1 (instantaneous)."""
    mech = screwkin.load(DATA / "shaky_triangle.urdf")
    la = local_analysis(mech, mech.generic_configurations()[0].q)
    assert (la.kind, la.infinitesimal_mobility, la.finite_mobility, la.order, la.certain) == ("shaky", 1, 0, 2, True)
    assert la.branches == ()
    from screwkin.analysis.mobility import analyze_mobility

    r = analyze_mobility(mech)
    assert r.mobility == 0 and r.classification.startswith("shaky structure")


def test_regular_point_of_a_crank_rocker_is_decided_at_order_one():
    """A Grashof crank-rocker at 60 deg: the planar loop's three rows have rank 3 with the cut joint's
    rotation, so K has full row rank in the plane: a regular point of mobility 1 (order 1, a theorem)."""
    mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    la = local_analysis(mech, mech.generic_configurations()[0].q)
    assert (la.kind, la.infinitesimal_mobility, la.finite_mobility, la.order, la.certain) == ("regular", 1, 1, 1, True)


@pytest.mark.parametrize("name, kutzbach, rows", [("bennett.urdf", -2, 3), ("sarrus.urdf", 0, 1)])
def test_bennett_and_sarrus_move_with_one_freedom_everywhere(name, kutzbach, rows):
    """Bennett (1903) and Sarrus (1853): one degree of freedom at every configuration although Kutzbach
    gives -2 and 0.  At configurations along a whole sweep of the input: ker K is one-dimensional, every
    quadratic (and higher) term of the redundant rows vanishes identically (the overconstraint, 3 and 1
    rows), the series continues to Tolerances.local_order, and a step of 0.01 along the tangent closes
    again with rank(K) = nv - 1 there: finite mobility 1, said to order 6, not more."""
    mech = screwkin.load(ROBOTS / name)
    assert mech.topology().kutzbach == kutzbach
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.analysis.motion.sweep import sweep

    inp = mech.actuated[0]
    start = mech.joint_values(mech.generic_configurations()[0].q)[inp]
    res = sweep(PositionSolver(mech, [inp]), inp, start, start + 1.2, 4)
    for q in res.q:
        la = local_analysis(mech, q)
        assert (la.kind, la.infinitesimal_mobility, la.finite_mobility) == ("regular", 1, 1)
        assert (la.order, la.certain, la.identically_zero) == (mech.tolerances.local_order, False, rows)
        assert la.branches[0].confirmed and la.branches[0].mobility == 1


def tsai_singular():
    """Tsai's 3-UPU with the platform centre at (0.2, 0, 0.3), not turned (legs from value_for_leg_length)."""
    mech = screwkin.load(ROBOTS / "tsai_3upu.urdf")
    from screwkin.analysis.position.position import PositionSolver

    P = np.array([0.2, 0.0, 0.3])
    values = {}
    for i, name in enumerate(["leg1", "leg2", "leg3"]):
        r = np.array([np.cos(2 * np.pi * i / 3), np.sin(2 * np.pi * i / 3), 0.0])
        values[name] = value_for_leg_length(mech, name, float(np.linalg.norm(P + 0.1 * r - 0.2 * r)))
    for s in PositionSolver(mech, list(values)).solve(values).solutions:
        R = KinematicState(mech, s.q).frame_placement(mech.link_frame("platform")).rotation
        if np.linalg.norm(pin.log3(R)) < 1e-4:
            return mech, s.q
    raise AssertionError("no untwisted mode")


def platform_turn(mech, q):
    return float(np.linalg.norm(pin.log3(KinematicState(mech, q).frame_placement(mech.link_frame("platform")).rotation)))


def test_tsai_3upu_constraint_singularity_is_finitely_mobile():
    """Tsai's 3-UPU (robots/tsai_3upu.urdf: base radius 0.2, platform radius 0.1, outer U axes tangent).
    Leg i constrains the platform's rotation about m_i = a1_i x a2_i, the leg's direction projected on its
    radial-vertical plane: m_i = alpha_i r_i + beta_i z with alpha_i = (P.r_i - 0.1) / l_i, beta_i = h / l_i.
    det[m_1 m_2 m_3] = 0 (a constraint singularity) when sum_i beta_i / alpha_i = 0 (the r_i 120 deg
    apart); for P = (x, 0, h): 1/(x - 0.1) + 2/(-x/2 - 0.1) = 0, x = 0.2.  There K loses one rank
    (infinitesimal mobility 4).  Finitely or only infinitesimally?  The quadratic form of the one redundant
    row on ker K has signature (1, 1) and a 2-dimensional kernel: its zeros are two hyperplanes of ker K,
    simple zeros off their intersection, so two branches of mobility 3 cross (order 2, a theorem).  How we
    know the extra rotation is finite, apart from the series: the configuration closed again at a step of
    0.01 along the second branch has the platform turned (it left the translational mode), and following that
    branch further (closing the loops at each step, the step's projection on its tangent held) turns the
    platform by more than 0.04 rad with the loops closed.  So: finitely mobile -- a change of operation
    mode, as Bonev and Zlatanov explained the SNU robot's puzzling motion (ParalleMIC review, 2001)."""
    mech, q = tsai_singular()
    la = local_analysis(mech, q)
    assert (la.kind, la.infinitesimal_mobility, la.finite_mobility, la.order, la.certain) == ("bifurcation", 4, 3, 2, True)
    assert [b.mobility for b in la.branches] == [3, 3]
    from screwkin.analysis.local import _confirm, _orth
    from screwkin.analysis.loop_series import loop_system as ls

    system = ls(mech, q)
    turns = []
    for b in la.branches:
        t = np.array([b.tangent[n] for n in mech.coordinate_names])
        x = t / system.scale[:mech.nv]
        x /= np.linalg.norm(x)
        X = [np.r_[x, np.zeros(system.columns - mech.nv)]]
        B = _orth(x[:, None], 1e-9)
        qh, _, res = _confirm(mech, q, system, X, B, 0.05)
        assert qh is not None and np.linalg.norm(mech.closure.residual(qh)) < 1e-9
        turns.append(platform_turn(mech, qh))
    assert min(turns) < 1e-6 < 0.04 < max(turns)  # one branch translates, the other turns the platform


def test_mobility_reports_the_finite_mobility_and_json_contract(capsys):
    """mobility --json at the folded four-bar: the contract keys of "local", M = 1 (finite), the generic
    rank's M beside; the shaky triangle: M = 0 (finite) although K's rank at its only configuration leaves
    one instantaneous freedom (its "generic" samples are near-solutions of rank 2, a check that agrees here
    only by luck)."""
    assert main(["mobility", str(FOURBAR), *FOLDED_ARGS, "--arg", "theta=0", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    local = d["local"]
    assert {"rank_drop", "infinitesimal_mobility", "finite_mobility", "kind", "order", "branches"} <= set(local)
    assert (local["kind"], local["rank_drop"], local["infinitesimal_mobility"], local["finite_mobility"]) == ("bifurcation", 1, 2, 1)
    assert all({"tangent", "mobility"} <= set(b) for b in local["branches"])
    assert d["mobility"] == 1 and d["generic_mobility"] == 1
    assert main(["mobility", str(DATA / "shaky_triangle.urdf"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["mobility"] == 0 and d["local"]["kind"] == "shaky" and d["local"]["infinitesimal_mobility"] == 1
    assert d["classification"].startswith("shaky structure")


def test_mobility_and_singularities_at_a_given_configuration(capsys):
    """--set puts the local analysis at that configuration: the four-bar drawn at 0.5 rad, its crank set
    back to the folded pose (-0.5), is at the change point; singularities names the types that meet there."""
    args = [str(FOURBAR), *FOLDED_ARGS, "--arg", "theta=0.5", "--set", "crank_joint=-0.5", "--json"]
    assert main(["mobility", *args]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["local"]["kind"] == "bifurcation" and d["local"]["where"] == "the configuration given"
    assert main(["singularities", *args, "--output", "rocker"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["local"]["kind"] == "bifurcation" and d["constraint"]
    names = {t["name"] for t in d["types"]}
    assert {"type II", "increased instantaneous mobility", "constraint singularity"} <= names
    assert main(["singularities", *args[:-1]]) == 0
    out = capsys.readouterr().out
    assert "Zlatanov-Bonev-Gosselin: constraint singularity" in out and "a change point" in out


@pytest.mark.parametrize("branch", ["continue", "other"])
def test_sweep_names_the_change_point_and_the_branch_it_takes(capsys, branch):
    """The four-bar drawn as a parallelogram at 0.5 rad, swept to -1 (the crank through 0, the folded pose
    at input -0.5): the constraint measure dips to 0 there without a sign change; the sweep lists it as a
    change point and says it comes in on the parallelogram (1, -1, 1) and goes on along it (issue 41: the
    branch whose tangent continues the motion), or, with --branch other, along the other one (1, -3, -3)."""
    assert main(["sweep", str(FOURBAR), *FOLDED_ARGS, "--arg", "theta=0.5", "--input", "crank_joint", "--from", "0",
                 "--to", "-1", "--steps", "21", "--singularities", "--branch", branch, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    points = [s for s in d["singularities"] if s.get("local")]
    assert len(points) == 1
    p = points[0]
    assert abs(p["input"] + 0.5) < 1e-5 and p["local"]["kind"] == "bifurcation"
    came = p["local"]["branches"][p["came_on_branch"] - 1]["tangent"]
    goes = p["local"]["branches"][p["continues_on_branch"] - 1]["tangent"]
    assert np.allclose(list(came.values()), [1, -1, 1], atol=1e-6)
    assert np.allclose(list(goes.values()), [1, -1, 1] if branch == "continue" else [1, -3, -3], atol=1e-6)
    (named,) = d["change_points"]
    assert abs(named["input"] + 0.5) < 1e-6 and named["branch"] == branch


def test_a_sliding_contact_is_said_undecided_beyond_order_one_not_guessed():
    """The cam's contact rows have no closed-form series here: at a configuration where K keeps full row rank
    the point is regular at order 1; the analysis never claims an order it did not check."""
    mech = screwkin.load(ROBOTS / "cam_followers.urdf")
    la = local_analysis(mech, mech.generic_configurations()[0].q)
    assert (la.kind, la.order, la.certain) == ("regular", 1, True)


def test_stretched_fourbar_cannot_move_though_the_generic_rank_says_it_can():
    """Ground 0.3 with crank, coupler and rocker 0.1: 0.1 + 0.1 + 0.1 = 0.3, so the only assembly is the
    straight one.  Absolute angles th2, th3, th4 of the three bars (all 0, pointing along the ground):
    0.1 (e^{i th2} + e^{i th3} + e^{i th4}) = 0.3.  First order: v2 + v3 + v4 = 0 (ker K of dimension 2);
    second order: v2^2 + v3^2 + v4^2 = 0, definite: only v = 0.  Rigid (shaky), decided at order 2 -- while
    the assembled configurations the generic rank is taken over (near-solutions within the closure
    tolerance) have rank 2 and would say mobility 1: the note says which decides and why."""
    mech = screwkin.load(FOURBAR, args={"ground": 0.3, "crank": 0.1, "coupler": 0.1, "rocker": 0.1, "theta": 0.0})
    from screwkin.analysis.mobility import analyze_mobility

    r = analyze_mobility(mech)
    assert (r.mobility, r.generic_mobility, r.local.kind, r.local.infinitesimal_mobility) == (0, 1, "shaky", 2)
    assert any("would give mobility 1" in n and "finite mobility" in n for n in r.notes)


def test_the_same_change_point_in_se3_is_said_to_order_six_only(monkeypatch):
    """Written in se(3) (the planar rows not dropped), the folded four-bar's loop has 4 redundant rows at the
    change point, 3 of them (F_z, M_x, M_y) vanishing identically at order 2: the quadratic cone still
    gives the two tangents, but the theorem needs every row, so the answer is said to order 6 -- the same
    branches, with less certainty, never more."""
    import screwkin.analysis.local as local_module

    monkeypatch.setattr(local_module, "loop_system", lambda m, q: loop_system(m, q, reduce=False))
    mech = folded()
    la = local_module.local_analysis(mech, mech.generic_configurations()[0].q)
    assert (la.kind, la.finite_mobility, la.redundant_rows, la.identically_zero) == ("bifurcation", 1, 4, 3)
    assert (la.order, la.certain) == (mech.tolerances.local_order, False)
    names = mech.coordinate_names
    found = sorted(tuple(np.round(direction(b.tangent, names) / direction(b.tangent, names)[0], 9)) for b in la.branches)
    assert found == sorted([(1.0, -1.0, 1.0), (1.0, -3.0, -3.0)])


def test_zero_sets_of_quadratic_forms_by_hand():
    """The cone's zeros on ker K, for forms written by hand: y1^2 - y2^2 in R^3 vanishes on the planes
    y1 = y2 and y1 = -y2 (two linear candidates of dimension 2); y1^2 + y2^2 - y3^2 on a circular cone (one
    curved candidate of dimension 2); y1^2 + y2^2 + y3^2 nowhere; {y1 y2, y1 y3} together on the plane
    y1 = 0 (dimension 2, where the second form's gradient vanishes: degenerate) and the line y2 = y3 = 0
    (dimension 1, gradients (0, 1, 0) and (0, 0, 1): regular) -- two components of different dimensions."""
    from screwkin.analysis.local import _cone
    from screwkin.tolerances import DEFAULT

    def cone(*forms):
        return _cone(np.array(forms, float), 1e-9, 64, DEFAULT)

    planes = cone(np.diag([1.0, -1.0, 0.0]))
    assert [(c.T.shape[1], c.linear, c.regular) for c in planes] == [(2, True, True), (2, True, True)]
    normals = sorted(tuple(np.round(np.abs(np.linalg.svd(c.T.T)[2][-1]) * np.sqrt(2), 9)) for c in planes)
    assert normals == [(1.0, 1.0, 0.0), (1.0, 1.0, 0.0)]  # |normal| = (1, 1, 0)/sqrt 2 for y1 = +-y2
    (circular,) = cone(np.diag([1.0, 1.0, -1.0]))
    assert (circular.T.shape[1], circular.linear) == (2, False)
    assert cone(np.eye(3)) == []
    f1 = np.array([[0, 0.5, 0], [0.5, 0, 0], [0, 0, 0]])
    f2 = np.array([[0, 0, 0.5], [0, 0, 0], [0.5, 0, 0]])
    parts = sorted((c.T.shape[1], c.regular, c.linear) for c in cone(f1, f2))
    assert parts == [(1, True, True), (2, False, True)]
