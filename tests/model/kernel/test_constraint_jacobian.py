"""Constraint Jacobians against central finite differences of the closure residual.

Differences are taken on the configuration manifold with pin.integrate (joint
coordinates such as continuous joints' (cos, sin) pairs are not a vector
space), at closed configurations and at arbitrary ones: the rows are exact
derivatives everywhere, not only on the closure manifold.
"""

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import CORPUS

# A spatial test bench: two branches from the ground (R-R-P-R and R-R-R-continuous)
# whose tips are joined by one loop joint of every type in mechanism-format.md.
BENCH = """<robot name="bench">
  <link name="ground"/>
  <link name="a1"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="a2"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="a3"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="a4"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b1"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b2"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b3"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b4"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="ja1" type="revolute"><parent link="ground"/><child link="a1"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-9" upper="9" effort="1" velocity="1"/></joint>
  <joint name="ja2" type="revolute"><parent link="a1"/><child link="a2"/><origin xyz="0.2 0 0" rpy="0.3 0 0"/><axis xyz="0 1 0"/><limit lower="-9" upper="9" effort="1" velocity="1"/></joint>
  <joint name="ja3" type="prismatic"><parent link="a2"/><child link="a3"/><origin xyz="0 0.1 0.3"/><axis xyz="1 1 0"/><limit lower="-9" upper="9" effort="1" velocity="1"/></joint>
  <joint name="ja4" type="revolute"><parent link="a3"/><child link="a4"/><origin xyz="0.1 0 0" rpy="0 0.4 0.2"/><axis xyz="1 0 0"/><limit lower="-9" upper="9" effort="1" velocity="1"/></joint>
  <joint name="jb1" type="revolute"><parent link="ground"/><child link="b1"/><origin xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-9" upper="9" effort="1" velocity="1"/></joint>
  <joint name="jb2" type="revolute"><parent link="b1"/><child link="b2"/><origin xyz="0 0.2 0.1" rpy="0 0 0.5"/><axis xyz="1 0 0"/><limit lower="-9" upper="9" effort="1" velocity="1"/></joint>
  <joint name="jb3" type="revolute"><parent link="b2"/><child link="b3"/><origin xyz="0 0 0.3"/><axis xyz="0 1 1"/><limit lower="-9" upper="9" effort="1" velocity="1"/></joint>
  <joint name="jb4" type="continuous"><parent link="b3"/><child link="b4"/><origin xyz="0.1 0.1 0" rpy="0.1 0.2 0.3"/><axis xyz="0 0 1"/></joint>
  {loop}
</robot>"""

TYPES = ["fixed", "revolute", "continuous", "prismatic", "cylindrical", "universal", "planar", "spherical"]


def bench(tmp_path, jtype):
    axis2 = '<axis2 xyz="0 0 1"/>' if jtype == "universal" else ""
    loop = (f'<loop_joint name="cut" type="{jtype}"><link1 link="a4" xyz="0.05 0.02 0.1" rpy="0.2 -0.1 0.4"/>'
            f'<link2 link="b4" xyz="-0.03 0.04 0.02" rpy="-0.3 0.2 0.1"/><axis xyz="0.3 -0.5 0.8"/>{axis2}</loop_joint>')
    path = tmp_path / f"bench_{jtype}.urdf"
    path.write_text(BENCH.format(loop=loop))
    return screwkin.load(path)


def fd_jacobian(mech, q, solver, h=1e-6):
    model = mech.model
    cols = []
    for i in range(model.nv):
        e = np.zeros(model.nv)
        e[i] = h
        rp = mech.closure.evaluate(pin.integrate(model, q, e), jacobian=False, solver=solver)[0]
        rm = mech.closure.evaluate(pin.integrate(model, q, -e), jacobian=False, solver=solver)[0]
        cols.append((rp - rm) / (2 * h))
    return np.stack(cols, axis=1)


@pytest.mark.parametrize("jtype", TYPES)
@pytest.mark.parametrize("solver", [False, True])
def test_every_cut_type_matches_finite_differences(tmp_path, jtype, solver):
    mech = bench(tmp_path, jtype)
    rng = np.random.default_rng(7)
    for _ in range(3):
        # seeded (pin.randomConfiguration draws from a generator other tests move: the configurations, and
        # so the finite differences' error, changed with the tests run before); on the manifold for continuous
        q = pin.integrate(mech.model, pin.neutral(mech.model), rng.uniform(-1, 1, mech.nv))
        r, K = mech.closure.evaluate(q, solver=solver)
        assert K.shape == (len(r), mech.nv)
        np.testing.assert_allclose(K, fd_jacobian(mech, q, solver), rtol=0, atol=2e-7)


@pytest.mark.parametrize("jtype", TYPES)
def test_rows_per_type_are_six_minus_dof(tmp_path, jtype):
    mech = bench(tmp_path, jtype)
    dof = {"fixed": 0, "revolute": 1, "continuous": 1, "prismatic": 1, "cylindrical": 2,
           "universal": 2, "planar": 3, "spherical": 3}[jtype]
    assert mech.closure.nrows == 6 - dof


