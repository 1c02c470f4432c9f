"""Joints nobody set are not solved for (issue 33 item 1).

A tree joint that no loop passes through is decided by nothing but its own value: a configuration
given by --set values that leave one out is a usage error naming it (exit 2), never "assembly mode 1
of 25" of a pose nobody typed.  The statics of the fully given pose is checked against Pinocchio's
RNEA with the load as an external force (an independent computation of tau = -J^T w)."""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOT_DATA, ROBOTS
from screwkin.analysis.position.position import PositionSolver
from screwkin.cli import main
from screwkin.model.topology import open_joints

GRIPPER = ROBOTS / "gripper_arm_mimic.urdf"
PANDA = None if ROBOT_DATA is None else ROBOT_DATA / "panda_description" / "urdf" / "panda.urdf"
ARM = [f"panda_joint{k}" for k in range(1, 8)]
needs_panda = pytest.mark.skipif(PANDA is None, reason="example-robot-data is not installed")


def test_open_joints_are_the_ones_no_loop_passes_through():
    assert open_joints(screwkin.load(ROBOTS / "fourbar_crank_rocker.urdf")) == ()
    assert open_joints(screwkin.load(ROBOTS / "delta_parallelogram.urdf")) == ()
    assert open_joints(screwkin.load(ROBOTS / "friction_wheels.urdf")) == ()  # the rolling pair's law is a loop
    assert open_joints(screwkin.load(ROBOTS / "arm_6r.urdf")) == tuple(f"joint{k}" for k in range(1, 7))
    # the right finger mimics the left: it has no coordinate, the left one is an input
    assert open_joints(screwkin.load(GRIPPER)) == ("shoulder", "elbow", "wrist", "finger_left_joint")


def test_a_solve_that_leaves_out_an_open_joint_is_refused():
    mech = screwkin.load(GRIPPER)
    with pytest.raises(screwkin.errors.UsageError, match="no loop passes through shoulder, elbow, wrist"):
        PositionSolver(mech, ["finger_left_joint"]).solve({"finger_left_joint": 0.01})
    res = PositionSolver(mech, ["shoulder", "elbow", "wrist", "finger_left_joint"]).solve(
        {"shoulder": 0.1, "elbow": 0.2, "wrist": 0.3, "finger_left_joint": 0.01})
    assert len(res.solutions) == 1 and res.free_dofs == 0


@pytest.mark.parametrize("command", [
    ["statics", "--output", "hand", "--wrench", "0 0 -10 0 0 0"],
    ["solve"], ["singularities"], ["screws", "--output", "hand"], ["draw", "--png", "{tmp}/d.png"],
    ["export", "--urdf", "{tmp}/e.urdf"], ["sweep", "--input", "shoulder", "--from", "0", "--to", "1"],
])
def test_every_command_names_the_joints_nobody_set(command, tmp_path, capsys):
    """--set elbow alone: the shoulder, wrist and finger are named, exit 2, nothing analysed."""
    args = [a.replace("{tmp}", str(tmp_path)) for a in command]
    code = main([args[0], str(GRIPPER), *args[1:], "--set", "elbow=0.5"])
    out, err = capsys.readouterr()
    assert code == 2, err
    if command[0] == "sweep":  # the swept shoulder is given; the actuated wrist and finger are its other inputs
        assert "give values for the other inputs with --set: wrist, finger_left_joint" in err
    else:
        assert "no loop passes through shoulder, wrist, finger_left_joint" in err and "--set " in err
    assert "assembly mode" not in err and out == ""


def test_without_set_the_file_configuration_is_named(capsys):
    """The documented default (no --set: the file's configuration) is said in one line with its values."""
    assert main(["screws", str(ROBOTS / "arm_6r.urdf"), "--output", "flange"]) == 0
    err = capsys.readouterr().err
    assert "no --set given: the file's configuration (joint1 = 0 deg" in err
    assert main(["singularities", str(ROBOTS / "fourbar_crank_rocker.urdf")]) == 0
    assert "no --set given: the configuration assembled from the file's (crank_joint = " in capsys.readouterr().err


def test_a_joint_of_several_coordinates_keeps_the_file_value(tmp_path, capsys):
    """A floating base no loop passes through cannot be typed as one value: it keeps the file's, said so."""
    p = tmp_path / "float.xml"
    p.write_text('<mujoco><worldbody><body name="base" pos="0 0 1"><freejoint name="root"/>'
                 '<inertial pos="0 0 0" mass="1" diaginertia="0.1 0.1 0.1"/><body name="arm" pos="0.1 0 0">'
                 '<joint name="hinge" type="hinge" axis="0 0 1"/>'
                 '<inertial pos="0.1 0 0" mass="1" diaginertia="0.1 0.1 0.1"/></body></body></worldbody></mujoco>')
    assert main(["solve", str(p), "--set", "hinge=30deg", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert len(d["solutions"]) == 1
    assert [d["solutions"][0]["joints"][f"root[q{k}]"] for k in range(7)] == [0, 0, 0, 0, 0, 0, 1]
    assert any("root keeps the file's value" in n for n in d["notes"])


@needs_panda
def test_panda_statics_with_one_joint_set_is_refused(capsys):
    """The issue's reproducer: one joint of seven set analysed 'assembly mode 1 of 25' of a pose nobody typed."""
    code = main(["statics", str(PANDA), "--output", "panda_hand", "--wrench", "0 0 -10 0 0 0",
                 "--set", "panda_joint4=-2.356"])
    err = capsys.readouterr().err
    assert code == 2
    assert "no loop passes through panda_joint1, panda_joint2, panda_joint3, panda_joint5, panda_joint6, " \
           "panda_joint7, panda_finger_joint1" in err
    assert "assembly mode" not in err


@needs_panda
def test_panda_statics_of_the_given_pose_is_pinocchios(capsys):
    """Every joint given: the efforts are Pinocchio's RNEA with the load as an external force on the hand
    (gravity off), tau = -J^T w, computed here from the URDF without screwkin."""
    q_arm = [0.3, -0.4, 0.2, -2.356, 0.1, 1.2, -0.5]
    sets = [f"{n}={v!r}" for n, v in zip(ARM, q_arm)] + ["panda_finger_joint1=0"]
    code = main(["statics", str(PANDA), "--output", "panda_hand", "--wrench", "0 0 -10 0 0 0", "--json",
                 "--actuated", ",".join(ARM), *(x for s in sets for x in ("--set", s))])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    efforts = json.loads(captured.out)["efforts"]
    model = pin.buildModelFromUrdf(str(PANDA))
    data = model.createData()
    q = pin.neutral(model)
    for n, v in zip(ARM, q_arm):
        q[model.idx_qs[model.getJointId(n)]] = v
    fid = model.getFrameId("panda_hand")
    pin.framesForwardKinematics(model, data, q)
    w = np.array([0, 0, -10.0, 0, 0, 0])
    frame = model.frames[fid]
    o = data.oMf[fid].translation
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    fext[frame.parentJoint] = data.oMi[frame.parentJoint].actInv(pin.Force(w[:3], w[3:] + np.cross(o, w[:3])))
    model.gravity.linear[:] = 0
    tau = pin.rnea(model, data, q, np.zeros(model.nv), np.zeros(model.nv), fext)
    for n in ARM:
        assert efforts[n] == pytest.approx(tau[model.idx_vs[model.getJointId(n)]], abs=1e-9)
    assert np.abs(tau[:7]).max() > 1.0  # the load is felt: a comparison of zeros would prove nothing
