"""``draw FILE --set ... --connect I:J --animate OUT.gif`` (issue 44, part 4): the path joining two assembly modes
without a singularity, drawn as ``draw --animate`` draws a sweep.  Checked: the GIF's frames read back with PIL
(one per point of the path), the first and last frames' configurations are the modes I and J as ``solve --all``
lists them, the platform's legs computed with numpy from its pose (tests/test_connect_modes.py's
_rpr_geometry) are the inputs at both ends, the titles give the inputs in the units typed and the running
minimum of the actuator measure; a pair of opposite det signs (a five-bar's two modes, the tip either side of
the line of the elbows: test_connect_modes.py checks the sides with Pinocchio) is said not joined, no file,
exit 0."""

import json

import numpy as np
import pytest
from conftest import ROBOTS, screwkin_cli

from screwkin.cli import main

pytest.importorskip("matplotlib")
Image = pytest.importorskip("PIL.Image")

FIVE_BAR = str(ROBOTS / "five_bar.urdf")
FIVE_BAR_SET = "motor1=0.3,motor2=-0.2"


def _gif_frames(path):
    with Image.open(path) as im:
        return im.n_frames


@pytest.fixture
def frames_drawn(monkeypatch):
    """Every configuration present.animate turns into a skeleton, and each frame's (title, subtitle) as drawn
    for the file (the second pass, with the shared framing)."""
    import screwkin.present.animate as animate

    qs, titles = [], []
    skel, draw = animate.skeleton, animate.draw_mechanism

    def spy_skeleton(mech, q, *a, **kw):
        qs.append(np.array(q))
        return skel(mech, q, *a, **kw)

    def spy_draw(s, **kw):
        if kw.get("limits") is not None:
            titles.append((kw["title"], kw.get("subtitle")))
        return draw(s, **kw)

    monkeypatch.setattr(animate, "skeleton", spy_skeleton)
    monkeypatch.setattr(animate, "draw_mechanism", spy_draw)
    return qs, titles


def test_connect_usage_errors(tmp_path, capsys):
    gif = str(tmp_path / "c.gif")
    for extra, said in ((["--connect", "1:2"], "--animate"), (["--connect", "1:1", "--animate", gif], "different"),
                        (["--connect", "one:two", "--animate", gif], "I:J"),
                        (["--connect", "1:2", "--animate", gif, "--from", "0"], "--from"),
                        (["--connect", "1:2", "--animate", gif, "--mode", "2"], "--mode")):
        try:
            code = main(["draw", FIVE_BAR, "--set", FIVE_BAR_SET, *extra])
        except SystemExit as e:  # (argparse's own)
            code = e.code
        assert code == 2, extra
        err = capsys.readouterr().err
        assert said in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert not (tmp_path / "c.gif").exists()


def test_a_mode_beyond_the_list_is_a_usage_error(tmp_path):
    p = screwkin_cli("draw", FIVE_BAR, "--set", FIVE_BAR_SET, "--connect", "1:3", "--animate", str(tmp_path / "c.gif"))
    assert p.returncode == 2 and "lists 2 assembly modes" in p.stderr and len(p.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "c.gif").exists()


