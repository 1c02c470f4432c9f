"""Product-of-exponentials structure equations and Jacobians, against Pinocchio and closed forms."""

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import CORPUS, DATA, fourbar
from screwkin.analysis.screws import chains, planar_form, poe, screw_of, split_jacobians, structure


@pytest.mark.parametrize("name", ["cassie_like", "digit_like", "robot_delta", "talos_like"])
def test_poe_reproduces_pinocchio_placements(name):
    mech = screwkin.load(CORPUS / name / "robot.urdf", warn=lambda m: None)
    rng = np.random.default_rng(2)
    for _ in range(3):
        q = pin.integrate(mech.model, mech.neutral(), rng.uniform(-1, 1, mech.nv))
        for st in structure(mech, q):
            np.testing.assert_allclose(poe(st["chain"], st["theta"]), st["g"], rtol=0, atol=1e-12)


def test_current_twists_are_adjoint_transported_reference_twists():
    """xi'_i = Ad(exp(xi_1 th_1) ... exp(xi_{i-1} th_{i-1})) xi_i (Murray, Li, Sastry 3.54),
    and the body Jacobian is Ad(g^-1) times the space Jacobian."""
    mech = screwkin.load(CORPUS / "cassie_like" / "robot.urdf", warn=lambda m: None)
    q = pin.integrate(mech.model, mech.neutral(), np.random.default_rng(4).uniform(-1, 1, mech.nv))
    for st in structure(mech, q, output="foot_2"):
        ch, th = st["chain"], st["theta"]
        M = pin.SE3.Identity()
        for k in range(len(ch.joints)):
            np.testing.assert_allclose(M.toActionMatrix() @ ch.xi0[:, k], st["space_jacobian"][:, k], atol=1e-12)
            M = M * pin.exp6(pin.Motion(ch.xi0[:, k] * th[k]))
        g = pin.SE3(st["g"])
        np.testing.assert_allclose(g.inverse().toActionMatrix() @ st["space_jacobian"], st["body_jacobian"], atol=1e-12)