@pytest.mark.parametrize("jtype", TYPES)
def test_assembled_bench_satisfies_its_joint_geometry(tmp_path, jtype):
    """After assembly, F2 relative to F1 is a motion the joint allows (checked
    here from the placements directly, not from the residual rows)."""
    mech = bench(tmp_path, jtype)
    a = mech.assemble()
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, a.q)
    cut = mech.cuts[0]
    T = data.oMf[cut.frame1].inverse() * data.oMf[cut.frame2]
    axis = np.asarray(cut.axis)
    p, R = T.translation, T.rotation
    perp = p - (p @ axis) * axis
    checks = {
        "fixed": [p, R - np.eye(3)],
        "revolute": [p, R @ axis - axis],
        "continuous": [p, R @ axis - axis],
        "prismatic": [perp, R - np.eye(3)],
        "cylindrical": [perp, R @ axis - axis],
        "universal": [p, [axis @ (R @ np.asarray(cut.axis2 or (0, 0, 1)))]],
        "planar": [[p @ axis], R @ axis - axis],
        "spherical": [p],
    }[jtype]
    for c in checks:
        np.testing.assert_allclose(np.asarray(c, float), 0.0, rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", ["cassie_like", "robot_delta", "5bar_linkage_iso3d"])
def test_corpus_jacobian_on_the_manifold(name):
    """At an assembled configuration of a real file, K equals the finite
    differences of the closure residual, and K annihilates the tangent motions."""
    mech = screwkin.load(CORPUS / name / "robot.urdf", warn=lambda m: None)
    q = mech.assemble().q
    K = mech.closure.jacobian(q)
    np.testing.assert_allclose(K, fd_jacobian(mech, q, False), rtol=0, atol=2e-7)
    # a step along the null space of K stays closed to second order
    _, s, vt = np.linalg.svd(K)
    v = vt[-1]
    for h in (1e-3, 1e-4):
        r = mech.closure.residual(pin.integrate(mech.model, q, h * v))
        assert np.linalg.norm(r) < 50 * h * h


@pytest.mark.parametrize("jtype", TYPES)
def test_bias_term_matches_finite_differences_of_K_v(tmp_path, jtype):
    """K'(q, v) v at an assembled configuration equals the central difference
    of K(q(t)) v along q(t) = q (+) t v (straight lines in these coordinates)."""
    mech = bench(tmp_path, jtype)
    q = mech.assemble().q
    rng = np.random.default_rng(3)
    v = rng.normal(size=mech.nv)
    h = 1e-5
    Kp = mech.closure.jacobian(pin.integrate(mech.model, q, h * v))
    Km = mech.closure.jacobian(pin.integrate(mech.model, q, -h * v))
    expected = (Kp - Km) @ v / (2 * h)
    np.testing.assert_allclose(mech.closure.bias(q, v), expected, rtol=0, atol=1e-6 * max(1, np.abs(expected).max()))


def test_many_cut_joints_of_mixed_types_are_each_their_own_rows(tmp_path):
    """From three cut joints of one type on, they are evaluated together with stacked arrays
    (fewer, one at a time with 2-D arrays): three of every type, in mixed order and with
    different axes and frames, give for each cut joint the rows it gives alone, and a
    Jacobian equal to finite differences."""
    from screwkin.model.kernel.closure import ClosureSystem

    rng = np.random.default_rng(11)
    loops = []
    for k, jtype in enumerate(TYPES + TYPES[::-1] + TYPES):
        axis = rng.normal(size=3)
        axis2 = '<axis2 xyz="{:.3f} {:.3f} {:.3f}"/>'.format(*np.cross(axis, rng.normal(size=3))) \
            if jtype == "universal" else ""
        x1, x2, r1, r2 = (rng.uniform(-0.1, 0.1, 3) for _ in range(4))
        loops.append(f'<loop_joint name="cut{k}" type="{jtype}">'
                     f'<link1 link="a4" xyz="{x1[0]} {x1[1]} {x1[2]}" rpy="{r1[0]} {r1[1]} {r1[2]}"/>'
                     f'<link2 link="b4" xyz="{x2[0]} {x2[1]} {x2[2]}" rpy="{r2[0]} {r2[1]} {r2[2]}"/>'
                     f'<axis xyz="{axis[0]} {axis[1]} {axis[2]}"/>{axis2}</loop_joint>')
    path = tmp_path / "many.urdf"
    path.write_text(BENCH.format(loop="".join(loops)))
    mech = screwkin.load(path)
    assert len(mech.cuts) == 24 and all(len(g["members"]) == 3 for g in mech.closure._groups)
    q = pin.integrate(mech.model, pin.neutral(mech.model), rng.uniform(-1, 1, mech.nv))
    for solver in (False, True):
        r, K = mech.closure.evaluate(q, solver=solver)
        np.testing.assert_allclose(K, fd_jacobian(mech, q, solver), rtol=0, atol=3e-7)
        i = 0
        for cut in mech.cuts:
            alone = ClosureSystem(mech.model, [cut])
            r1, K1 = alone.evaluate(q, solver=solver)
            np.testing.assert_allclose(r[i:i + len(r1)], r1, rtol=0, atol=1e-15)
            np.testing.assert_allclose(K[i:i + len(r1)], K1, rtol=0, atol=1e-15)
            i += len(r1)
        assert i == len(r)
