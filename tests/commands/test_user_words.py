"""What a new user trips on (issue 43 items 5-8): the unit typed is the unit shown (tables, plots, reports),
words that say what they measure, one lettering, one parse of counts, an answer that fits a screen with the
explanations behind --explain, and when --workers helps."""

from __future__ import annotations

import math

import pytest

from conftest import ROBOTS
from screwkin.cli import main

FOURBAR = str(ROBOTS / "fourbar_crank_rocker.urdf")


def _out(argv, capsys, code=0):
    got = main(argv)
    out, err = capsys.readouterr()
    assert got == code, err
    return out, err


# ------------------------------------------------------------------ item 5: units
def _captured_figures(monkeypatch, module):
    """The matplotlib figures ``module`` would write, kept (the plot is checked, not its pixels)."""
    figures = []
    monkeypatch.setattr(module, "write_figure", lambda fig, path, **kw: figures.append(fig))
    return figures


def _curve(fig, row_word, name):
    ax = next(a for a in fig.axes if row_word in a.get_ylabel())
    line = next(ln for ln in ax.get_lines() if ln.get_label().startswith(name))
    return ax, line


def test_sweep_plot_draws_rates_in_the_rpm_typed(tmp_path, monkeypatch, capsys):
    """--rate 120rpm: the text table says rpm, so does the plot -- the crank's omega is 120 (the rate typed),
    not 720 deg/s, and alpha is in rpm/s."""
    pytest.importorskip("matplotlib")
    import screwkin.present.plots as plots

    figures = _captured_figures(monkeypatch, plots)
    out, _ = _out(["sweep", FOURBAR, "--input", "crank_joint", "--from", "40deg", "--to", "400deg", "--steps", "12",
                   "--rate", "120rpm", "--plot", str(tmp_path / "s.png")], capsys)
    assert "omega crank [rpm]" in out
    (fig,) = figures
    ax, crank = _curve(fig, "omega", "crank")
    assert ax.get_ylabel().endswith("[rpm]") and crank.get_label().endswith("[rpm]")
    assert list(crank.get_ydata()) == pytest.approx([120.0] * 13)
    ax, _ = _curve(fig, "alpha", "rocker")
    assert ax.get_ylabel().endswith("[rpm/s]")


def test_sweep_plot_draws_deg_per_s_typed_and_keeps_its_default(tmp_path, monkeypatch, capsys):
    pytest.importorskip("matplotlib")
    import screwkin.present.plots as plots

    figures = _captured_figures(monkeypatch, plots)
    for rate in (["--rate", "90deg/s"], []):
        _out(["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "3", *rate,
              "--plot", str(tmp_path / "s.png")], capsys)
    typed, default = figures
    _, crank = _curve(typed, "omega", "crank")
    assert crank.get_label().endswith("[deg/s]") and list(crank.get_ydata()) == pytest.approx([90.0] * 4)
    _, crank = _curve(default, "omega", "crank")  # per 1 rad/s of the input, drawn in deg/s as before
    assert list(crank.get_ydata()) == pytest.approx([math.degrees(1.0)] * 4)


def test_report_sweeps_in_the_rpm_typed(tmp_path, monkeypatch, capsys):
    """report --rate crank_joint=120rpm: the sweep section says 120 rpm (not 12.5664 rad/s) and its figure draws
    omega in rpm."""
    pytest.importorskip("matplotlib")
    import screwkin.commands.report as report

    figures = []
    real = report.motion_figure
    monkeypatch.setattr(report, "motion_figure", lambda *a, **k: figures.append(real(*a, **k)) or figures[-1])
    md = tmp_path / "r.md"
    _out(["report", FOURBAR, "--set", "crank_joint=40deg", "--rate", "crank_joint=120rpm", "--md", str(md),
          "--no-view", "--steps", "24"], capsys)
    text = md.read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith("crank_joint moved"))
    assert "120 rpm" in line and "rad/s" not in line and "from 40 deg" in line
    (fig,) = figures
    _, crank = _curve(fig, "omega", "crank")
    assert list(crank.get_ydata()) == pytest.approx([120.0] * len(crank.get_ydata()))


# ------------------------------------------------------------------ item 6: words and conventions
WATT = str(ROBOTS / "watt_sixbar.urdf")


