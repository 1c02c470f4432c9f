"""singularities --ellipsoids: the numbers of screwkin.analysis.singularities.ellipsoids on the command line,
checked on a planar 2R arm against the singular values of its closed-form Jacobian."""

import json

import numpy as np
import pytest
from conftest import ROBOTS, screwkin_cli

ARM = """<robot name="arm2r">
  <link name="base"/><link name="upper"/><link name="fore"/><link name="hand"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0.4 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="wrist" type="fixed"><parent link="fore"/><child link="hand"/><origin xyz="0.25 0 0"/></joint>
</robot>"""


def test_planar_2r_point_ellipsoid_against_closed_form(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM)
    t1, t2 = 0.3, 1.1
    out = screwkin_cli("singularities", str(path), "--set", f"shoulder={t1}", "--set", f"elbow={t2}", "--output", "hand",
              "--point", "--ellipsoids", "--length", "0.5", "--json")
    assert out.returncode == 0, out.stderr
    e = json.loads(out.stdout)["ellipsoids"]
    l1, l2, L = 0.4, 0.25, 0.5
    J = np.array([[-l1 * np.sin(t1) - l2 * np.sin(t1 + t2), -l2 * np.sin(t1 + t2)],
                  [l1 * np.cos(t1) + l2 * np.cos(t1 + t2), l2 * np.cos(t1 + t2)]]) / L
    s = np.linalg.svd(J, compute_uv=False)
    assert e["rank"] == 2
    assert np.allclose(sorted(e["velocity_semi_axes"])[-2:], sorted(s), rtol=1e-9)
    finite = [f for f in e["force_semi_axes"] if f != "inf"]  # the z direction loads no input: "inf"
    assert e["force_semi_axes"].count("inf") == 1
    assert np.allclose(sorted(finite), sorted(1 / s), rtol=1e-9)
    assert e["isotropy"] == pytest.approx(0.0)  # the z direction is not reached: rank 2 of 3
    text = screwkin_cli("singularities", str(path), "--set", f"shoulder={t1}", "--set", f"elbow={t2}", "--output", "hand",
               "--point", "--ellipsoids", "--length", "0.5")
    assert "velocity and force ellipsoids" in text.stdout and "inf" in text.stdout


def test_ellipsoids_need_an_output():
    out = screwkin_cli("singularities", str(ROBOTS / "gough_stewart_6ups.urdf"), "--ellipsoids")
    assert out.returncode == 2 and "--output" in out.stderr and len(out.stderr.strip().splitlines()) == 1