def test_revolute_twist_and_planar_form(tmp_path):
    """A revolute about z through (x, y): xi = (y, -x, 0, 0, 0, 1), planar (y, -x, 1), pitch 0."""
    p = tmp_path / "fb.urdf"
    p.write_text(fourbar())
    mech = screwkin.load(p)
    ch = next(c for c in chains(mech) if c.name.endswith("@F2"))  # the rocker chain
    xi = ch.xi0[:, 0]
    np.testing.assert_allclose(xi, [0, -0.1, 0, 0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(planar_form(xi, [0, 0, 1]), [0, -0.1, 1], atol=1e-15)
    # in the x-z plane (normal +y) the plane's axes are those of every planar output (geometry.plane_basis):
    # e1 = x, e2 = y x x = -z; a revolute about y through (0.1, 0, 0.2): v = -w x p = (-0.2, 0, 0.1),
    # so (v.e1, v.e2, w.n) = (-0.2, -0.1, 1)
    p_y = np.array([0.1, 0.0, 0.2])
    xi_y = np.r_[-np.cross([0.0, 1.0, 0.0], p_y), 0.0, 1.0, 0.0]
    np.testing.assert_allclose(planar_form(xi_y, [0, 1, 0]), [-0.2, -0.1, 1], atol=1e-15)
    s = screw_of(xi)
    assert s.pitch == 0 and np.allclose(s.point, [0.1, 0, 0])
    assert screw_of([1, 0, 0, 0, 0, 0]).pitch == np.inf


def test_forward_jacobian_of_a_four_bar_against_finite_differences(tmp_path):
    from screwkin.analysis.position.position import PositionSolver

    p = tmp_path / "fb.urdf"
    p.write_text(fourbar())
    mech = screwkin.load(p, actuated=["crank_joint"])
    solver = PositionSolver(mech, ["crank_joint"], output="rocker")
    s = solver.solve({"crank_joint": 0.4}).solutions[0]
    J = split_jacobians(mech, s.q, "rocker")
    h = 1e-6
    a = solver.solve({"crank_joint": 0.4 + h}, near=s.joints).solutions[0]
    b = solver.solve({"crank_joint": 0.4 - h}, near=s.joints).solutions[0]
    Ma, Mb = pin.SE3(a.output_pose), pin.SE3(b.output_pose)
    w_fd = pin.log3(Ma.rotation @ Mb.rotation.T) / (2 * h)
    np.testing.assert_allclose(J["forward"][3:, 0], w_fd, atol=1e-6)
    assert J["inverse"] is not None  # a rocker angle fixes the crank angle of this circuit
    np.testing.assert_allclose(J["inverse"] @ J["forward"], np.eye(1), atol=1e-9)


def test_batched_singular_values_match_one_by_one():
    """The vectorized path (a stack of Jacobians, one SVD call) gives the per-configuration
    values, and finds the wrist singularity of the 6R arm (theta5 = 0)."""
    from conftest import ROBOTS
    from screwkin.analysis.singularities.batch import frame_jacobians, smallest_singular_values

    mech = screwkin.load(ROBOTS / "arm_6r.urdf")
    rng = np.random.default_rng(0)
    Q = rng.uniform(-2, 2, (200, 6))
    Q[:10, 4] = 0.0
    fid = mech.link_frame("flange")
    J = frame_jacobians(mech.model, fid, Q)
    s = smallest_singular_values(J, scale_translation=0.5)
    for k in (0, 50, 199):
        Jk = pin.computeFrameJacobian(mech.model, mech.model.createData(), Q[k], fid, pin.ReferenceFrame.WORLD).copy()
        Jk[:3] /= 0.5
        assert abs(np.linalg.svd(Jk, compute_uv=False)[-1] - s[k]) < 1e-12
    assert (s[:10] < 1e-12).all() and (s[10:] > 1e-6).all()


def test_every_joint_of_a_loop_the_cut_joint_included(capsys):
    """issue 25 item 4: the R-R-P-R loop of tests/data/student/rrpr.urdf (A at the origin, B at the crank tip
    (0.1, 0), D at (0.1, 0), the slide cut along x): the loop lists D, the cut slide, then B and A backwards,
    with the twists written by hand, and the product of their exponentials is the identity at solved
    configurations (Pinocchio's exp6, the cut joint's value from the kinematic state)."""
    import json

    import numpy as np
    import pinocchio as pin

    from screwkin import load
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.analysis.screws import loop_product, loop_screws
    from screwkin.cli import main
    from screwkin.model.state import KinematicState

    path = str(DATA / "student" / "rrpr.urdf")
    mech = load(path)
    (loop,) = loop_screws(mech)
    assert loop.joints == ("D", "slide", "B", "A") and loop.signs == (1, 1, -1, -1) and loop.closed_at_reference
    by_hand = {"D": [0, -0.1, 0, 0, 0, 1], "slide": [1, 0, 0, 0, 0, 0], "B": [0, -0.1, 0, 0, 0, 1],
               "A": [0, 0, 0, 0, 0, 1]}  # revolute (-w x p, w), prismatic (v, 0)
    for k, name in enumerate(loop.joints):
        np.testing.assert_allclose(loop.xi0[:, k], by_hand[name], atol=1e-12)
    cut = mech.cuts[0]
    for a in (0.4, 1.3, -2.0):
        for sol in PositionSolver(mech, ["A"]).solve({"A": a}).solutions:
            dq = dict(zip(mech.coordinate_names, pin.difference(mech.model, mech.neutral(), sol.q), strict=True))
            theta = [KinematicState(mech, sol.q).loop_value(cut) if n == "slide" else dq[n] for n in loop.joints]
            np.testing.assert_allclose(loop_product(loop, theta), np.eye(4), atol=1e-9)
    assert main(["screws", path, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert [j["joint"] for j in d["loops"][0]["joints"]] == ["D", "slide", "B", "A"]
    assert d["loops"][0]["joints"][1]["cut"] is True
    assert d["loops"][0]["joints"][0]["xi0_planar"] == pytest.approx([0, -0.1, 1])
    assert main(["screws", path]) == 0
    assert "exp([xi_D] th_D) exp([xi_slide] th_slide) exp(-[xi_B] th_B) exp(-[xi_A] th_A) = I" in \
        capsys.readouterr().out
