"""Wrong words (issue 33 item 5): what a report says must be what the mechanism is.

What a new user trips on (issue 43 items 5-8): the unit typed is the unit shown (tables, plots, reports),
words that say what they measure, one lettering, one parse of counts, an answer that fits a screen with the
explanations behind --explain, and when --workers helps."""

from __future__ import annotations

import json
import math

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.analysis.position.position import PositionSolver
from screwkin.analysis.singular import classify, lost_direction
from screwkin.cli import main
from screwkin.model._pin import joint_axis
from screwkin.model.state import KinematicState

BALL = """<mujoco model="ball"><worldbody><body name="arm" pos="0 0 0.1"><joint name="ball" type="ball"/>
<inertial pos="0 0 0.1" mass="1" diaginertia="0.1 0.1 0.1"/></body></worldbody></mujoco>"""


def _out(argv, capsys, code=0):
    got = main(argv)
    out, err = capsys.readouterr()
    assert got == code, err
    return out, err


# ------------------------------------------------------------------ (a) a ball joint's axes are concurrent
def test_a_single_ball_joint_moves_spherically(tmp_path, capsys):
    p = tmp_path / "ball.xml"
    p.write_text(BALL)
    out, _ = _out(["mobility", str(p), "--json"], capsys)
    d = json.loads(out)
    assert d["motion_space"] == "spherical"
    out, _ = _out(["mobility", str(p)], capsys)
    assert "motion space: spherical (every joint axis passes through (0, 0, 0.1))" in out
    assert "neither all parallel" not in out
    # a mechanism whose balls are not concurrent stays spatial; the spherical four-bar stays spherical
    assert screwkin.load(ROBOTS / "delta_parallelogram.urdf").topology().motion_space == "spatial"
    assert screwkin.load(ROBOTS / "spherical_fourbar.urdf").topology().motion_space == "spherical"


# ------------------------------------------------------------------ (b) never a zero twist as a screw
def test_the_lost_direction_of_a_planar_output_stays_in_its_plane():
    """The output's motion map of a planar point: it moves along x only (a serial singularity: y is lost);
    round-off out of the plane (1e-17 in z) is larger than the vanishing in-plane singular value (0), so the
    plain SVD's second left singular vector is z -- the zero twist once projected onto the plane."""
    JV = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1e-17, 0.0]])
    naive = np.linalg.svd(JV)[0][:, 1]
    assert abs(naive[2]) == pytest.approx(1.0)  # the trap: out of the plane
    lost = lost_direction(JV, 2, normal=(0.0, 0.0, 1.0))
    assert np.allclose(np.abs(lost), [0, 1, 0, 0, 0, 0], atol=1e-12)
    lost = lost_direction(np.vstack([JV, np.zeros((3, 3))]), 2, normal=(0.0, 0.0, 1.0))  # (v, w) rows
    assert np.linalg.norm(lost) == pytest.approx(1.0)  # a unit twist in the plane: (vx, vy, wz) only
    assert np.abs(lost[[2, 3, 4]]).max() < 1e-12


def test_3rpr_serial_direction_at_a_zero_length_leg_is_a_translation_across_it(capsys):
    """Leg 1 of zero length: the platform's joint with it sits on its base pivot, and moves only along the leg;
    the platform loses the translation across the leg (its frame is at that joint: the lost twist is that
    translation, a screw of infinite pitch perpendicular to the leg's axis)."""
    mech = screwkin.load(ROBOTS / "planar_3rpr.urdf")
    q0 = mech.generic_configurations()[0].q
    st = KinematicState(mech, q0)
    w1 = st.joint_placement(mech.model.getJointId("wrist1")).translation[:2]
    frame2 = {c.name: st.frame_placement(c.frame1).translation[:2] for c in mech.cuts}
    anchors = {1: np.zeros(2), 2: frame2["wrist2"] - w1, 3: frame2["wrist3"] - w1}
    base = {1: np.array([0, 0.25]), 2: np.array([-0.2165063509461096, -0.125]),
            3: np.array([0.2165063509461096, -0.125])}
    values = {f"leg{i}": float(np.linalg.norm(base[1] + anchors[i] - base[i])) - st.leg_lengths[f"leg{i}"]
              for i in (1, 2, 3)}
    res = PositionSolver(mech, ["leg1", "leg2", "leg3"], output="platform").solve(values)
    for sol in res.solutions:
        rep = classify(mech, sol.q, ["leg1", "leg2", "leg3"], "platform")
        (serial,) = [t for t in rep.singular_twists if t.kind == "serial"]
        assert rep.serial and np.linalg.norm(serial.screw.direction) == pytest.approx(1.0)
        assert math.isinf(serial.screw.pitch)
        j = mech.model.getJointId("leg1")
        axis = KinematicState(mech, sol.q).joint_placement(j).rotation @ joint_axis(mech.model.joints[j])
        assert abs(np.dot(serial.screw.direction, axis)) < 1e-6
    text, _ = _out(["singularities", str(ROBOTS / "planar_3rpr.urdf"), "--output", "platform", "--set",
                    ",".join(f"{k}={v!r}" for k, v in values.items())], capsys)
    assert "serial singular direction" in text and "axis direction 0 0 0" not in text