def test_a_ternary_links_angle_names_the_line_it_is_measured_along(capsys):
    """The Watt rocker (pivot rocker_joint at (0.12, 0), carrying joint_F at (0.0454, 0.0392) and the loop
    joint B at (-0.0012, 0.0900) in its frame, robots/watt_sixbar.urdf): its angle, 40.76 deg, is that of
    rocker_joint to joint_F, not of rocker_joint to B (90.76 deg); the text and JSON now say so."""
    import json

    out, _ = _out(["solve", WATT, "--set", "crank_joint=0", "--json"], capsys)
    links = json.loads(out)["solutions"][0]["links"]
    rocker = links["rocker"]
    assert rocker["angle_along"] == ["rocker_joint", "joint_F"]
    assert math.degrees(rocker["angle"]) == pytest.approx(math.degrees(math.atan2(0.03917235122948064,
                                                                                  0.04544806815645969)), abs=1e-9)
    assert abs(math.degrees(rocker["angle"]) - math.degrees(math.atan2(0.08999211311152194, -0.001191460332130287))) > 45
    assert links["coupler"]["angle_along"] == ["coupler_joint", "joint_E"]
    out, _ = _out(["solve", WATT, "--set", "crank_joint=0"], capsys)
    row = next(line for line in out.splitlines() if line.startswith("rocker "))
    assert row.split()[1] == "40.7585" and row.endswith("rocker_joint to joint_F")
    out, _ = _out(["sweep", WATT, "--input", "crank_joint", "--from", "0", "--to", "90deg", "--steps", "3"], capsys)
    assert "rocker: rocker_joint to joint_F" in out
    out, _ = _out(["equations", WATT, "--set", "crank_joint=0"], capsys)
    assert "the line rocker_joint to joint_F" in out


def test_start_takes_the_symbol_as_equations_writes_it(capsys):
    out, _ = _out(["equations", FOURBAR, "--set", "crank_joint=30deg"], capsys)
    assert "θ3" in out and "θ4" in out
    greek, _ = _out(["solve", FOURBAR, "--set", "crank_joint=30deg", "--start", "θ3=30deg,θ4=80deg"], capsys)
    latin, _ = _out(["solve", FOURBAR, "--set", "crank_joint=30deg", "--start", "theta3=30deg,theta4=80deg"], capsys)
    assert greek == latin and "θ3 = 18.8879 deg" in greek
    assert main(["solve", FOURBAR, "--set", "crank_joint=30deg", "--start", "θ7=30deg"]) == 2
    assert "'θ7'" in capsys.readouterr().err


def test_a_synthesized_file_letters_its_pivots_one_way_and_reached_says_within_what(tmp_path, capsys):
    """The file's comment named the pivots A0 and B0, the text A and D (draw's letters): the comment now names
    the joints themselves.  "reached: yes" beside a structural error: "reached" says its tolerance, and the
    structural error says it is between the precision points."""
    out_file = tmp_path / "f.urdf"
    out, _ = _out(["synthesize", "function", "--function", "log(x)", "--x-range", "1:2", "--input-range",
                   "30deg:120deg", "--output-range", "240deg:330deg", "-o", str(out_file)], capsys)
    comment = out_file.read_text().split("-->")[0]
    assert "A0" not in comment and "B0" not in comment
    assert "rocker's pivot rocker_joint to the crank's crank_joint" in comment
    assert "A crank_joint (0.1, 0)" in out and "D rocker_joint (0, 0)" in out
    assert "reached (within 1e-09 rad)" in out
    assert "structural error (the output's miss between the precision points)" in out
    assert "between them the output is off by up to 0.4203 deg (the structural error)" in out


@pytest.mark.slow
def test_the_two_transmission_ranges_have_their_own_names(tmp_path, capsys):
    """The written design's range (between its precision positions, screwkin's sweep) and each searched design's
    (over the whole motion) were both `transmission_angle_range`: the keys stay, each gets a name of its own."""
    import json

    out, _ = _out(["synthesize", "function", "--function", "log(x)", "--x-range", "1:2", "--input-range",
                   "30deg:120deg", "--output-range", "240deg:330deg", "--points", "5", "--generations", "3",
                   "--min-transmission", "20deg", "-o", str(tmp_path / "f.urdf"), "--json"], capsys)
    d = json.loads(out)
    assert d["transmission_angle_range_between_positions"] == d["transmission_angle_range"]
    for design in d["search"]["designs"]:
        assert design["transmission_angle_range_over_motion"] == design["transmission_angle_range"]


@pytest.mark.parametrize("argv", [
    ["mobility", FOURBAR, "--set", "crank_joint=30deg", "--mode", "2_0"],
    ["mobility", FOURBAR, "--set", "crank_joint=30deg", "--mode", "٢"],
    ["sweep", FOURBAR, "--input", "crank_joint", "--from", "0", "--to", "1", "--steps", "1_0"],
    ["synthesize", "chains", "--links", "4_0", "--dof", "1"],
])
def test_a_count_with_an_underscore_is_refused(argv, capsys):
    """Python's int() reads "2_0" as 20: --mode 2_0 chose mode 20 ("these inputs give 2 assembly modes")."""
    assert main(argv) == 2
    assert "expected a whole number" in capsys.readouterr().err


