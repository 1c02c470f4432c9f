"""The six-bar inversions named by their graphs (issue 25, point 15): Watt I, II and Stephenson I, II,
III as E. Constans and K. Dyer, *Introduction to Mechanism Design with Computer Applications* (CRC
2018), six-bar chapter, describe them (and its MATLAB exercises, github
ziolkowskid06/Introduction_to_Mechanism_Design_with_Computer_Application): each graph below is
built here from the book's pin letters, the names checked against the book's, under relabelling
(by the graph, not by index); then synthesize chains' inversions and the two six-bars in robots/
against a classification written in this test from the URDF's own joints."""

import json
import random
import xml.etree.ElementTree as ET

import pytest

from screwkin.cli import main
from screwkin.model.six_bar import six_bar_chain, six_bar_inversion

# joints as (link, link) pairs named by the book's pins
BOOK = {
    # Watt I: ground pins A, D only (a binary ground); the coupler (B, C, E) and the rocker (C, D, F) ternary
    "Watt I": [("ground", "crank"), ("crank", "coupler"), ("coupler", "rocker"), ("ground", "rocker"),
               ("coupler", "link5"), ("rocker", "link6"), ("link5", "link6")],
    # Watt II: a ternary ground (A, D, F), the rocker (C, D, E) ternary and jointed to it at D
    "Watt II": [("ground", "crank"), ("crank", "coupler"), ("coupler", "rocker"), ("rocker", "ground"),
                ("rocker", "link5"), ("link5", "link6"), ("link6", "ground")],
    # Stephenson I: a binary ground (A, D) carrying a crank triangle (A, B, E) and a rocker triangle (D, C, F)
    "Stephenson I": [("ground", "crank"), ("ground", "rocker"), ("crank", "coupler"), ("coupler", "rocker"),
                     ("crank", "link5"), ("link5", "link6"), ("link6", "rocker")],
    # Stephenson II: the ground in the two-binary path between the ternary links (coupler, rocker): joined to
    # the binary crank and the ternary rocker
    "Stephenson II": [("ground", "crank"), ("crank", "coupler"), ("ground", "rocker"), ("coupler", "link5"),
                      ("link5", "rocker"), ("coupler", "link6"), ("link6", "rocker")],
    # Stephenson III: a ternary ground (A, D, F), a ternary coupler (B, C, E) and the dyad E-G-F
    "Stephenson III": [("ground", "crank"), ("crank", "coupler"), ("coupler", "rocker"), ("rocker", "ground"),
                       ("coupler", "link5"), ("link5", "link6"), ("link6", "ground")],
}


@pytest.mark.parametrize("name", sorted(BOOK))
def test_the_books_six_bars_are_named_by_their_graphs(name):
    edges = BOOK[name]
    assert six_bar_inversion(edges, "ground") == name
    assert six_bar_chain(edges) == name.split()[0]
    rng = random.Random(name)
    for _ in range(5):  # the links renamed and the joints listed in another order: the same name
        labels = ["ground", "crank", "coupler", "rocker", "link5", "link6"]
        new = dict(zip(labels, rng.sample(range(10, 16), 6)))
        shuffled = [(new[u], new[v]) if rng.random() < 0.5 else (new[v], new[u]) for u, v in edges]
        rng.shuffle(shuffled)
        assert six_bar_inversion(shuffled, new["ground"]) == name


def test_what_is_not_a_six_bar_is_not_named():
    four_bar = [(0, 1), (1, 2), (2, 3), (3, 0)]
    assert six_bar_inversion(four_bar, 0) is None and six_bar_chain(four_bar) is None
    doubled = BOOK["Watt I"][:-1] + [("coupler", "link5")]  # two joints between the same links
    assert six_bar_inversion(doubled, "ground") is None
    assert six_bar_inversion(BOOK["Watt I"], "not a link") is None


def _by_hand(edges, ground):
    """The test's own rule: the ternary links (three joints) adjacent -> Watt; a ternary ground -> II (Watt) or III
    (Stephenson); a binary Stephenson ground joined to two ternary links -> I, to one -> II."""
    deg = {}
    for u, v in edges:
        deg[u] = deg.get(u, 0) + 1
        deg[v] = deg.get(v, 0) + 1
    t = [x for x, d in deg.items() if d == 3]
    watt = (t[0], t[1]) in edges or (t[1], t[0]) in edges
    if watt:
        return "Watt II" if deg[ground] == 3 else "Watt I"
    if deg[ground] == 3:
        return "Stephenson III"
    joined = {v if u == ground else u for u, v in edges if ground in (u, v)}
    return "Stephenson I" if all(deg[x] == 3 for x in joined) else "Stephenson II"


def test_synthesize_chains_names_every_six_bar_inversion(tmp_path, capsys):
    assert main(["synthesize", "chains", "--links", "6", "--dof", "1", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    names = []
    for chain in d["chains"]:
        edges = [tuple(j["links"]) for j in chain["joints"]]
        for m in chain["mechanisms"]:
            assert m["inversion"] == _by_hand(edges, m["ground"])
            names.append(m["inversion"])
    assert sorted(names) == sorted(BOOK)  # the five inversions, each once
    assert main(["synthesize", "chains", "--links", "6", "--dof", "1"]) == 0
    text = capsys.readouterr().out
    assert all(f"({n})" in text for n in BOOK)
    # the files are named by index: the inversion's name is in each file's comment, and info names it the same
    assert main(["synthesize", "chains", "--links", "6", "--dof", "1", "-o", str(tmp_path / "six"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    for chain in d["chains"]:
        for m in chain["mechanisms"]:
            comment = open(m["file"]).read().split("-->")[0]
            assert f"inversions: {m['inversion']}," in comment
            assert main(["info", m["file"], "--json"]) == 0
            assert json.loads(capsys.readouterr().out)["six_bar"] == m["inversion"]


def _urdf_edges(path):
    """The URDF's joints (tree and loop joints) as (link, link) pairs, and its ground (a parent never a child)."""
    root = ET.parse(path).getroot()
    edges = [(j.find("parent").get("link"), j.find("child").get("link")) for j in root.findall("joint")]
    edges += [(j.find("link1").get("link"), j.find("link2").get("link")) for j in root.findall("loop_joint")]
    children = {c for _, c in edges[:len(root.findall("joint"))]}
    (ground,) = {p for p, _ in edges if p not in children}
    return edges, ground


@pytest.mark.parametrize("path, name", [("robots/watt_sixbar.urdf", "Watt I"),
                                        ("robots/stephenson_sixbar.urdf", "Stephenson III")])
def test_info_and_mobility_name_the_six_bars_in_robots(path, name, capsys):
    edges, ground = _urdf_edges(path)
    assert _by_hand(edges, ground) == name
    for command in ("info", "mobility"):
        assert main([command, path, "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["six_bar"] == name
    assert main(["info", path]) == 0
    assert f"six-bar: {name}: " in capsys.readouterr().out
    assert main(["info", "robots/friction_wheels.urdf", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["six_bar"] is None


def test_synthesize_chains_writes_into_an_existing_folder(tmp_path, capsys):
    """-o names a folder for chains: an existing one is used (it was refused as 'a folder, not a file')."""
    from screwkin.cli import main

    assert main(["synthesize", "chains", "--links", "4", "--dof", "1", "-o", str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["chain01_ground0.urdf"]
    assert "wrote 1 file to" in capsys.readouterr().out
