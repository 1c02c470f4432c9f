"""Loading details: loop-joint forms, sidecars, SDF, actuation precedence, compound joints."""

import json
import shutil

import pytest
from conftest import CORPUS, DATA, fourbar

import screwkin
from screwkin.cli import main


def test_fourbar_loop_joint_is_closed_in_the_file(tmp_path):
    p = tmp_path / "fb.urdf"
    p.write_text(fourbar())
    mech = screwkin.load(p)
    a = mech.assemble()
    assert a.iterations == 0  # the file's configuration is already closed
    r = mech.mobility()
    assert (r.mobility, r.topology.gruebler, r.topology.kutzbach) == (1, 1, -2)
    assert r.topology.motion_space == "planar"


def test_second_link1_is_read_as_link2(tmp_path):
    p = tmp_path / "fb.urdf"
    p.write_text(fourbar('<link1 link="coupler" xyz="0.12 0 0"/><link1 link="rocker" xyz="0.08 0 0"/>'))
    seen = []
    mech = screwkin.load(p, warn=seen.append)
    assert any("second is read as <link2>" in w for w in seen)
    assert mech.cuts[0].link2 == "rocker"
    assert mech.mobility().mobility == 1


def test_actuation_precedence(tmp_path):
    tx = ('<transmission name="t"><type>transmission_interface/SimpleTransmission</type>'
          '<joint name="rocker_joint"><hardwareInterface>EffortJointInterface</hardwareInterface></joint></transmission>')
    p = tmp_path / "fb.urdf"
    p.write_text(fourbar(extra=tx))
    mech = screwkin.load(p)
    assert (mech.actuated, mech.actuation_source) == (["rocker_joint"], "transmission")
    (tmp_path / "fb.yaml").write_text("closed_loop: []\ntype: []\nname_mot: ['crank_joint']\n")
    mech = screwkin.load(p)
    assert (mech.actuated, mech.actuation_source) == (["crank_joint"], "yaml name_mot")
    mech = screwkin.load(p, actuated=["coupler_joint"])
    assert (mech.actuated, mech.actuation_source) == (["coupler_joint"], "command line")


def test_sidecar_joint_replacement_spherical(tmp_path):
    """The sidecar's joint_name/joint_type turn a revolute into a native
    spherical joint (3 velocity coordinates)."""
    src = CORPUS / "5bar_linkage_iso3d"
    shutil.copy(src / "robot.urdf", tmp_path / "robot.urdf")
    text = (src / "robot.yaml").read_text()
    (tmp_path / "robot.yaml").write_text(text + "joint_name: ['freeortho']\njoint_type: ['SPHERICAL']\n")
    mech = screwkin.load(tmp_path / "robot.urdf", warn=lambda m: None)
    assert mech.coordinate("freeortho").nv == 3
    r = mech.mobility()
    # one revolute (1) became spherical (3): the count and the rank both go up by 2
    assert r.topology.kutzbach == 4
    assert r.mobility == 4


def test_sdf_four_bar_is_cut_into_tree_plus_loop_joint():
    mech = screwkin.load(DATA / "fourbar.sdf")
    assert len(mech.cuts) == 1
    r = mech.mobility(actuated=["A"], output="rocker")
    assert r.mobility == 1 and r.topology.gruebler == 1
    assert r.output.label == "1R"
    assert r.classification.startswith("constrained")


def test_sdf_ball_joints_become_compound_spherical():
    """RSSR in SDF with two ball joints: the tree ball becomes three revolutes
    through massless links, recognized again as one spherical joint."""
    r = screwkin.load(DATA / "rssr.sdf").mobility()  # (also a base of the SDF fuzz test)
    t = r.topology
    assert sorted(j.type for j in t.joints) == ["revolute", "revolute", "spherical", "spherical"]
    assert (t.n_links, t.n_joints, t.kutzbach) == (4, 4, 2)
    assert (r.mobility, r.idle_dofs) == (2, 1)  # the rod spins about the line through its two ball centres
    assert [i.link for i in r.idle] == ["rod"]


def test_cli_and_api_give_the_same_numbers(capsys):
    path = CORPUS / "cassie_like" / "robot.urdf"
    assert main(["mobility", str(path), "--json", "--output", "foot_2"]) == 0
    d = json.loads(capsys.readouterr().out)
    r = screwkin.load(path, warn=lambda m: None).mobility(output="foot_2")
    for key in ("links", "joints", "loops", "kutzbach", "gruebler", "motion_space", "mobility", "overconstraint",
                "idle_dofs", "effective_dofs", "actuated", "classification", "output_motion"):
        assert key in d
    assert d["mobility"] == r.mobility and d["kutzbach"] == r.kutzbach
    assert d["links"] == r.topology.n_links and d["loops"] == r.topology.loops
    assert d["idle_dofs"] == r.idle_dofs and d["effective_dofs"] == r.effective_dofs
    assert d["output_motion"] == r.output.label
    assert [j["name"] for j in d["joints"]] == [j.name for j in r.topology.joints]
    assert all(set(j) >= {"name", "type", "dof"} for j in d["joints"])


def test_json_nulls_without_actuators_or_output(tmp_path, capsys):
    p = tmp_path / "fb.urdf"
    p.write_text(fourbar())
    assert main(["mobility", str(p), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["effective_dofs"] is None and d["output_motion"] is None and d["actuated"] == []
    assert d["gruebler"] == 1


def test_info_table(capsys, tmp_path):
    p = tmp_path / "fb.urdf"
    p.write_text(fourbar())
    assert main(["info", str(p)]) == 0
    out = capsys.readouterr().out
    assert "loops L = J - N + 1 = 1" in out and "crank_joint" in out


def test_package_uri_resolves_against_ros_package_path(tmp_path, monkeypatch):
    pkg = tmp_path / "pkgs" / "mypkg" / "meshes"
    pkg.mkdir(parents=True)
    (pkg / "m.stl").write_text("solid x\nendsolid x\n")
    mesh = '<visual><geometry><mesh filename="package://mypkg/meshes/m.stl"/></geometry></visual>'
    text = fourbar().replace('<link name="ground">', f'<link name="ground">{mesh}')
    d = tmp_path / "robot"
    d.mkdir()
    (d / "fb.urdf").write_text(text)
    seen = []
    screwkin.load(d / "fb.urdf", warn=seen.append)
    assert any("mesh" in w for w in seen)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "pkgs"))
    seen.clear()
    screwkin.load(d / "fb.urdf", warn=seen.append)
    assert not seen


@pytest.mark.parametrize("kind, coordinates, kutzbach", [("UJOINT_XY", 6, 3), ("CARDAN", 6, 3), ("FIXED", 4, 1)])
def test_sidecar_joint_replacement_universal_and_fixed(tmp_path, kind, coordinates, kutzbach):
    """5bar_linkage_iso3d is 5 R + 1 S (Kutzbach 2): a revolute replaced by a universal joint adds
    one DOF to the count, a fixed one removes the joint and merges its two links (count 1)."""
    src = CORPUS / "5bar_linkage_iso3d"
    shutil.copy(src / "robot.urdf", tmp_path / "robot.urdf")
    (tmp_path / "robot.yaml").write_text((src / "robot.yaml").read_text()
                                         + f"joint_name: ['freeortho']\njoint_type: ['{kind}']\n")
    r = screwkin.load(tmp_path / "robot.urdf", warn=lambda m: None).mobility()
    assert (r.coordinates, r.topology.kutzbach) == (coordinates, kutzbach)
    if kind != "FIXED":
        assert r.mobility == kutzbach and "universal" in [j.type for j in r.topology.joints]