# ------------------------------------------------------------------ item 7: an answer that fits a screen
SCREEN = 40  # lines: a terminal's screen
# each command on the bundled four-bar as a new user runs it (the ones that take the file; files go to tmp)
COMMANDS = {
    "mobility": [],
    "info": [],
    "solve": ["--set", "crank_joint=30deg", "--rate", "60rpm"],
    "screws": [],
    "singularities": [],
    "statics": ["--gravity"],
    "equations": [],
    "sweep": ["--input", "crank_joint", "--from", "0", "--to", "360deg"],
    "dynamics": ["--input", "crank_joint", "--speed", "60rpm"],
    "draw": ["--svg", "{tmp}/d.svg"],
    "export": ["--mjcf", "{tmp}/e.xml"],
    "map": ["--x", "crank_joint=0:360deg:8", "--y", "rocker_joint=0:1:8"],
}
# what --explain brings back, by command (it was all printed before)
EXPLAINED = {
    "mobility": ["  how: order 1", "exactly constrained if you make coupler_rocker spherical",
                 "as Chrono removes them", "rank of K 2 (generic 2, drop 0)"],
    "singularities": ["  how: order 1"],
    "statics": ["coupler_rocker: 3 of its 5 rows", "as Chrono removes them"],
    "equations": ["    A = [", "    B = [", "unknown rates per unit input rate, A^-1 B:"],
}


def _argv(name, tmp_path, *extra):
    return [name, FOURBAR, *(a.replace("{tmp}", str(tmp_path)) for a in COMMANDS[name]), *extra]


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_the_default_text_of_each_command_fits_a_screen(name, tmp_path, capsys):
    out, _ = _out(_argv(name, tmp_path), capsys)
    lines = out.rstrip("\n").splitlines()
    assert 0 < len(lines) <= SCREEN, f"{name}: {len(lines)} lines\n{out}"
    for words in EXPLAINED.get(name, ()):
        assert words not in out, f"{name} explains by default: {words!r}"


@pytest.mark.parametrize("name", sorted(EXPLAINED))
def test_explain_brings_the_explanations_back(name, tmp_path, capsys):
    out, _ = _out(_argv(name, tmp_path, "--explain"), capsys)
    for words in EXPLAINED[name]:
        assert words in out, f"{name} --explain lacks {words!r}"


def test_mobility_answers_first_and_json_keeps_everything(capsys):
    import json

    out, _ = _out(["mobility", FOURBAR], capsys)
    assert out.splitlines()[0] == "M = 1, actuated by crank_joint: constrained mechanism (properly actuated)"
    assert "redundant constraints: 3, 3 at coupler_rocker (the loop is planar) (--explain names them" in out
    d = json.loads(_out(["mobility", FOURBAR, "--json"], capsys)[0])
    assert d["exactly_constrained_by"]["overconstraint"] == 0 and len(d["redundant_wrenches"]) == 3
    assert d["local"]["decided_by"].startswith("order 1")


# ------------------------------------------------------------------ item 8: --workers
def _square_after(x):
    import time

    time.sleep(0.05 * (3 - x % 3))  # uneven tasks: the next free process takes the next one
    return x * x


def test_the_local_process_pool_maps_in_order_and_leaves_no_server():
    """synthesize --workers N: N local processes forked from a fork server (a Dask LocalCluster took 3 to 9 s to
    start and made the README's search 2.6 times slower on 2 loaded cores); the results in the tasks' order."""
    from multiprocessing import forkserver

    from screwkin.parallel.pool import process_pool

    with process_pool(2, ["math"]) as (mapper, how):
        assert mapper(_square_after, range(7)) == [x * x for x in range(7)]
    assert how in ("local processes (forkserver)", "local processes (spawn)")
    assert getattr(forkserver._forkserver, "_forkserver_pid", None) is None  # stopped and waited for


def test_synthesize_workers_says_when_it_helps(capsys):
    assert main(["synthesize", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "it helps only with N idle cores" in text


def test_dynamics_flywheel_speaks_the_rpm_typed(capsys):
    """dynamics --speed 120rpm said the flywheel's speed as 12.5664 rad/s only."""
    out, _ = _out(["dynamics", FOURBAR, "--input", "crank_joint", "--speed", "120rpm"], capsys)
    line = next(ln for ln in out.splitlines() if ln.startswith("flywheel:"))
    assert f"at 120rpm ({4 * math.pi:.6g} rad/s)" in line
