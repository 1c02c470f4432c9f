"""One kinematic state for every reader (issue 37 item 3): the large-model path, where every state
reads the mechanism's one Data (Mechanism.shares_data, past SHARED_DATA_NV coordinates), gives the
numbers of the per-thread path and of Pinocchio's own algorithms run alone; two states read one after
the other never read each other's placements; place_tool leaves the model as it was.

References: Pinocchio's forward kinematics, frame Jacobians, velocities and classical accelerations
in a Data made for the check (nothing else runs in it), the velocity of a point as the central
difference of its positions along the motion (pin.integrate), and the frame a tool is, added to a
copy of the model by hand (pinocchio.Model.addFrame) -- the way place_tool worked before.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import screwkin
import screwkin.model.mechanism as mechanism
from conftest import ROBOTS
from screwkin.analysis.forces.statics import statics
from screwkin.model.kernel.stacks import TreeKinematics
from screwkin.analysis.position.position import PositionSolver
from screwkin.model.state import KinematicState, model_with_output, place_tool

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
N_CHAIN = mechanism.SHARED_DATA_NV + 5  # joints: past the threshold as the loader builds it, nothing lowered


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    """A serial chain of N_CHAIN revolutes, their axes z, y, x in turn, each link 5 cm on and 1 cm aside
    turned 0.1 rad: a spatial chain whose every frame moves."""
    axes = ("0 0 1", "0 1 0", "1 0 0")
    links = "".join(f'<link name="l{k}"/>' for k in range(N_CHAIN + 1))
    joints = "".join(
        f'<joint name="j{k}" type="revolute"><parent link="l{k - 1}"/><child link="l{k}"/>'
        f'<origin xyz="0.05 0.01 0" rpy="0 0 0.1"/><axis xyz="{axes[k % 3]}"/>'
        '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>' for k in range(1, N_CHAIN + 1))
    path = tmp_path_factory.mktemp("chain") / "chain.urdf"
    path.write_text(f'<?xml version="1.0"?><robot name="chain">{links}{joints}</robot>')
    return screwkin.load(path)


def _motion(mech, seed):
    rng = np.random.default_rng(seed)
    return (pin.normalize(mech.model, rng.uniform(-1.0, 1.0, mech.nq)), rng.normal(size=mech.nv),
            rng.normal(size=mech.nv))


def _reference(mech, q, v, a, fid):
    """Pinocchio's placement, frame Jacobian, velocity and classical acceleration of frame fid, alone."""
    model = mech.model
    data = model.createData()
    pin.forwardKinematics(model, data, q, v, a)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    return (data.oMf[fid].homogeneous.copy(), pin.getFrameJacobian(model, data, fid, LWA).copy(),
            pin.getFrameVelocity(model, data, fid, LWA).vector.copy(),
            pin.getFrameClassicalAcceleration(model, data, fid, LWA).vector.copy())


def _read(state, fid):
    return state.frame_pose(fid), state.frame_jacobian(fid), state.frame_twist(fid), state.frame_acceleration(fid)


def test_a_chain_past_the_threshold_shares_the_data_and_reads_what_pinocchio_computes(chain):
    mech = chain
    assert mech.nv > mechanism.SHARED_DATA_NV and mech.shares_data
    tip, middle = mech.link_frame(f"l{N_CHAIN}"), mech.link_frame(f"l{N_CHAIN // 2}")
    (q1, v1, a1), (q2, v2, a2) = _motion(mech, 1), _motion(mech, 2)
    s1, s2 = KinematicState(mech, q1, v1, a1), KinematicState(mech, q2, v2, a2)
    # one after the other, every quantity, each state reading the shared Data after the other wrote it
    first = _read(s1, tip)
    second = _read(s2, tip)
    again = (s1.frame_pose(tip), s2.frame_jacobian(middle), s1.frame_jacobian(middle), s1.frame_twist(tip))
    for got, ref in zip(first, _reference(mech, q1, v1, a1, tip), strict=True):
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12)
    for got, ref in zip(second, _reference(mech, q2, v2, a2, tip), strict=True):
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(again[0], first[0])  # s1 after s2: its own placements, not s2's
    np.testing.assert_array_equal(again[3], first[2])
    np.testing.assert_allclose(again[1], _reference(mech, q2, v2, a2, middle)[1], rtol=0, atol=1e-12)
    np.testing.assert_allclose(again[2], _reference(mech, q1, v1, a1, middle)[1], rtol=0, atol=1e-12)
    assert np.abs(first[0] - second[0]).max() > 0.1  # (the two configurations place the tip apart)
    # what a state returned is its own: reading another state does not change it
    held = s1.link_motion(f"l{N_CHAIN}")
    kept = {k: v.copy() for k, v in held.items()}
    s2.link_motion(f"l{N_CHAIN}")
    for k in kept:
        np.testing.assert_array_equal(held[k], kept[k])


