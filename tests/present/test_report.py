"""screwkin report: one self-contained document (HTML, Markdown) of a mechanism, checked against
the commands each section comes from (equations --json, solve --json, draw --singular --json,
mobility), opened in headless Chromium, and for the mechanisms whose sections must step aside
(a spatial loop, a serial arm)."""

import base64
import html as htmllib
import json
import re
import subprocess
import tempfile

import numpy as np
import pytest
from conftest import ROBOTS

import screwkin
from screwkin.cli import main
from screwkin.present.view import chromium

pytest.importorskip("matplotlib")

FOURBAR = str(ROBOTS / "fourbar_crank_rocker.urdf")
SET = ["--set", "crank_joint=30deg"]


def _json(capsys, argv):
    capsys.readouterr()
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def _text(page: str) -> str:
    """The visible text of a page: no script data, style or pictures; tags as spaces."""
    page = re.sub(r"<script.*?</script>|<style.*?</style>", " ", page, flags=re.S)
    return htmllib.unescape(re.sub(r"<[^>]+>", " ", page))


def _table(page: str, cls: str) -> list:
    m = re.search(rf'<table class="{cls}">(.*?)</table>', page, re.S)
    assert m, f"no table {cls}"
    body = m.group(1).split("<tbody>")[-1]  # the rows under the header (a table without one: all rows)
    rows = re.findall(r"<tr>(.*?)</tr>", body, re.S)
    return [[htmllib.unescape(c) for c in re.findall(r"<t[dh]>(.*?)</t[dh]>", r, re.S)] for r in rows]


@pytest.fixture(scope="module")
def fourbar_report(tmp_path_factory):
    """The four-bar's report at crank 30 deg, as HTML and Markdown in one run (with the view)."""
    d = tmp_path_factory.mktemp("report")
    h, md = d / "fourbar.html", d / "fourbar.md"
    assert main(["report", FOURBAR, *SET, "--html", str(h), "--md", str(md)]) == 0
    return h, md


def test_html_is_self_contained(fourbar_report):
    page = fourbar_report[0].read_text()
    assert page.startswith("<!DOCTYPE html>")
    # nothing is fetched: no URL in any src or href but data: pictures and in-page anchors
    refs = re.findall(r'\b(?:src|href)\s*=\s*"([^"]*)"', page)
    assert refs and all(r.startswith(("data:", "#")) for r in refs), [r[:40] for r in refs if r[:5] != "data:"]
    assert not re.search(r"https?://", re.sub(r'"data:[^"]*"', "", page).split('id="screwkin-data"')[0].replace(
        "http://www.w3.org", ""))
    assert not re.search(r"<(?:link|iframe|object|embed)\b", page)
    scripts = re.findall(r"<script([^>]*)>", page)
    assert scripts == [' type="application/json" id="screwkin-data"']  # data, never executed
    # every picture decodes
    for mime, b64 in re.findall(r'src="data:(image/[a-z+]+);base64,([^"]+)"', page):
        blob = base64.b64decode(b64)
        assert blob.startswith(b"\x89PNG") if mime == "image/png" else b"<svg" in blob[:2000]


def test_header_states_file_version_configuration_and_no_date(fourbar_report):
    page = fourbar_report[0].read_text()
    facts = dict(_table(page, "facts"))
    text = _text(page)
    assert facts["file"] == FOURBAR
    assert facts["screwkin"] == screwkin.__version__
    assert facts["configuration"] == "crank_joint = 30 deg"
    assert not re.search(r"\b20\d\d-\d\d-\d\d\b", text)  # no date


def test_counts_and_mobility(fourbar_report):
    page = fourbar_report[0].read_text()
    counts = {r[0]: (r[1], r[2]) for r in _table(page, "counts")}
    assert counts["Gruebler (planar)"] == ("3(N-1-J) + sum f = 3(4-1-4) + 4", "1")
    assert counts["Gruebler, as the textbooks write it"] == ("3(N-1) - 2 J1 - J2 = 3(4-1) - 2*4 - 0", "1")
    mob = dict(_table(page, "mobility"))
    assert mob["mobility M = coordinates - rank K"] == "1"
    joints = _table(page, "joints")
    assert [r[0] for r in joints] == ["crank_joint", "coupler_joint", "rocker_joint", "coupler_rocker"]
    assert joints[3][-1] == "cut"


