"""The batched structure-equation Jacobians against Pinocchio's, one configuration at a time."""

import numpy as np
import pinocchio as pin
import pytest
from conftest import LINK, ROBOTS, rev

import screwkin
from screwkin.batch import SerialJacobians, determinants, smallest_singular_values
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
    Q = np.array([pin.randomConfiguration(mech.model) for _ in range(500)])
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
            assert np.abs((s - s_ref) / s_ref)[10:].max() < 1e-9
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
    Q = pin.randomConfiguration(mech.model)[None]
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