def test_modes_of_opposite_det_signs_said_not_joined_no_file(tmp_path):
    """The five-bar's two modes: det K_p of opposite signs, proved apart; said in one line, no GIF, exit 0."""
    gif = tmp_path / "c.gif"
    p = screwkin_cli("draw", FIVE_BAR, "--set", FIVE_BAR_SET, "--connect", "2:1", "--animate", str(gif))
    assert p.returncode == 0, p.stderr
    lines = p.stdout.strip().splitlines()
    assert lines[0].startswith("modes 2 and 1: not joined: det J of opposite signs")
    assert "every path between them meets an actuator singularity" in lines[0]
    assert lines[-1] == f"no path from mode 2 to mode 1 to animate: {gif} not written"
    assert not gif.exists()
    p = screwkin_cli("draw", FIVE_BAR, "--set", FIVE_BAR_SET, "--connect", "1:2", "--animate", str(gif), "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    (c,) = d["connections"]
    assert c["modes"] == [1, 2] and c["joined"] is False and c["proved"] is True and c["path"] == []
    assert d["file"] is None and d["frames"] == 0 and sorted(d["det_signs"]) == [-1, 1] and not gif.exists()


def test_a_joined_path_is_drawn_one_frame_a_point(tmp_path, capsys, monkeypatch, frames_drawn):
    """The command's plumbing on a five-bar, the search replaced by a made-up joined Connection (5 points from
    mode 2 to mode 1, as mode_connect would return it for --connect 2:1): one GIF frame per point, the first
    and last configurations drawn the listed modes (solve --all --json), the inputs in the unit typed (deg),
    the running minimum given under each title."""
    import screwkin.commands.draw as draw
    from screwkin.analysis.singularities.mode_connect import Connection, Connections

    p = screwkin_cli("solve", FIVE_BAR, "--set", "motor1=0.3,motor2=-0.2", "--all", "--json")
    modes = [s["joints"] for s in json.loads(p.stdout)["solutions"]]
    asked = []

    def fake(solver, values, qs, pairs=None):
        asked.append(pairs)
        (i, j), = pairs
        path = np.array([(1 - t) * qs[i] + t * qs[j] for t in np.linspace(0, 1, 5)])
        sig = np.array([0.5, 0.4, 0.45, 0.3, 0.35])
        c = Connection((i, j), True, True, "joined (made up)", path, None, ("motor1", "motor2"), 0.3,
                       np.minimum.accumulate(sig))
        return Connections((c,), (1, 1), "made up")

    monkeypatch.setattr(draw, "connect_modes", fake)
    gif = tmp_path / "c.gif"
    assert main(["draw", FIVE_BAR, "--set", "motor1=17.188733853924695deg,motor2=-0.2", "--connect", "2:1",
                 "--animate", str(gif), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert asked == [[(1, 0)]]  # only the pair asked, from mode 2 to mode 1
    assert d["file"] == str(gif) and d["frames"] == 5 == _gif_frames(gif) == len(d["connections"][0]["path"])
    assert d["sigma_so_far"] == [0.5, 0.4, 0.4, 0.3, 0.3]
    qs, titles = frames_drawn
    import screwkin

    mech = screwkin.load(FIVE_BAR)
    first, last = mech.joint_values(qs[0]), mech.joint_values(qs[-1])
    for name in first:
        assert abs(first[name] - modes[1][name]) < 1e-6 and abs(last[name] - modes[0][name]) < 1e-6, name
    assert len(titles) == 5
    assert titles[0][0] == "five_bar.urdf: motor1 = 17.189 deg, motor2 = -0.2 rad"
    assert titles[1][1] == "mode 2 to mode 1 without a singularity: smallest actuator measure so far 0.4 (frame 2 of 5)"


@pytest.mark.slow
def test_3rpr_modes_joined_round_a_cusp_animated(tmp_path, capsys, frames_drawn):
    """The Innocenti 3-RPR 4 mm from a cusp (test_connect_modes.py: modes 1 and 3 of solve --all are joined by a
    loop of leg2 and leg3): draw --connect 3:1 writes one GIF frame per point of the path (at most 100: thinned),
    the first frame mode 3 and the last mode 1 as solve --all lists them, the legs computed from the platform's
    pose equal to the inputs at both ends, the smallest measure so far never rising and ending at sigma_min."""
    from loci_robots import rpr3
    from test_connect_modes import RHO, _rpr_geometry

    text, rho0 = rpr3()
    path = tmp_path / "rpr3.urdf"
    path.write_text(text)
    values = ",".join(f"leg{i + 1}={float(RHO[i] - rho0[i])!r}" for i in range(3))
    p = screwkin_cli("solve", str(path), "--set", values, "--all", "--json")
    assert p.returncode == 0, p.stderr
    modes = [s["joints"] for s in json.loads(p.stdout)["solutions"]]
    assert len(modes) == 4
    gif = tmp_path / "c.gif"
    assert main(["draw", str(path), "--set", values, "--connect", "3:1", "--animate", str(gif), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    (c,) = d["connections"]
    assert c["modes"] == [3, 1] and c["joined"] and c["proved"]
    n = len(c["path"])
    assert 50 <= n <= 100 and d["frames"] == n == _gif_frames(gif)
    qs, titles = frames_drawn
    import screwkin

    mech = screwkin.load(path)
    assert len(qs) == n and len(titles) == n
    for q, k in ((qs[0], 2), (qs[-1], 0)):
        joints = mech.joint_values(q)
        for name, v in joints.items():
            assert abs(modes[k][name] - v) < 1e-6, (name, modes[k][name], v)
        lengths, det = _rpr_geometry(text, rho0, joints)
        assert np.allclose(lengths, RHO, rtol=0, atol=1e-9)
    s = np.array(d["sigma_so_far"])
    assert len(s) == n and np.all(np.diff(s) <= 0) and s[-1] == pytest.approx(c["sigma_min"], rel=1e-12)
    assert titles[0][0].startswith("rpr3.urdf: leg1 = ") and "frame 1 of" in titles[0][1]
