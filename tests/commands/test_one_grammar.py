"""One grammar per option, units and signs in tables (issue 33 items 3 and 4).

--rate/--accel (and dynamics' --speed) take NAME=VALUE on every command, a bare value where there is one input;
a sweep without --rate says its rates are per 1 rad/s of the input, in the text, the JSON and the plot.  Each
table column carries its unit, accelerations in the typed rate's unit per second (rpm -> rpm/s), velocities as
signed vectors; a slide's value says what it is measured from, and its absolute position d is given.  Values
are checked against the offset slider-crank's closed form (derived in closed_form below).

sweep's text table shows the links' omega and alpha in the units the --rate was typed in (issue 24 item 2).

Offset slider-crank of robots/slider_crank_offset.urdf: crank r = 0.05 m about the origin, drawn at 60 deg
(crank angle theta = 60 deg + crank_joint), rod l = 0.15 m, slider pin on y = e = 0.02 m.  The rod's angle
phi from r sin(theta) + l sin(phi) = e, so omega_rod = -r cos(theta) omega / (l cos(phi))."""

from __future__ import annotations

import json
import math
import numpy as np

import pytest

from conftest import ROBOTS
from screwkin.cli import main

SLIDER = str(ROBOTS / "slider_crank_offset.urdf")
FOURBAR = str(ROBOTS / "fourbar_crank_rocker.urdf")
FIVE_BAR = str(ROBOTS / "five_bar.urdf")
R, L, E = 0.05, 0.15, 0.02  # crank, rod, offset of robots/slider_crank_offset.urdf (its comment)
DRAWN = math.radians(60.0)  # the crank's absolute angle where the file draws it (crank_joint = 0)


def closed_form(t, w):
    """Offset slider-crank, crank pivot at the origin, slider on y = e: the slider pin at (x, e) with
    (x - r cos t)^2 + (e - r sin t)^2 = l^2, so x = r cos t + sqrt(l^2 - s^2), s = r sin t - e.  Differentiating
    at constant crank rate w: x' = -r w sin t - s s' / sqrt(.), s' = r w cos t; the rod's angle phi has
    sin phi = -s / l, so omega_rod = -s' / (l cos phi) and alpha_rod = (-s''/l + omega^2 sin phi) / cos phi with
    s'' = -r w^2 sin t."""
    s = R * math.sin(t) - E
    root = math.sqrt(L**2 - s**2)
    x = R * math.cos(t) + root
    ds, dds = R * math.cos(t) * w, -R * math.sin(t) * w**2
    xd = -R * math.sin(t) * w - s * ds / root
    phi = math.atan2(-s, root)
    omega = -ds / (L * math.cos(phi))
    alpha = (-dds / L + omega**2 * math.sin(phi)) / math.cos(phi)
    return x, xd, phi, omega, alpha


def _out(argv, capsys, code=0):
    got = main(argv)
    out, err = capsys.readouterr()
    assert got == code, err
    return out, err


# ------------------------------------------------------------------ item 3: one grammar
def test_rate_is_name_value_or_the_bare_value_of_the_one_input(capsys):
    a, _ = _out(["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "3",
                 "--rate", "120rpm", "--json"], capsys)
    b, _ = _out(["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "3",
                 "--rate", "crank_joint=120rpm", "--json"], capsys)
    da, db = json.loads(a), json.loads(b)
    assert da["rates"] == db["rates"] and da["input_rate"] == pytest.approx(4 * math.pi)
    assert da["rates_are"] == "at crank_joint 120 rpm"
    names = da["coordinates"]
    assert [row[names.index("crank_joint")] for row in da["rates"]] == pytest.approx([4 * math.pi] * 4)
    a, _ = _out(["solve", FOURBAR, "--set", "crank_joint=30deg", "--rate", "120rpm", "--accel", "2", "--json"], capsys)
    b, _ = _out(["solve", FOURBAR, "--set", "crank_joint=30deg", "--rate", "crank_joint=120rpm", "--accel",
                 "crank_joint=2", "--json"], capsys)
    assert json.loads(a)["solutions"][0]["accelerations"] == json.loads(b)["solutions"][0]["accelerations"]
    a, _ = _out(["dynamics", FOURBAR, "--input", "crank_joint", "--speed", "60rpm", "--steps", "4", "--json"], capsys)
    b, _ = _out(["dynamics", FOURBAR, "--input", "crank_joint", "--speed", "crank_joint=60rpm", "--steps", "4",
                 "--json"], capsys)
    assert json.loads(a)["efforts"] == json.loads(b)["efforts"]


def test_a_bare_rate_with_several_inputs_or_a_wrong_name_is_refused(capsys):
    _, err = _out(["solve", FIVE_BAR, "--set", "motor1=30deg,motor2=60deg", "--rate", "1"], capsys, 2)
    assert "--rate '1': give NAME=VALUE" in err and "inputs: motor1, motor2" in err
    _, err = _out(["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "1", "--rate",
                   "rocker_joint=1"], capsys, 2)
    assert "--rate rocker_joint: not an input (inputs: crank_joint)" in err
    _, err = _out(["dynamics", FOURBAR, "--input", "crank_joint", "--speed", "rocker_joint=1"], capsys, 2)
    assert "dynamics drives --input 'crank_joint' only" in err


