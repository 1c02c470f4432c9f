"""Exports a simulator can run (issue 34, second part): the joints' own dynamics (armature, damping,
friction loss) kept from MJCF and URDF and written back, transmissions with reductions, ball and
universal joints in the tree, the minimal equality rows and the redundant ones named -- checked
against MuJoCo (its own readers, its constraint rows, its simulation), hand formulas and urdfdom's
check_urdf."""

import shutil
import subprocess

import numpy as np
import pytest

import screwkin
from conftest import DATA
from screwkin.analysis.forces.dynamics import dynamics
from screwkin.cli import main

mujoco = pytest.importorskip("mujoco")
MJCF = DATA / "mjcf"
FINGER = MJCF / "finger_armature.xml"
DYNAMICS = ("armature", "damping", "frictionloss")


def _dof(m, name, what):
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
    return float(getattr(m, "dof_" + what)[m.jnt_dofadr[j]])


def simulate(path, seconds=1.0, effort=0.05):
    """1 s of mj_step at the file's timestep with ``effort`` on every motor: MuJoCo's warnings."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    d.ctrl[:] = effort
    for _ in range(int(round(seconds / m.opt.timestep))):
        mujoco.mj_step(m, d)
    return [mujoco.mjtWarning(k).name for k in range(len(d.warning)) if d.warning[k].number]


def check_urdf(path):
    tool = shutil.which("check_urdf")
    if tool:
        done = subprocess.run([tool, str(path)], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stdout + done.stderr


# ------------------------------------------------------------------ armature, damping, friction loss
def test_joint_dynamics_are_read_as_mujoco_reads_them():
    """Each joint's armature, damping and frictionloss (from a default class, one overridden per joint)
    are MuJoCo's own dof_armature, dof_damping, dof_frictionloss of the file."""
    mech = screwkin.load(FINGER, warn=lambda w: None)
    m = mujoco.MjModel.from_xml_path(str(FINGER))
    joints = {j.name: j for j in mech.spec.joints}
    for name in ("base", "mid", "tip"):
        for what in DYNAMICS:
            assert getattr(joints[name], what) == _dof(m, name, what)
    assert (joints["mid"].damping, joints["tip"].armature) == (0.002, 0.005)
    res = dynamics(mech, "base", 1.0, 0.0, 0.5, 3, inputs=["base", "mid", "tip"], fixed={"mid": 0.0, "tip": 0.0})
    assert any("friction loss the file gives 3 joints" in n and "not in these efforts" in n for n in res.notes)


def test_export_keeps_the_armature_and_simulates(tmp_path, capsys):
    """The finger's links weigh grams with inertias of 1e-9 kg m^2: without its joints' armature MuJoCo
    is unstable within 0.03 s under 0.05 N m (the published Allegro and OP3 exports failed so); the
    export keeps armature, damping and friction loss (MuJoCo's dof_* of the export equal the
    original's) and runs 1 s without a warning.  The URDF export writes damping and friction as
    <dynamics> (MuJoCo's own URDF reader finds them there), passes check_urdf, and says that the
    armature has no URDF form."""
    m = mujoco.MjModel.from_xml_path(str(FINGER))
    d = mujoco.MjData(m)
    m.dof_armature[:] = 0  # the instability the test model reproduces
    d.ctrl[:] = 0.05
    for _ in range(50):
        mujoco.mj_step(m, d)
    assert d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0
    out_x, out_u = tmp_path / "f.xml", tmp_path / "f.urdf"
    assert main(["export", str(FINGER), "--mjcf", str(out_x), "--urdf", str(out_u)]) == 0
    assert "armature of 3 joints ('base', 'mid', 'tip') has no URDF form" in capsys.readouterr().out
    assert simulate(out_x) == []
    original = mujoco.MjModel.from_xml_path(str(FINGER))
    written = mujoco.MjModel.from_xml_path(str(out_x))
    from_urdf = mujoco.MjModel.from_xml_path(str(out_u))
    for name in ("base", "mid", "tip"):
        for what in DYNAMICS:
            assert _dof(written, name, what) == _dof(original, name, what)
        for what in ("damping", "frictionloss"):
            assert _dof(from_urdf, name, what) == _dof(original, name, what)
    check_urdf(out_u)
    back = {j.name: j for j in screwkin.load(out_u, warn=lambda w: None).spec.joints}
    assert (back["mid"].damping, back["mid"].frictionloss, back["mid"].armature) == (0.002, 0.01, 0.0)


def test_urdf_dynamics_are_read_and_exported(tmp_path, capsys):
    """URDF <dynamics damping friction>: the MJCF export's dof_damping and dof_frictionloss are those
    MuJoCo's own URDF reader gives the source file."""
    link = ('<link name="{n}"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="1e-3" iyy="1e-2" '
            'izz="1e-2" ixy="0" ixz="0" iyz="0"/></inertial></link>')
    src = tmp_path / "arm.urdf"
    src.write_text('<robot name="arm">' + "".join(link.format(n=n) for n in ("base", "upper", "fore")) +
                   '<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>'
                   '<limit lower="-2" upper="2" effort="10" velocity="1"/><dynamics damping="0.7" friction="0.2"/></joint>'
                   '<joint name="elbow" type="continuous"><parent link="upper"/><child link="fore"/><origin xyz="0.2 0 0"/>'
                   '<axis xyz="0 0 1"/><dynamics damping="0.4"/></joint></robot>')
    out = tmp_path / "arm.xml"
    assert main(["export", str(src), "--mjcf", str(out)]) == 0
    capsys.readouterr()
    theirs, ours = mujoco.MjModel.from_xml_path(str(src)), mujoco.MjModel.from_xml_path(str(out))
    for name in ("shoulder", "elbow"):
        for what in ("damping", "frictionloss"):
            assert _dof(ours, name, what) == _dof(theirs, name, what)
    assert (_dof(ours, "shoulder", "damping"), _dof(ours, "shoulder", "frictionloss")) == (0.7, 0.2)
