"""report's positions, velocities and accelerations in the user's quantities (issue 24 items 1, 2, 8):
the offset slider-crank robots/slider_crank_offset.urdf against its closed form written here.

Geometry from the URDF (its comment and joints): the crank (r = 0.05 m) turns about the ground's
origin and is drawn at 60 deg at crank_joint = 0, so its absolute angle is t = 60 deg + crank_joint;
the rod (l = 0.15 m) runs from the crank tip to the slider's pin, which slides on the line y = e =
0.02 m (slider_joint's origin x0 = 0.1731791173126931 m, axis +x).  With the pin at (x, e):
    (x - r cos t)^2 + (e - r sin t)^2 = l^2  ->  x = r cos t + sqrt(l^2 - (r sin t - e)^2)
(the + root: the drawn mode, pin to the right of the crank tip); slider_joint = x - x0.  Rates by
differentiating in t (t' = w, t'' = 0), the rod's absolute angle phi = atan2(e - r sin t, x - r cos t)."""

import json
import math
import re

import numpy as np
import pytest
from conftest import ROBOTS

import screwkin
from screwkin.analysis.motion.planar import LinkAngles
from screwkin.analysis.position.position import PositionSolver
from screwkin.cli import main

SLIDER_CRANK = str(ROBOTS / "slider_crank_offset.urdf")
R, L, E, X0 = 0.05, 0.15, 0.02, 0.1731791173126931
DRAWN = math.radians(60.0)


def closed_form(t, w):
    """Slider x, x', x'' and the rod's phi, omega, alpha at absolute crank angle t, rate w (alpha_crank 0)."""
    s = R * math.sin(t) - E
    root = math.sqrt(L**2 - s**2)
    x = R * math.cos(t) + root
    ds = R * math.cos(t) * w  # s'
    dds = -R * math.sin(t) * w**2  # s''
    xd = -R * math.sin(t) * w - s * ds / root
    xdd = -R * math.cos(t) * w**2 - (ds**2 + s * dds) / root - (s * ds) ** 2 / root**3
    phi = math.atan2(-s, root)  # from the crank tip to the pin: (root, -s)
    # sin phi = -s / l  ->  omega cos phi = -s'/l ; alpha cos phi - omega^2 sin phi = -s''/l
    omega = -ds / (L * math.cos(phi))
    alpha = (-dds / L + omega**2 * math.sin(phi)) / math.cos(phi)
    return x, xd, xdd, phi, omega, alpha


def test_link_angles_do_not_move_with_a_prismatic_child():
    """The ground's vector-loop line runs from the crank pivot to where slider_joint is mounted: a constant
    angle atan2(e, x0), whatever the slider's position (it followed the slider before: 7.75 deg at 30 deg)."""
    mech = screwkin.load(SLIDER_CRANK)
    solver = PositionSolver(mech, ["crank_joint"])
    qs = [solver.solve({"crank_joint": math.radians(a)}).solutions[0].q for a in (30, 100, 250)]
    angles = LinkAngles(mech, mech.topology(qs[0]))
    for q in qs:
        assert angles(q)["ground"] == pytest.approx(math.atan2(E, X0), abs=1e-12)
    batch = angles.batch(np.array(qs))
    np.testing.assert_allclose(batch["ground"], math.atan2(E, X0), rtol=0, atol=1e-12)
    for q, rod in zip(qs, batch["rod"]):
        assert rod == pytest.approx(angles(q)["rod"], abs=1e-12)


PHI0 = math.atan2(-0.02330127018922193, 0.1481791173126931)  # the rod's pin in the rod's frame (loop_joint link1)


def _md_tables(text: str, section: str) -> list:
    """The Markdown tables of ``section`` (## title), each as {first cell: row cells}, with its header."""
    body = text.split(f"## {section}\n", 1)[1].split("\n## ", 1)[0]
    out = []
    for block in re.split(r"\n\s*\n", body):
        lines = [ln for ln in block.splitlines() if ln.startswith("|")]
        if len(lines) < 3:
            continue
        cells = [[c.strip().replace("\\", "") for c in ln.strip("|").split(" | ")] for ln in lines]
        out.append((cells[0], {r[0]: r for r in cells[2:]}))
    return out


@pytest.fixture(scope="module", params=[30.0, -30.0])
def report(request, tmp_path_factory):
    """The report at crank_joint = 30 deg (crank at 90 deg: the rod translates) and -30 deg, 10 rad/s."""
    d = tmp_path_factory.mktemp("quantities")
    md = d / "r.md"
    assert main(["report", SLIDER_CRANK, "--set", f"crank_joint={request.param}deg", "--rate", "crank_joint=10",
                 "--point", "P=rod:0.05,0,0", "--steps", "72", "--no-view", "--md", str(md)]) == 0
    data = json.loads((d / "r_files" / "data.json").read_text())
    return request.param, md.read_text(), data