def test_a_sweep_says_what_its_rates_are_for(tmp_path, capsys):
    out, _ = _out(["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "3"], capsys)
    assert "rates and accelerations per 1 rad/s of crank_joint (the velocity ratios" in out
    out, _ = _out(["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "3",
                   "--rate", "60rpm"], capsys)
    assert "rates and accelerations at crank_joint 60 rpm" in out
    out, _ = _out(["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "3",
                   "--csv", str(tmp_path / "s.csv"), "--chunk", "2"], capsys)
    assert "per 1 rad/s of crank_joint" in out  # the streamed summary too


def test_the_sweep_plot_says_the_input_rate(tmp_path):
    pytest.importorskip("matplotlib")
    import screwkin
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.analysis.motion.sweep import sweep
    from screwkin.present.plots import motion_figure

    mech = screwkin.load(FOURBAR)
    res = sweep(PositionSolver(mech, ["crank_joint"]), "crank_joint", 0.0, 1.0, 4)
    fig = motion_figure(res)
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert fig._suptitle.get_text() == "sweep of crank_joint, per 1 rad/s of crank_joint"
    assert any("rate (per 1 rad/s of crank_joint)" in lab for lab in labels)
    assert any("acceleration (per 1 rad/s of crank_joint)" in lab for lab in labels)
    fig = motion_figure(res, rate_words="at crank_joint 120 rpm")
    assert "at crank_joint 120 rpm" in fig._suptitle.get_text()


# ------------------------------------------------------------------ item 4: units and signs
def _row(text, first):
    return next(line.split() for line in text.splitlines() if line.startswith(first + " "))


@pytest.mark.parametrize("deg", [30.0, -100.0])
def test_solve_tables_units_and_signs_against_the_closed_form(deg, capsys):
    """--rate 120rpm: omega in rpm and alpha in rpm/s (it was rad/s^2 beside rpm), velocities as signed world
    vectors (they were |v|), and the slider's d (its x, from the crank pivot) beside its joint value."""
    w = 4 * math.pi
    x, xd, phi, omega, alpha = closed_form(DRAWN + math.radians(deg), w)
    out, _ = _out(["solve", SLIDER, "--set", f"crank_joint={deg}deg", "--rate", "120rpm"], capsys)
    head = next(line for line in out.splitlines() if line.startswith("link "))
    assert "omega [rpm]" in head and "alpha [rpm/s]" in head and "v origin x y z [m/s]" in head
    assert "|v" not in out
    rpm = 60 / (2 * math.pi)
    rod = _row(out, "rod")
    assert float(rod[2]) == pytest.approx(omega * rpm, rel=1e-5, abs=1e-9)  # signed
    assert float(rod[3]) == pytest.approx(alpha * rpm, rel=1e-5, abs=1e-9)
    slider = _row(out, "slider")
    assert [float(c) for c in slider[4:7]] == pytest.approx([xd, 0.0, 0.0], rel=1e-5, abs=1e-9)
    joint_head = next(line for line in out.splitlines() if line.startswith("joint "))
    assert "value [rad or m*]" in joint_head and "acceleration [rpm/s or m/s^2]" in joint_head
    sj = _row(out, "slider_joint")
    assert sj[2] == "d" and float(sj[4]) == pytest.approx(x, abs=1e-8)
    assert "* a slide's value is measured from where the file placed its joint" in out
    d, _ = _out(["solve", SLIDER, "--set", f"crank_joint={deg}deg", "--json"], capsys)
    assert json.loads(d)["solutions"][0]["guide_positions"]["slider_joint"] == pytest.approx(x, abs=1e-9)


def test_accelerations_are_in_the_rate_unit_per_second():
    from screwkin.present.tables import RateUnits
    from screwkin.units import parse_quantity, parse_value

    for typed, rate, accel in (("rpm", "rpm", "rpm/s"), ("rev/s", "rev/s", "rev/s^2"), ("deg", "deg/s", "deg/s^2"),
                               ("cm/s", "cm/s", "cm/s^2"), ("mm/s", "mm/s", "mm/s^2")):
        u = RateUnits.typed([parse_quantity("1" + typed)])  # the units.Quantity of --rate NAME=1<typed>
        linear = typed.startswith(("cm", "mm"))
        assert (u.rate(linear), u.acceleration(linear)) == (rate, accel)
        assert parse_value("1" + accel) == pytest.approx(parse_value("1" + rate))  # per second
    assert parse_value("60rpm/s") == pytest.approx(2 * math.pi)


def test_readme_says_what_the_tables_show():
    """The docs (the README's Command line section until issue 45: docs/reference/) say the unit typed is shown."""
    docs = ROBOTS.parent / "docs" / "reference"
    text = (docs / "options.md").read_text() + (docs / "notes" / "solve.md").read_text()
    assert "omega in rad/s)" not in text  # the passage that said the table is in rad/s whatever was typed
    assert "accelerations and alpha in rpm/s" in text and "--rate [NAME=]VALUE" in text
    assert "guide_positions" in text


# ---------------------------------------------------------------- folded in from test_sweep_rate_units.py
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
