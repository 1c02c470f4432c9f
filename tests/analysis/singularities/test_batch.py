"""The batched structure-equation Jacobians against Pinocchio's, one configuration at a time."""

import numpy as np
import pinocchio as pin
import pytest
from conftest import LINK, ROBOTS, rev

import screwkin
from screwkin.analysis.singularities.batch import SerialJacobians, determinants, smallest_singular_values
from screwkin.errors import UsageError

REFS = (pin.ReferenceFrame.WORLD, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED, pin.ReferenceFrame.LOCAL)


def pinocchio_jacobians(mech, frame, Q, reference):
    data = mech.model.createData()
    return np.array([pin.computeFrameJacobian(mech.model, data, q, frame, reference) for q in Q])


def skewed_arm(tmp_path):
    """Revolute joints about oblique axes, a prismatic joint, a continuous joint, an
    offset tool frame and a side branch that is not in the chain."""
    body = "".join(LINK.format(n=n) for n in ("base", "a", "b", "c", "d", "e", "tool", "side"))
    body += rev("j1", "base", "a", axis="0.3 -0.2 0.9", xyz="0.1 0 0.2", rpy="0.2 0 0")
    body += rev("j2", "a", "b", axis="0 1 0", xyz="0 0.05 0.3", rpy="0 0.4 -0.3")
    body += rev("slide", "b", "c", axis="1 1 0", xyz="0.2 0 0", jtype="prismatic")
    body += rev("j3", "c", "d", axis="1 0 0", xyz="0.1 -0.1 0", rpy="1.0 0.2 0.1", jtype="continuous")
    body += rev("j4", "d", "e", axis="0 0 -1", xyz="0 0 0.15")
    body += rev("side_joint", "a", "side", axis="1 0 0", xyz="0 0.3 0")
    body += '<joint name="flange" type="fixed"><parent link="e"/><child link="tool"/>' \
            '<origin xyz="0.05 0.02 0.1" rpy="0.3 -0.2 0.5"/></joint>'
    path = tmp_path / "skewed.urdf"
    path.write_text(f'<robot name="skewed">{body}</robot>')
    return screwkin.load(path)


@pytest.mark.parametrize("reference", REFS)
def test_arm_6r_matches_pinocchio(reference):
    mech = screwkin.load(ROBOTS / "arm_6r.urdf")
    Q = np.random.default_rng(1).uniform(-np.pi, np.pi, (3000, 6))
    Q[:20] = 0.0  # the reference configuration itself, where the half-angle tangents are zero
    Q[20:40, 2] = np.pi  # a half-turn: tan(pi / 2) is huge, sin and 1 - cos must still come out right
    sj = SerialJacobians(mech, "flange", reference, block=1000)  # several blocks and a short last one
    J = sj(Q)
    ref = pinocchio_jacobians(mech, sj.frame, Q, reference)
    assert np.abs(J - ref).max() < 1e-13


@pytest.mark.parametrize("reference", REFS)
def test_oblique_prismatic_continuous_chain(tmp_path, reference):
    mech = skewed_arm(tmp_path)
    rng = np.random.default_rng(5)  # (a continuous joint has no limits: Pinocchio's sampler refuses it)
    Q = np.array([mech.random_configuration(rng) for _ in range(500)])
    sj = SerialJacobians(mech, "tool", reference, block=128)
    J = sj(Q)
    ref = pinocchio_jacobians(mech, sj.frame, Q, reference)
    assert np.abs(J - ref).max() < 1e-13
    side = mech.velocity_indices(["side_joint"])
    assert not J[:, :, side].any()  # a joint off the chain moves nothing


