"""sweep's text table shows the links' omega and alpha in the units the --rate was typed in (issue 24 item 2).

Offset slider-crank of robots/slider_crank_offset.urdf: crank r = 0.05 m about the origin, drawn at 60 deg
(crank angle theta = 60 deg + crank_joint), rod l = 0.15 m, slider pin on y = e = 0.02 m.  The rod's angle
phi from r sin(theta) + l sin(phi) = e, so omega_rod = -r cos(theta) omega / (l cos(phi))."""

import numpy as np
import pytest

from screwkin.cli import main

from conftest import ROBOTS

R, L, E = 0.05, 0.15, 0.02


def _omega_rod(theta, omega):
    phi = np.arcsin((E - R * np.sin(theta)) / L)
    return -R * np.cos(theta) * omega / (L * np.cos(phi))


def _table(out):
    lines = out.split("absolute motion\n", 1)[1].splitlines()
    head = [h.strip() for h in lines[0].split("  ") if h.strip()]
    return head, [[c for c in line.split()] for line in lines[2:] if line.strip()]


def test_omega_in_rpm_as_typed(capsys):
    argv = ["sweep", str(ROBOTS / "slider_crank_offset.urdf"), "--input", "crank_joint", "--from", "0",
            "--to", "360deg", "--steps", "12", "--rows", "all", "--rate", "60rpm"]
    assert main(argv) == 0
    head, rows = _table(capsys.readouterr().out)
    assert "omega rod [rpm]" in head and "omega crank [rpm]" in head and "rod_slider (loop) [deg]" in head
    k_in, k_w, k_crank = head.index("input [deg]"), head.index("omega rod [rpm]"), head.index("omega crank [rpm]")
    for row in rows:
        theta = np.radians(60 + float(row[k_in]))
        expected = _omega_rod(theta, 2 * np.pi) * 60 / (2 * np.pi)  # rad/s -> rpm
        assert float(row[k_w]) == pytest.approx(expected, rel=1e-5, abs=1e-6)  # 6 digits printed
        assert float(row[k_crank]) == pytest.approx(60)


def test_no_rate_typed_no_rate_columns(capsys):
    argv = ["sweep", str(ROBOTS / "slider_crank_offset.urdf"), "--input", "crank_joint", "--from", "0",
            "--to", "360deg", "--steps", "12"]
    assert main(argv) == 0
    head, _ = _table(capsys.readouterr().out)
    assert not any(h.startswith("omega") for h in head)
