"""Every bundled mechanism against the literature values listed in robots/README.md."""

import pytest

import screwkin
from conftest import ROBOTS, robots_table

TABLE = robots_table()
SPACE = {"Gruebler": "planar", "spherical": "spherical", "Kutzbach": "spatial"}




def test_the_table_lists_every_robot():
    assert set(TABLE) == {p.name for p in ROBOTS.glob("*.urdf")}
    assert len(TABLE) >= 14


@pytest.mark.parametrize("name", sorted(TABLE))
def test_robot_mobility(name):
    row = TABLE[name]
    mech = screwkin.load(ROBOTS / name)
    assert mech.assemble().iterations == 0  # the file is drawn closed
    r = mech.mobility(output=row["out"])
    t = r.topology
    assert (t.n_links, t.n_joints) == (int(row["N"]), int(row["J"]))
    assert t.motion_space == SPACE[row["crit"]]
    assert t.count_in_motion_space == int(row["count"])
    assert r.mobility == int(row["M"])
    assert r.idle_dofs == int(row["idle"])
    assert r.effective_mobility == int(row["eff"])
    assert r.output.label.split(" ")[0] == row["motion"]
    assert r.actuation_source == "transmission"
    assert r.classification.startswith("constrained")  # each is drawn with as many inputs as effective DOFs
    assert r.overconstraint == r.mobility - t.kutzbach


def test_overconstrained_linkages_get_a_note():
    r = screwkin.load(ROBOTS / "bennett.urdf").mobility()
    assert r.kutzbach == -2 and r.mobility == 1 and r.overconstraint == 3
    assert any("overconstrained" in n for n in r.notes)


def test_idle_links_are_the_rods():
    r = screwkin.load(ROBOTS / "delta_parallelogram.urdf").mobility(output="platform")
    assert sorted(i.link for i in r.idle) == ["rod1a", "rod1b", "rod2a", "rod2b", "rod3a", "rod3b"]
    assert all(i.dofs == 1 for i in r.idle)
    r = screwkin.load(ROBOTS / "rssr.urdf").mobility()
    assert [i.link for i in r.idle] == ["coupler"]