def test_the_shared_path_gives_the_per_thread_paths_numbers(chain, monkeypatch):
    mech = chain
    q, v, a = _motion(mech, 3)
    local = (0.02, -0.01, 0.03)
    links = [f"l{k}" for k in (1, N_CHAIN // 3, N_CHAIN)]

    def everything():
        s = KinematicState(mech, q, v, a)
        out = [s.joint_placement(7).homogeneous, s.centre(("mount", 9)), s.joint_twists(N_CHAIN)]
        for link in links:
            p = s.point(link, local)
            out += [s.link_pose(link), s.link_jacobian(link), s.link_jacobian(link, pin.ReferenceFrame.WORLD),
                    p.position, p.velocity, p.acceleration]
        return out

    shared = everything()
    monkeypatch.setattr(mechanism, "SHARED_DATA_NV", 10 * N_CHAIN)  # the same mechanism, a Data per thread
    assert not mech.shares_data
    own = everything()
    for x, y in zip(shared, own, strict=True):
        np.testing.assert_allclose(x, y, rtol=0, atol=1e-14)
    # the point's velocity is the central difference of its positions along the motion
    h = 1e-6
    p = [KinematicState(mech, pin.integrate(mech.model, q, s * h * v)).point(links[-1], local).position
         for s in (-1, 1)]
    np.testing.assert_allclose(shared[-2], (p[1] - p[0]) / (2 * h), rtol=0, atol=1e-6)


@pytest.mark.parametrize("name, inputs, output", [("fourbar_crank_rocker.urdf", {"crank_joint": 0.7}, "rocker"),
                                                  ("five_bar.urdf", {"motor1": 1.9, "motor2": 1.1}, "distal1")])
def test_a_loop_mechanism_on_the_shared_data_solves_as_on_its_own(name, inputs, output, monkeypatch):
    """With the threshold lowered before loading, the closure's Newton loop, the states and statics all
    run in the mechanism's one Data, one after the other: every number as on the per-thread path."""

    def run():
        mech = screwkin.load(ROBOTS / name)
        res = PositionSolver(mech, list(inputs), output=output).solve(inputs, rates={k: 1.0 for k in inputs})
        s = res.solutions[0]
        st = statics(mech, s.q, output=output, wrench=(1.0, 2.0, 0.0, 0.0, 0.0, 0.5))
        loops = KinematicState(mech, s.q, s.qdot, s.qddot)
        return mech.shares_data, [s.q, s.output_pose, s.output_twist, s.output_acceleration,
                                  [list(x.values()) for x in (loops.loop_joints, loops.loop_rates,
                                                              loops.loop_accelerations)],
                                  [st.efforts[k] for k in sorted(st.efforts)],
                                  [r.wrench for r in st.reactions]]

    alone, own = run()
    monkeypatch.setattr(mechanism, "SHARED_DATA_NV", 0)
    shares, shared = run()
    assert shares and not alone
    for x, y in zip(shared, own, strict=True):
        np.testing.assert_allclose(np.asarray(x, float), np.asarray(y, float), rtol=0, atol=1e-12)


def test_two_states_in_one_thread_read_their_own_configuration():
    """The per-thread Data: a state whose pass another state overwrote runs it again, its Jacobians too."""
    mech = screwkin.load(ROBOTS / "arm_6r.urdf")
    fid = mech.link_frame("flange")
    (q1, v1, a1), (q2, v2, a2) = _motion(mech, 4), _motion(mech, 5)
    s1, s2 = KinematicState(mech, q1, v1, a1), KinematicState(mech, q2, v2, a2)
    order = [(s1.frame_pose, s1), (s2.frame_jacobian, s2), (s1.frame_jacobian, s1), (s2.frame_pose, s2),
             (s1.frame_acceleration, s1), (s2.frame_twist, s2)]
    refs = {id(s1): _reference(mech, q1, v1, a1, fid), id(s2): _reference(mech, q2, v2, a2, fid)}
    which = {"frame_pose": 0, "frame_jacobian": 1, "frame_twist": 2, "frame_acceleration": 3}
    for read, state in order:
        np.testing.assert_allclose(read(fid), refs[id(state)][which[read.__name__]], rtol=0, atol=1e-12)


def test_place_tool_leaves_the_model_as_it_was():
    mech = screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")
    before = [(f.name, f.parentJoint, f.parentFrame, f.placement.homogeneous.copy()) for f in mech.model.frames]
    tool = pin.SE3(pin.rpy.rpyToMatrix(0.1, -0.2, 0.3), np.array([0.03, 0.01, -0.02]))
    name = place_tool(mech, "tip", "coupler", tool)
    after = [(f.name, f.parentJoint, f.parentFrame, f.placement.homogeneous.copy()) for f in mech.model.frames]
    assert len(after) == len(before)
    for x, y in zip(before, after, strict=True):
        assert x[:3] == y[:3]
        np.testing.assert_array_equal(x[3], y[3])
    # the reference: the tool as a frame added to a copy of the model by hand
    model = pin.Model(mech.model)
    body = mech.link_frame("coupler")
    ref_id = model.addFrame(pin.Frame("tip", model.frames[body].parentJoint, body,
                                      model.frames[body].placement * tool, pin.FrameType.OP_FRAME), False)
    data = model.createData()
    q = mech.generic_configurations()[0].q
    v = np.linspace(0.3, -0.4, mech.nv)
    pin.forwardKinematics(model, data, q, v, np.zeros(mech.nv))
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    state = KinematicState(mech, q, v)
    np.testing.assert_allclose(state.link_pose(name), data.oMf[ref_id].homogeneous, rtol=0, atol=1e-12)
    np.testing.assert_allclose(state.link_jacobian(name), pin.getFrameJacobian(model, data, ref_id, LWA),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(state.link_motion(name)["velocity"],
                               pin.getFrameVelocity(model, data, ref_id, LWA).linear, rtol=0, atol=1e-12)
    # the mechanism's own Data holds no tool; a copy placed for a closure system does
    own = mech.model.createData()
    pin.framesForwardKinematics(mech.model, own, q)
    np.testing.assert_array_equal(own.oMf[mech.tool_frame].homogeneous, np.eye(4))
    placed = model_with_output(mech)
    pdata = placed.createData()
    pin.framesForwardKinematics(placed, pdata, q)
    np.testing.assert_allclose(pdata.oMf[mech.tool_frame].homogeneous, data.oMf[ref_id].homogeneous, rtol=0,
                               atol=1e-12)
    # placed again, elsewhere: every reader takes the new frame (the state, a batched pass made before)
    tree = TreeKinematics(mech)
    _, p, _, _ = tree.frames(q[None], [mech.tool_frame], jacobian=False)[mech.tool_frame]
    np.testing.assert_allclose(p[0], data.oMf[ref_id].translation, rtol=0, atol=1e-12)
    moved = pin.SE3(np.eye(3), np.array([-0.01, 0.04, 0.0]))
    other = place_tool(mech, "tip2", "rocker", moved)
    there = KinematicState(mech, q).link_pose("rocker") @ moved.homogeneous
    np.testing.assert_allclose(KinematicState(mech, q).link_pose(other), there, rtol=0, atol=1e-12)
    _, p, _, _ = tree.frames(q[None], [mech.tool_frame], jacobian=False)[mech.tool_frame]
    np.testing.assert_allclose(p[0], there[:3, 3], rtol=0, atol=1e-12)