def test_equations_and_solved_values_are_the_commands_own(fourbar_report, capsys):
    page = fourbar_report[0].read_text()
    text = _text(page)
    eq = _json(capsys, ["equations", FOURBAR, *SET, "--json"])
    assert eq["det_A"] and eq["det_A"] in text  # the same sympy string
    for c in eq["singular_conditions"]:
        assert c.replace("theta", "θ").replace("pi", "π") in text or c in text
    sol = _json(capsys, ["solve", FOURBAR, *SET, "--json"])["solutions"][0]
    angles = {r[0]: float(r[1]) for r in _table(page, "links-1")}  # solve's links table: the moving links, deg
    assert angles.keys() == sol["links"].keys() == sol["link_angles"].keys() - {"ground"}
    for link, m in sol["links"].items():
        assert angles[link] == pytest.approx(np.degrees(m["angle"]), abs=1e-4)
    joints = {r[0].removesuffix(" (loop)"): float(r[1]) for r in _table(page, "solution-1")}
    rates = {r[0].removesuffix(" (loop)"): float(r[3]) for r in _table(page, "solution-1")}
    for name, v in sol["joints"].items():
        assert joints[name] == pytest.approx(v, abs=1e-8)
    with_rates = _json(capsys, ["solve", FOURBAR, *SET, "--rate", "crank_joint=1", "--json"])["solutions"][0]
    for name, v in with_rates["rates"].items():
        assert rates[name] == pytest.approx(v, rel=1e-5, abs=1e-9)  # solve's 6 digits


def test_newton_from_the_default_estimate_reaches_the_solved_angles(fourbar_report):
    page = fourbar_report[0].read_text()
    data = json.loads(htmllib.unescape(re.search(r'id="screwkin-data">(.*?)</script>', page, re.S).group(1)
                                       .replace("<\\/", "</")))
    nw = data["newton"]
    solved = data["solve"]["solutions"][0]["link_angles"]
    assert nw["start"]["theta3"] == pytest.approx(solved["coupler"] + np.radians(10))
    assert nw["start"]["theta4"] == pytest.approx(solved["rocker"] + np.radians(10))
    assert nw["closes"] and len(nw["trace"]) >= 2
    assert nw["values"]["theta3"] == pytest.approx(solved["coupler"], abs=1e-9)
    text = _text(page)
    assert "default estimate: the solved unknowns, each angle +10 deg" in text
    assert len(_table(page, "newton")) == len(nw["trace"])


def test_one_drawing_per_singular_configuration(fourbar_report, capsys, tmp_path):
    page = fourbar_report[0].read_text()
    drawn = _json(capsys, ["draw", FOURBAR, *SET, "--singular", "--svg", str(tmp_path / "s.svg"), "--json"])
    n = len(drawn["singular_configurations"])
    assert n == 2  # the rocker's two limit positions (crank and coupler collinear)
    assert page.count('<figure class="singular">') == n
    rows = _table(page, "singular")
    assert len(rows) == n
    for row, s in zip(rows, drawn["singular_configurations"], strict=True):
        assert float(row[2].split()[0]) == pytest.approx(np.degrees(s["input_wrapped"]), abs=1e-3)
    assert page.count('<figure class="sweep">') == 1
    assert page.count('<figure class="skeleton">') == 1