# ------------------------------------------------------------------ (c) one lettering
def test_synthesize_letters_the_joints_as_its_drawing(tmp_path, capsys):
    out_file = tmp_path / "m.urdf"
    out, _ = _out(["synthesize", "motion", "--poses", "0,0,0; 0.05,0.02,20deg; 0.1,0.0,40deg", "--pivots",
                   "0,-0.1; 0.15,-0.1", "-o", str(out_file), "--json"], capsys)
    d = json.loads(out)
    drawn, _ = _out(["draw", str(out_file), "--png", str(tmp_path / "m.png"), "--json"], capsys)
    letters = {j["name"]: j["letter"] for j in json.loads(drawn)["joints"]}
    for role, pj in d["pivot_joints"].items():
        assert pj["letter"] == letters[pj["joint"]]
        x, y = d["pivots"][role]
        point = next(j["point"] for j in json.loads(drawn)["joints"] if j["name"] == pj["joint"])
        assert (x, y) == pytest.approx(tuple(point), abs=1e-9)  # the same joint, at the same place
    text, _ = _out(["synthesize", "motion", "--poses", "0,0,0; 0.05,0.02,20deg; 0.1,0.0,40deg", "--pivots",
                    "0,-0.1; 0.15,-0.1", "-o", str(out_file)], capsys)
    line = next(ln for ln in text.splitlines() if ln.startswith("joints [m]"))
    for name, letter in letters.items():
        assert f"{letter} {name} (" in line
    assert "A0" not in text and "B0" not in text


# ------------------------------------------------------------------ (d) compound joints named as mobility does
def test_reactions_name_compound_joints_as_mobility(capsys):
    delta = str(ROBOTS / "delta_parallelogram.urdf")
    mob, _ = _out(["mobility", delta, "--json"], capsys)
    compound = {j["name"] for j in json.loads(mob)["joints"] if "[" in j["name"]}
    assert "rod1a_top[S]" in compound
    out, _ = _out(["dynamics", delta, "--input", "arm1", "--speed", "60rpm", "--steps", "2", "--set", "arm2=0,arm3=0",
                   "--from", "0", "--to", "10deg", "--json"], capsys)
    reactions = json.loads(out)["reactions"]
    assert not any(n.endswith(("_x", "_y", "_z")) for n in reactions)
    assert "rod1a_top[S]" in reactions
    out, _ = _out(["statics", delta, "--output", "platform", "--wrench", "0 0 -10 0 0 0", "--gravity", "--json"],
                  capsys)
    d = json.loads(out)
    by_name = {r["joint"]: r for r in d["reactions"]}
    assert "rod1a_top[S]" in by_name and "rod1a_top_x" not in by_name
    assert all(not n.endswith(("_x", "_y", "_z")) for leg in d["legs"] for n in leg["joints"])
    # the compound's row is the wrench its first member passes on; the massless links inside pass it on to the
    # rod unchanged: Pinocchio's RNEA of the last member (into the rod) gives the same force
    mech = screwkin.load(delta)
    q = mech.generic_configurations()[0].q
    data = mech.model.createData()
    pin.rnea(mech.model, data, q, np.zeros(mech.nv), np.zeros(mech.nv))
    last = mech.model.getJointId("rod1a_top_z")
    f_last = data.oMi[last].rotation @ data.f[last].linear
    first = mech.model.getJointId("rod1a_top_x")
    f_first = data.oMi[first].rotation @ data.f[first].linear
    assert f_first == pytest.approx(f_last, abs=1e-6 * max(1.0, np.abs(f_last).max()))


# ------------------------------------------------------------------ (e) said once
def test_delta_singularities_say_adj_g_once(capsys):
    out, _ = _out(["singularities", str(ROBOTS / "delta_parallelogram.urdf"), "--output", "platform"], capsys)
    assert out.count("adj(G) = 0") == 1
    for loop in ("rod1b_bottom", "rod2a_bottom", "rod2b_bottom", "rod3a_bottom", "rod3b_bottom"):
        assert loop in out


# ------------------------------------------------------------------ (f) legs only where there are legs
def test_statics_of_a_slider_crank_prints_no_legs(capsys):
    slider = str(ROBOTS / "slider_crank_offset.urdf")
    out, _ = _out(["statics", slider, "--output", "slider", "--wrench", "10 0 0 0 0 0", "--set", "crank_joint=30deg"],
                  capsys)
    assert "leg 1:" not in out and "no legs' wrenches: 'slider' is joined to the ground by the single joint " \
                                   "slider_joint" in out
    out, _ = _out(["statics", slider, "--output", "slider", "--wrench", "10 0 0 0 0 0", "--set", "crank_joint=30deg",
                   "--json"], capsys)
    d = json.loads(out)
    assert d["legs"] == [] and d["legs_note"].startswith("no legs: ")
    out, _ = _out(["statics", str(ROBOTS / "delta_parallelogram.urdf"), "--output", "platform", "--wrench",
                   "0 0 -10 0 0 0"], capsys)
    assert out.count("\nleg ") == 3  # a Delta's three legs


# ---------------------------------------------------------------- folded in from test_user_words.py
FOURBAR = str(ROBOTS / "fourbar_crank_rocker.urdf")


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
