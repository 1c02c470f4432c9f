"""Synthesis results shown as designs (issue 24 item 10): the targets written into the file
(<screwkin:targets>), read back and drawn by ``screwkin draw``; the coupler curve through the
path's points; function generation's targets in the angles typed.  Values are checked against
what the test itself computes: the poses and points as typed, coupler points by circle
intersection of the lengths written in the file, Freudenstein's mapping of x to phi and psi."""

import json
import math
import re

import numpy as np
import pinocchio as pin
import pytest
from conftest import circles

import screwkin
from screwkin.cli import main

POSES = [(0.0, 0.0, 0.0), (0.04, 0.02, math.radians(20)), (0.07, 0.06, math.radians(45))]
POSES_TEXT = "0,0,0; 0.04,0.02,20deg; 0.07,0.06,45deg"
PIVOTS_TEXT = "-0.03,-0.08; 0.10,-0.06"
POINTS = [(0.0, 0.0), (0.05, 0.02), (0.1, 0.05), (0.12, 0.1), (0.08, 0.12)]
POINTS_TEXT = "; ".join(f"{x},{y}" for x, y in POINTS)


def run_json(capsys, argv, code=0):
    got = main([*argv, "--json"])
    out = capsys.readouterr()
    assert got == code, out.err
    return json.loads(out.out), out.err


@pytest.fixture(scope="module")
def designs(tmp_path_factory):
    """The three kinds synthesized once: {kind: (file, JSON report)}."""
    import contextlib
    import io

    folder = tmp_path_factory.mktemp("designs")
    out = {}
    for kind, argv in (
        ("motion", ["--poses", POSES_TEXT, "--pivots", PIVOTS_TEXT]),
        ("path", ["--points", POINTS_TEXT]),
        ("function", ["--function", "log(x)", "--x-range", "1:2", "--input-range", "0:60deg",
                      "--output-range", "0:90deg"]),
    ):
        path = folder / f"{kind}.urdf"
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            assert main(["synthesize", kind, *argv, "-o", str(path), "--json"]) == 0
        out[kind] = (path, json.loads(buf.getvalue()))
    return out


# ------------------------------------------------------------------ the targets in the file


def test_the_file_carries_the_poses_as_typed_and_loads_without_a_warning(designs):
    path, _ = designs["motion"]
    warnings = []
    mech = screwkin.load(path, warn=warnings.append)
    assert warnings == [] and mech.spec.warnings == []
    got = mech.spec.targets
    assert [t.kind for t in got] == ["pose"] * 3
    assert {t.link for t in got} == {"coupler_frame"} and {t.input for t in got} == {"crank_joint"}
    for t, (x, y, th) in zip(got, POSES):
        np.testing.assert_allclose(t.xyz, (x, y, 0.0), rtol=0, atol=1e-15)
        assert t.yaw == pytest.approx(th, abs=1e-15)
    assert got[0].value == 0.0  # the file is drawn at the first position


def test_pinocchio_reads_the_file_as_if_the_element_were_not_there(designs):
    path, _ = designs["path"]
    text = path.read_text()
    assert "<screwkin:targets>" in text and 'xmlns:screwkin="urn:screwkin:urdf"' in text
    bare = re.sub(r"\s*<screwkin:targets>.*</screwkin:targets>", "", text, flags=re.S)
    bare = bare.replace(' xmlns:screwkin="urn:screwkin:urdf"', "")
    assert "screwkin:" not in bare
    a, b = pin.buildModelFromXML(text), pin.buildModelFromXML(bare)
    assert list(a.names) == list(b.names) and [f.name for f in a.frames] == [f.name for f in b.frames]
    q = pin.neutral(a)
    da, db = a.createData(), b.createData()
    pin.framesForwardKinematics(a, da, q)
    pin.framesForwardKinematics(b, db, q)
    for k in range(a.nframes):
        np.testing.assert_allclose(da.oMf[k].homogeneous, db.oMf[k].homogeneous, rtol=0, atol=0)


@pytest.mark.parametrize("edit, says", [
    ('kind="point"', "kind 'dot'"),
    ('link="coupler_point"', "link 'nowhere'"),
    ('input="crank_joint"', "input 'nojoint'"),
])
def test_a_broken_target_refuses_the_file_naming_the_problem(designs, tmp_path, capsys, edit, says):
    path, _ = designs["path"]
    bad_value = {"kind": "dot", "link": "nowhere", "input": "nojoint"}[edit.split("=")[0]]
    text = path.read_text().replace(edit, f'{edit.split("=")[0]}="{bad_value}"', 1)
    bad = tmp_path / "bad.urdf"
    bad.write_text(text)
    assert main(["mobility", str(bad)]) == 1
    err = capsys.readouterr().err
    assert "bad.urdf" in err and says in err and "Traceback" not in err


# ------------------------------------------------------------------ function generation as typed


def test_function_targets_are_reported_in_the_angles_typed(designs, capsys, tmp_path):
    _, report = designs["function"]
    x0, x1, p0, p1, s0, s1 = 1.0, 2.0, 0.0, 60.0, 0.0, 90.0
    xs = (x0 + x1) / 2 - (x1 - x0) / 2 * np.cos((2 * np.arange(1, 4) - 1) * np.pi / 6)  # Chebyshev, n = 3
    phi = p0 + (xs - x0) / (x1 - x0) * (p1 - p0)
    psi = s0 + (np.log(xs) - math.log(x0)) / (math.log(x1) - math.log(x0)) * (s1 - s0)
    typed = [p["as_typed"] for p in report["precision"]]
    np.testing.assert_allclose([t["x"] for t in typed], xs, rtol=0, atol=1e-12)
    np.testing.assert_allclose([t["phi_deg"] for t in typed], phi, rtol=0, atol=1e-9)
    np.testing.assert_allclose([t["psi_deg"] for t in typed], psi, rtol=0, atol=1e-9)
    np.testing.assert_allclose([t["psi_reached_deg"] for t in typed], psi, rtol=0, atol=1e-9)  # 3 points: exact
    assert all(0.0 <= t["psi_deg"] <= 90.0 for t in typed)  # inside --output-range, not -171 deg
    for key in ("target", "input_deg", "value", "error_deg"):  # the existing keys are kept
        assert key in report["precision"][0]
    # the text's table says the same numbers
    assert main(["synthesize", "function", "--function", "log(x)", "--x-range", "1:2", "--input-range", "0:60deg",
                 "--output-range", "0:90deg", "-o", str(tmp_path / "f.urdf")]) == 0
    text = capsys.readouterr().out
    for ph, ps in zip(phi, psi):
        assert f"phi {ph:.6g} deg -> psi {ps:.6g} deg" in text
    assert "psi -1" not in text