def test_markdown_has_the_same_numbers_and_its_pictures_beside_it(fourbar_report):
    h, md = fourbar_report
    text = md.read_text()
    page = h.read_text()
    assert text.startswith("# screwkin report: fourbar_crank_rocker.urdf")
    assert "| Gruebler (planar) | 3(N-1-J) + sum f = 3(4-1-4) + 4 | 1 |" in text
    det = re.search(r"det A in sympy syntax.*?</p>\s*<pre>(.*?)</pre>", page, re.S).group(1)
    assert "```text\n" + htmllib.unescape(det) + "\n```" in text
    for link, value in (r[:2] for r in _table(page, "links-1")):
        assert f"| {link} | {value} |" in text
    pictures = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert pictures and all(p.startswith("fourbar_files/") for p in pictures)
    for p in pictures:
        assert (md.parent / p).stat().st_size > 1000
    assert sum("singular" in p for p in pictures) == page.count('<figure class="singular">')
    assert json.loads((md.parent / "fourbar_files" / "data.json").read_text())["file"] == FOURBAR


@pytest.mark.skipif(chromium() is None, reason="Chromium is not installed (.ci/run installs it)")
def test_opens_and_renders_in_headless_chromium(fourbar_report, tmp_path):
    from PIL import Image

    from screwkin.present.view import screenshot

    h = fourbar_report[0]
    page = h.read_text()
    assert '<figure class="view">' in page  # Chromium is here: the view is in
    with tempfile.TemporaryDirectory() as profile:
        p = subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu", f"--user-data-dir={profile}",
                            "--disable-background-networking", "--dump-dom", h.resolve().as_uri()],
                           capture_output=True, text=True, timeout=120)
    dom = p.stdout
    assert "<title>screwkin report: fourbar_crank_rocker.urdf</title>" in dom
    for title in ("Topology and mobility", "Equations", "Newton iterations", "Singular configurations",
                  "Sweep of the input", "View"):
        assert f"<h2>{title}</h2>" in dom
    png = tmp_path / "page.png"
    screenshot(h, png, size=(1000, 1400))
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    assert img.shape[:2] == (1400, 1000)
    dark = (img.sum(axis=2) < 200).sum()
    coloured = ((img.max(axis=2) - img.min(axis=2)) > 80).sum()
    assert dark > 2000 and coloured > 200  # text, and the coloured links of the skeleton drawing


@pytest.mark.parametrize("argv, words", [
    ([FOURBAR], "give --html F.html and/or --md F.md"),
    ([FOURBAR, "--html", "/nonexistent-folder/r.html"], "/nonexistent-folder' does not exist"),
    ([FOURBAR, "--md", "."], "cannot write, it is a folder"),
    ([FOURBAR, "--html", "r.html", "--set", "rocker_joint=10deg", "--input", "crank_joint"], "not an input"),
    ([FOURBAR, "--html", "r.html", "--steps", "2"], "--steps must be at least 4"),
])
def test_bad_arguments_are_one_line_exit_2(argv, words, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["report", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err
    assert not (tmp_path / "r.html").exists()


def test_spatial_loop_gets_the_product_of_exponentials(tmp_path, capsys):
    h = tmp_path / "bennett.html"
    out = _json(capsys, ["report", str(ROBOTS / "bennett.urdf"), "--html", str(h), "--no-view", "--json"])
    assert out["written"] == [str(h)]
    text = _text(h.read_text())
    assert "no planar vector loops; the product-of-exponentials structure equations" in text
    assert "exp([xi1] th1)" in text
    assert "Newton's iterations are shown on the planar vector-loop equations only" in text
    assert "the view is left out (--no-view)" in text
    assert '<figure class="sweep">' in h.read_text()  # one input: its sweep


def test_serial_arm_says_why_there_is_no_sweep(tmp_path):
    h, md = tmp_path / "arm.html", tmp_path / "arm.md"
    argv = ["report", str(ROBOTS / "arm_6r.urdf"), "--no-view"]
    assert main([*argv, "--html", str(h), "--md", str(md)]) == 0
    text = _text(h.read_text())
    assert "chain to output link6" in text
    assert "no sweep: 6 inputs (joint1, joint2, joint3, joint4, joint5, joint6): give --sweep NAME" in text
    assert "no sweep: 6 inputs" in md.read_text()
    # reproducible: the same command writes the same bytes
    again = tmp_path / "again.html"
    assert main([*argv, "--html", str(again)]) == 0
    assert again.read_bytes() == h.read_bytes()