def test_markdown_tables_against_the_closed_form(report):
    deg, text, _ = report
    x, xd, xdd, phi, omega, alpha = closed_form(DRAWN + math.radians(deg), 10.0)
    tables = _md_tables(text, "Positions, velocities and accelerations")
    (jh, joints), (lh, links) = tables[0], tables[1]
    assert jh[:3] == ["joint", "value [rad or m*]", "(deg, d*)"] and jh[3].startswith("rate") and lh[:4] == [
        "link", "angle [deg]", "omega [rad/s]", "alpha [rad/s^2]"]
    s = joints["slider_joint"]
    assert float(s[1]) == pytest.approx(x - X0, abs=1e-9)  # from where the file placed the joint (issue 33)
    assert s[2].startswith("d = ") and float(s[2].split()[2]) == pytest.approx(x, rel=1e-6)  # from the crank pivot
    assert "* a slide's value is measured from where the file placed its joint" in text
    assert float(s[3]) == pytest.approx(xd, rel=1e-5, abs=1e-9)
    assert float(s[4]) == pytest.approx(xdd, rel=1e-5, abs=1e-9)
    loop = joints["rod_slider (loop)"]  # the loop joint is a coordinate like the others
    assert float(loop[1]) == pytest.approx(PHI0 - phi, abs=1e-8)
    assert float(loop[3]) == pytest.approx(-omega, rel=1e-5, abs=1e-9)
    assert float(loop[4]) == pytest.approx(-alpha, rel=1e-5, abs=1e-9)
    assert "ground" not in links and set(links) == {"crank", "rod", "slider"}
    rod = links["rod"]
    assert float(rod[1]) == pytest.approx(math.degrees(phi), abs=1e-4)
    assert float(rod[2]) == pytest.approx(omega, rel=1e-5, abs=1e-9)
    assert float(rod[3]) == pytest.approx(alpha, rel=1e-5, abs=1e-9)
    assert float(links["crank"][2]) == pytest.approx(10.0)
    # the slider's velocity, a signed vector in world axes (it was |v origin|, a speed): xd along +x
    assert [float(c) for c in links["slider"][4].split()] == pytest.approx([xd, 0, 0], rel=1e-5, abs=1e-9)
    assert "input rates crank_joint = 10 rad/s" in text


def test_data_json_against_the_closed_form_and_solve(report, capsys):
    deg, _, data = report
    x, xd, xdd, phi, omega, alpha = closed_form(DRAWN + math.radians(deg), 10.0)
    sol = data["solve"]["solutions"][0]
    # the closure converges to about 1e-11 m: the closed form's values to 1e-9
    assert sol["joints"]["slider_joint"] == pytest.approx(x - X0, abs=1e-9)
    assert sol["rates"]["slider_joint"] == pytest.approx(xd, abs=1e-8)
    assert sol["accelerations"]["slider_joint"] == pytest.approx(xdd, abs=1e-7)
    assert sol["loop_joints"]["rod_slider"] == pytest.approx(PHI0 - phi, abs=1e-8)
    rod = sol["links"]["rod"]
    assert (rod["angle"], rod["omega"], rod["alpha"]) == pytest.approx((phi, omega, alpha), abs=1e-7)
    assert "ground" not in sol["links"]
    assert sol["points"]["P"]["link"] == "rod"
    capsys.readouterr()
    assert main(["solve", SLIDER_CRANK, "--set", f"crank_joint={deg}deg", "--rate", "crank_joint=10",
                 "--point", "P=rod:0.05,0,0", "--json"]) == 0
    solved = json.loads(capsys.readouterr().out)
    assert set(solved["solutions"][0]) <= set(sol)  # every key solve writes, the report writes too
    assert {"joints", "rates", "accelerations", "links", "points"} <= set(sol)
    assert data["solve"]["characteristic_length"] == solved["characteristic_length"]


