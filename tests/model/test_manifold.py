"""model.manifold.Integrator: pin.integrate for stacks of configurations, joint type by joint type,
against Pinocchio's own pin.integrate one configuration at a time (the reference), on random stacks
of every joint type Pinocchio's URDF and MJCF parsers build."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from screwkin.model.manifold import Integrator, continuous_angle, set_continuous_angle


def every_joint_type():
    """A chain of one joint of each type (random placements between them): vector spaces (revolute,
    prismatic, helical, translation, spherical ZYX, universal), SO(2) (continuous joints), SO(3)
    (ball joints), SE(3) (free flyer) and SE(2) (planar)."""
    model = pin.Model()
    rng = np.random.default_rng(7)
    joints = [pin.JointModelRX(), pin.JointModelRUBZ(), pin.JointModelPY(), pin.JointModelRevoluteUnaligned(0.6, 0.8, 0.0),
              pin.JointModelSpherical(), pin.JointModelFreeFlyer(), pin.JointModelPlanar(),
              pin.JointModelTranslation(), pin.JointModelSphericalZYX(), pin.JointModelRevoluteUnboundedUnaligned(),
              pin.JointModelHX(0.1), pin.JointModelPrismaticUnaligned(np.array([0.0, 0.6, 0.8])),
              pin.JointModelUniversal(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])),
              pin.JointModelRUBX(), pin.JointModelSpherical()]
    parent = 0
    for k, joint in enumerate(joints):
        M = pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3))
        parent = model.addJoint(parent, joint, M, f"j{k}")
    return model


def reference(model, Q, V):
    return np.array([pin.integrate(model, q, v) for q, v in zip(Q, V)])


def random_stack(model, n, scale, rng):
    Q = np.array([pin.randomConfiguration(model, -3.0 * np.ones(model.nq), 3.0 * np.ones(model.nq)) for _ in range(n)])
    V = scale * rng.normal(size=(n, model.nv))
    V[::5] = 0.0  # no motion at all
    ball, free = model.idx_vs[model.getJointId("j4")], model.idx_vs[model.getJointId("j5")]
    V[1::7, ball:ball + 3] = 0.0  # a ball joint that does not turn (the Taylor branch of exp3)
    V[2::7, free + 3:free + 6] = 1e-9  # the free flyer turning by a hair (the Taylor branch of exp6)
    return Q, V


@pytest.mark.parametrize("scale", [1e-9, 1e-3, 0.5, 3.0])
def test_every_joint_type_integrates_as_pinocchio_does(scale):
    model = every_joint_type()
    integrator = Integrator(model)
    assert set(integrator.groups) == {"so2", "so3", "se3", "se2"} and not integrator.per_configuration
    rng = np.random.default_rng(int(scale * 1e9) % 1000)
    Q, V = random_stack(model, 400, scale, rng)
    got = integrator(Q, V)
    np.testing.assert_allclose(got, reference(model, Q, V), rtol=0, atol=1e-15)


def test_a_stack_of_one_and_a_vector_space():
    """One configuration: Pinocchio itself.  Only revolute and prismatic joints: Q + V, the same
    floating-point operation as Pinocchio's vector-space integrate (equal bit for bit)."""
    model = every_joint_type()
    rng = np.random.default_rng(3)
    Q, V = random_stack(model, 1, 0.7, rng)
    np.testing.assert_array_equal(Integrator(model)(Q, V), reference(model, Q, V))
    chain = pin.Model()
    parent = 0
    for k, joint in enumerate([pin.JointModelRZ(), pin.JointModelPX(), pin.JointModelRevoluteUnaligned(0.0, 0.6, 0.8)]):
        parent = chain.addJoint(parent, joint, pin.SE3.Random(), f"c{k}")
    integrator = Integrator(chain)
    assert integrator.plain
    Q, V = rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    np.testing.assert_array_equal(integrator(Q, V), reference(chain, Q, V))


def test_a_joint_the_numpy_forms_do_not_cover_integrates_one_configuration_at_a_time():
    """A composite joint (RZ then PX in one joint): Pinocchio's integrate for each configuration."""
    model = pin.Model()
    composite = pin.JointModelComposite(2)
    composite.addJoint(pin.JointModelRZ())
    composite.addJoint(pin.JointModelPX())
    j = model.addJoint(0, pin.JointModelSpherical(), pin.SE3.Random(), "ball")
    model.addJoint(j, composite, pin.SE3.Random(), "composite")
    integrator = Integrator(model)
    assert integrator.per_configuration
    rng = np.random.default_rng(5)
    Q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq)) for _ in range(6)])
    V = rng.normal(size=(6, model.nv))
    np.testing.assert_array_equal(integrator(Q, V), reference(model, Q, V))


def test_continuous_joint_coordinates_as_pinocchio_writes_them():
    """A continuous joint's (cos, sin): the angle written is pin.integrate's from the neutral (1, 0), and
    the angle read back is the one integrated, in (-pi, pi] (a half turn reads as +pi)."""
    model = pin.Model()
    model.addJoint(0, pin.JointModelPX(), pin.SE3.Identity(), "slide")
    model.addJoint(1, pin.JointModelRUBZ(), pin.SE3.Identity(), "wheel")
    i = model.idx_qs[2]
    angles = np.array([0.3, -2.5, np.pi, 7.0])
    Q = np.array([pin.integrate(model, pin.neutral(model), np.array([0.1, a])) for a in angles])
    np.testing.assert_allclose(continuous_angle(Q, i), [0.3, -2.5, np.pi, 7.0 - 2 * np.pi], rtol=0, atol=1e-14)
    assert continuous_angle(Q[2], i) == pytest.approx(np.pi, abs=1e-15)
    mine = np.tile(pin.neutral(model), (len(angles), 1))
    mine[:, 0] = 0.1
    set_continuous_angle(mine, i, angles)  # a stack, one angle per row
    np.testing.assert_allclose(mine, Q, rtol=0, atol=1e-15)
    q = pin.neutral(model)
    set_continuous_angle(q, i, -2.5)  # one configuration
    np.testing.assert_allclose(q, pin.integrate(model, pin.neutral(model), np.array([0.0, -2.5])), rtol=0, atol=1e-15)