def test_measures_match_per_configuration_linear_algebra():
    """det and sigma_min of each Jacobian, against numpy on Pinocchio's Jacobian; the wrist
    singularity of the arm (theta5 = 0) gives zero for both."""
    mech = screwkin.load(ROBOTS / "arm_6r.urdf")
    Q = np.random.default_rng(3).uniform(-np.pi, np.pi, (2000, 6))
    Q[:10, 4] = 0.0
    sj = SerialJacobians(mech, "flange", block=300)
    ref = pinocchio_jacobians(mech, sj.frame, Q, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    scaled = ref.copy()
    scaled[:, :3] /= 0.4
    s_ref = np.linalg.svd(scaled, compute_uv=False)[:, -1]
    d_ref = np.linalg.det(ref)
    for workers in (1, 2):
        d = sj.measures(Q, "det", workers=workers)
        assert np.abs(d - d_ref).max() < 1e-14
        for method in ("svd", "gram"):
            s = sj.measures(Q, "sigma_min", scale_translation=0.4, workers=workers, method=method)
            assert np.abs(s - s_ref).max() < 1e-12
            assert np.abs((s - s_ref)[10:] / s_ref[10:]).max() < 1e-9  # (the first ten are singular: s_ref 0)
    assert (np.abs(d[:10]) < 1e-14).all() and (s[:10] < 1e-12).all()
    np.testing.assert_allclose(determinants(ref), d_ref, rtol=0, atol=0)


def test_gram_method_falls_back_to_svd_near_singular():
    rng = np.random.default_rng(4)
    U, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    V, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    sig = np.array([2.0, 1.0, 0.5, 0.1, 1e-2, 1e-9])  # sigma_min / sigma_max = 5e-10: the Gram route has no digits
    J = (U * sig) @ V.T
    s = smallest_singular_values(J[None], method="gram")
    assert abs(s[0] - 1e-9) < 1e-15
    with pytest.raises(UsageError, match="unknown method"):
        smallest_singular_values(J[None], method="qr")


def test_refusals(tmp_path):
    mech = skewed_arm(tmp_path)
    sj = SerialJacobians(mech, "tool")
    Q = mech.random_configuration(np.random.default_rng(0))[None]
    with pytest.raises(UsageError, match="square"):  # five chain joints: 6 x 5
        sj.measures(Q, "det")
    with pytest.raises(UsageError, match="unknown measure"):
        sj.measures(Q, "volume")
    with pytest.raises(ValueError, match="shape"):
        sj(np.zeros((3, 2)))
    planar = tmp_path / "planar.urdf"
    planar.write_text('<robot name="p">' + LINK.format(n="a") + LINK.format(n="b")
                      + rev("j", "a", "b", jtype="planar").replace("<limit", "<!-- ").replace("/></joint>", "--></joint>")
                      + "</robot>")
    with pytest.raises(UsageError, match="3 DOF"):
        SerialJacobians(screwkin.load(planar), "b")


def test_scan_det_is_the_spherical_wrist_factorization():
    """arm_6r has a spherical wrist (axes 4, 5, 6 meet at the wrist centre w): the Jacobian
    at w is block triangular, so |det J| = |det[z_i x (w - p_i)], i = 1..3| |det[z4 z5 z6]|,
    computed here from Pinocchio's joint placements."""
    from screwkin.analysis.singularities.scan import scan

    mech = screwkin.load(ROBOTS / "arm_6r.urdf")
    res = scan(mech, "flange", samples=3000, seed=7, measure="det")
    data = mech.model.createData()
    closed = []
    for q in res.Q:
        pin.forwardKinematics(mech.model, data, q)
        z = [data.oMi[j].rotation[:, "XYZ".index(mech.model.joints[j].shortname()[-1])] for j in range(1, 7)]
        p = [data.oMi[j].translation for j in range(1, 7)]
        w = p[4]  # joint 5's origin: the wrist centre
        arm = np.linalg.det(np.column_stack([np.cross(z[i], w - p[i]) for i in range(3)]))
        wrist = np.linalg.det(np.column_stack(z[3:]))
        closed.append(arm * wrist)
    closed = np.abs(closed)
    assert len(closed) == len(res.values) == 3000
    np.testing.assert_allclose(np.abs(res.values), closed, rtol=0, atol=1e-13)
    # the configuration reported nearest a singularity is the one of smallest |det J| in closed form
    assert res.worst == int(np.argmin(closed)) and closed[res.worst] < 1e-2 * np.median(closed)


def test_scan_sigma_ratio_matches_pinocchio_and_cli(tmp_path, capsys):
    import json

    from screwkin.cli import main
    from screwkin.analysis.singularities.scan import scan

    mech = screwkin.load(ROBOTS / "arm_6r.urdf")
    res = scan(mech, "flange", samples=2000, seed=3, length=0.3)
    ref = pinocchio_jacobians(mech, mech.link_frame("flange"), res.Q, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    ref[:, :3] /= 0.3
    s = np.linalg.svd(ref, compute_uv=False)
    ratio = s[:, -1] / s[:, 0]
    assert len(ratio) == len(res.values) == 2000
    np.testing.assert_allclose(res.values, ratio, rtol=1e-12, atol=1e-15)
    # "singular" is the tolerances' threshold (Tolerances.singular), not a number of the scan's own
    threshold = mech.tolerances.singular
    assert res.threshold == threshold
    assert main(["scan", str(ROBOTS / "arm_6r.urdf"), "--output", "flange", "--samples", "2000", "--seed", "3",
                 "--length", "300mm", "--json", "--csv", str(tmp_path / "s.csv")]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["min"] == float(res.values[res.worst]) == pytest.approx(ratio.min(), rel=1e-12) and d["samples"] == 2000
    assert d["singular_fraction"] == float(np.mean(ratio < threshold))
    lines = (tmp_path / "s.csv").read_text().splitlines()
    assert len(lines) == 2001 and lines[0] == "joint1,joint2,joint3,joint4,joint5,joint6,sigma_ratio"


def test_scan_refusals(tmp_path, capsys):
    from conftest import fourbar
    from screwkin.cli import main

    fb = tmp_path / "fb.urdf"
    fb.write_text(fourbar())
    assert main(["scan", str(fb), "--output", "rocker"]) == 2
    assert "closed loop" in capsys.readouterr().err
    assert main(["scan", str(ROBOTS / "arm_6r.urdf"), "--output", "link3", "--measure", "det"]) == 2
    assert "3 joints" in capsys.readouterr().err
    slide = tmp_path / "slide.urdf"
    slide.write_text('<robot name="s">' + LINK.format(n="a") + LINK.format(n="b")
                     + '<joint name="j" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/>'
                       '<limit lower="0" upper="0" effort="1" velocity="1"/></joint></robot>')
    assert main(["scan", str(slide), "--output", "b"]) == 2
    assert "no finite <limit> range" in capsys.readouterr().err  # URDF requires <limit> here; 0..0 is no range