def test_sweep_section_strokes_and_time_ratio_are_sweeps(report, capsys):
    """The stroke of the offset slider-crank, sqrt((l+r)^2 - e^2) - sqrt((l-r)^2 - e^2), and its time ratio:
    the dead centres are at crank angles asin(e/(l+r)) (extended) and pi + asin(e/(l-r)) (folded), so the
    crank turns pi - asin(e/(l+r)) + asin(e/(l-r)) one way and the rest of the turn back."""
    _, text, data = report
    stroke = math.sqrt((L + R) ** 2 - E**2) - math.sqrt((L - R) ** 2 - E**2)
    one_way = math.pi - math.asin(E / (L + R)) + math.asin(E / (L - R))
    ratio = max(one_way, 2 * math.pi - one_way) / min(one_way, 2 * math.pi - one_way)
    (st,) = data["sweep"]["strokes"]
    assert st["coordinate"] == "slider_joint"
    assert st["stroke"] == pytest.approx(stroke, rel=1e-6)
    assert st["time_ratio"] == pytest.approx(ratio, rel=1e-5)
    section = text.split("## Sweep of the input\n", 1)[1].split("\n## ", 1)[0]
    capsys.readouterr()
    assert main(["sweep", SLIDER_CRANK, "--input", "crank_joint", "--steps", "72", "--from", "0",
                 "--to", "360deg"]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("slider slider_joint: stroke"))
    assert line.split(" (ends")[0] in section  # the same stroke, written by the same function
    assert float(re.search(r"time ratio ([0-9.]+)", section).group(1)) == pytest.approx(ratio, rel=1e-5)
    # the sweep's absolute quantities per step, as sweep --json has them, and the figure says what it shows
    sw = data["sweep"]
    assert {"links", "loop_joints", "points", "coordinates", "joints", "rates", "accelerations"} <= set(sw)
    assert "ground" not in sw["links"] and len(sw["links"]["rod"]["omega"]) == len(sw["values"])
    # the sweep starts at the configuration analysed, at the input rate of the positions section (10 rad/s)
    deg = report[0]
    *_, omega, alpha = closed_form(DRAWN + math.radians(deg), 10.0)
    assert sw["input_rate"] == 10.0 and sw["values"][0] == pytest.approx(math.radians(deg))
    assert (sw["links"]["rod"]["omega"][0], sw["links"]["rod"]["alpha"][0]) == pytest.approx((omega, alpha), abs=1e-7)
    assert "the links' absolute angle, omega and alpha" in section


def test_tables_in_the_units_typed(tmp_path, capsys):
    """--rate crank_joint=90deg (deg/s): omega, rates in deg/s and alpha in deg/s^2, in report and solve alike;
    --rate 10rpm: omega in rpm.  The values are the closed form's converted by hand here."""
    w = math.radians(90.0)
    x, xd, xdd, phi, omega, alpha = closed_form(DRAWN - math.radians(30.0), w)
    md = tmp_path / "u.md"
    args = ["--set", "crank_joint=-30deg", "--rate", "crank_joint=90deg", "--point", "P=rod:0.05,0,0"]
    assert main(["report", SLIDER_CRANK, *args, "--steps", "8", "--no-view", "--md", str(md)]) == 0
    text = md.read_text()
    (jh, joints), (lh, links), (ph, _) = _md_tables(text, "Positions, velocities and accelerations")[:3]
    assert jh[3:] == ["rate [deg/s or m/s]", "acceleration [deg/s^2 or m/s^2]"]
    assert lh[2:4] == ["omega [deg/s]", "alpha [deg/s^2]"] and ph[3:] == ["velocity [m/s]", "acceleration [m/s^2]"]
    assert float(links["rod"][2]) == pytest.approx(math.degrees(omega), rel=1e-5)
    assert float(links["rod"][3]) == pytest.approx(math.degrees(alpha), rel=1e-5)
    assert float(joints["crank_joint"][3]) == pytest.approx(90.0)
    assert float(joints["slider_joint"][3]) == pytest.approx(xd, rel=1e-5)  # a length's rate stays m/s
    assert "input rates crank_joint = 90 deg/s (1.5708 rad/s)" in text
    capsys.readouterr()
    assert main(["solve", SLIDER_CRANK, *args]) == 0
    solved = capsys.readouterr().out
    rod = next(ln.split() for ln in solved.splitlines() if ln.startswith("rod "))
    assert [float(c) for c in rod[2:4]] == pytest.approx([math.degrees(omega), math.degrees(alpha)], rel=1e-5)
    assert " ".join(links["rod"][1:]).split() == rod[1:]  # the one table builder
    capsys.readouterr()
    assert main(["solve", SLIDER_CRANK, "--set", "crank_joint=-30deg", "--rate", "crank_joint=10rpm"]) == 0
    solved = capsys.readouterr().out
    assert "omega [rpm]" in solved and "rate [rpm or m/s]" in solved
    crank = next(ln.split() for ln in solved.splitlines() if ln.startswith("crank "))
    assert float(crank[2]) == pytest.approx(10.0)
