"""ik counts its branches leg by leg and knows when a position alone leaves a continuum (issue 24 item 7).

The bound is checked against geometry done here: each leg of the planar 3-RRR, with the platform
placed, is a dyad whose elbow lies on two circles (about the motor axis, radius the proximal link;
about the wrist, radius the distal link); two real intersections per leg give 2 x 2 x 2 = 8 branches."""

import json
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from screwkin.analysis.position.ik import branches, inverse_kinematics

from conftest import ROBOTS


def _centre(m, q, joint):
    model = m.model
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    return data.oMi[model.getJointId(joint)].translation.copy()


@pytest.mark.slow  # about 3.3 s on 2 shared cores: out of the fast subset
def test_3rrr_pose_has_all_eight_branches_by_circle_intersections():
    m = screwkin.load(ROBOTS / "planar_3rrr.urdf")
    res = inverse_kinematics(m, "platform", pin.SE3.Identity())
    count = branches(m, res)
    assert count.found == 8 and count.at_most == 8 and count.complete
    assert [k for _, k, _ in count.legs] == [2, 2, 2]
    q = res.solutions[0].q
    for leg in "123":
        motor, elbow = _centre(m, q, f"motor{leg}"), _centre(m, q, f"elbow{leg}")
        elbows = {tuple(np.round(_centre(m, s.q, f"elbow{leg}"), 9)) for s in res.solutions}
        assert len(elbows) == 2  # the two settings of the leg are two elbow positions
        l1 = np.linalg.norm(elbow - motor)
        for e in elbows:
            assert abs(np.linalg.norm(np.array(e) - motor) - l1) < 1e-9  # both on the motor's circle
        # two points of one circle: the chord is perpendicular to the line from the centre to its middle
        e1, e2 = (np.array(e) for e in elbows)
        mid = (e1 + e2) / 2
        assert np.linalg.norm(e1 - e2) > 1e-6
        assert abs(np.dot(e1 - e2, mid - motor)) < 1e-9 * max(1.0, np.linalg.norm(mid - motor))


@pytest.mark.slow  # about 2.9 s on 2 shared cores: out of the fast subset
def test_position_alone_on_a_planar_platform_is_a_continuum_said_first():
    out = subprocess.run([sys.executable, "-m", "screwkin", "ik", str(ROBOTS / "planar_3rrr.urdf"), "--output",
                          "platform", "--position", "0,0,0"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[1].startswith("note: the target leaves 1 degree of freedom free")
    assert "continuum" in lines[1] and "solutions found" in lines[2]
    js = subprocess.run([sys.executable, "-m", "screwkin", "ik", str(ROBOTS / "planar_3rrr.urdf"), "--output",
                         "platform", "--position", "0,0,0", "--json"], capture_output=True, text=True, timeout=120)
    d = json.loads(js.stdout)
    assert d["free_dofs"] == 1 and d["branches"]["at_most"] is None


@pytest.mark.slow  # about 8.2 s on 2 shared cores: out of the fast subset
def test_pose_text_and_json_say_all_of_them():
    args = [sys.executable, "-m", "screwkin", "ik", str(ROBOTS / "planar_3rpr.urdf"), "--output", "platform",
            "--pose", "0,0,0,0,0,0"]
    out = subprocess.run(args, capture_output=True, text=True, timeout=120)
    assert "8 distinct branches found (legs: 2 x 2 x 2) of at most 8" in out.stdout and "all of them" in out.stdout
    d = json.loads(subprocess.run(args + ["--json"], capture_output=True, text=True, timeout=120).stdout)
    assert d["branches"]["found"] == 8 and d["branches"]["at_most"] == 8
    assert [leg["at_most"] for leg in d["branches"]["legs"]] == [2, 2, 2]


def test_serial_arm_with_a_spherical_wrist_is_answered_in_closed_form_every_solution():
    """arm_6r's last three axes meet: Pieper's closed form lists every real joint solution, the rest
    counted complex (8 in all), each placing the flange at the pose by Pinocchio's forward kinematics."""
    m = screwkin.load(ROBOTS / "arm_6r.urdf")
    pose = pin.SE3(np.eye(3), np.array([0.3, 0.0, 0.3]))
    res = inverse_kinematics(m, "flange", pose)
    count = branches(m, res)
    assert res.modes.method == "closed form (Pieper)" and count.complete
    assert res.modes.real == len(res.solutions) and res.modes.real + res.modes.complex == 8
    data = m.model.createData()
    for s in res.solutions:
        pin.framesForwardKinematics(m.model, data, s.q)
        assert np.linalg.norm(pin.log6(data.oMf[m.link_frame("flange")].inverse() * pose).vector) < 1e-10
