"""screwkin draw --animate: the skeleton through a sweep, as GIF (Pillow) or MP4 (imageio-ffmpeg).
Checked: the number of frames asked (read back with PIL's ImageSequence), frames that differ,
one framing for the whole motion, titles in the unit typed, a point of the crank traced on its
circle (closed form), and the non-Grashof four-bar's limit position (law of cosines)."""

import json
import sys

import numpy as np
import pytest
from conftest import ROBOTS

from screwkin.cli import main

pytest.importorskip("matplotlib")
Image = pytest.importorskip("PIL.Image")
from PIL import ImageSequence  # noqa: E402

FOURBAR = str(ROBOTS / "fourbar_crank_rocker.urdf")  # crank 0.04 m drawn at 60 deg, from A = (0, 0)
NON_GRASHOF = str(ROBOTS / "fourbar_non_grashof.urdf")  # input 0.08 at 70 deg, ground 0.1, coupler 0.09, output 0.075


def frames(path):
    with Image.open(path) as im:
        return [np.asarray(f.convert("RGB"), int) for f in ImageSequence.Iterator(im)]


@pytest.fixture
def drawn(monkeypatch):
    """The title and the axes' limits of every frame drawn for the file (the second pass)."""
    import screwkin.present.animate as animate

    seen = []
    original = animate.draw_mechanism

    def spy(skel, **kw):
        fig = original(skel, **kw)
        if kw.get("limits") is not None:
            seen.append((kw["title"], fig.axes[0].get_xlim(), fig.axes[0].get_ylim()))
        return fig

    monkeypatch.setattr(animate, "draw_mechanism", spy)
    return seen


def test_the_gif_has_the_frames_asked_and_they_differ(tmp_path, capsys, drawn):
    gif = tmp_path / "crank.gif"
    assert main(["draw", FOURBAR, "--animate", str(gif), "--from", "0deg", "--to", "360deg", "--steps", "12",
                 "--point", "P=crank:0.02,0.03464101615137755,0", "--fps", "10", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    imgs = frames(gif)
    assert len(imgs) == d["frames"] == 13
    assert all(a.shape == imgs[0].shape for a in imgs)
    assert all(np.abs(a - b).sum() > 0 for a, b in zip(imgs, imgs[1:]))  # every frame moves
    with Image.open(gif) as im:
        assert im.info["duration"] == 100  # 10 fps
    # one framing for the whole motion, the input's value in degrees as typed: 30 deg a step
    assert len(drawn) == 13
    assert len({(x, y) for _, x, y in drawn}) == 1
    assert [t.split(": ", 1)[1] for t, _, _ in drawn] == [f"crank_joint = {30 * k:g} deg" for k in range(13)]
    # the point on the crank at B runs on its circle: radius 0.04, at 60 deg + the input (closed form)
    path = np.array(d["traces"]["P"])
    angles = np.radians(60 + 30 * np.arange(13))
    np.testing.assert_allclose(path, 0.04 * np.stack([np.cos(angles), np.sin(angles)], axis=1), atol=1e-9)


def test_a_limit_position_stops_the_animation(tmp_path, capsys, drawn):
    gif = tmp_path / "rocker.gif"
    assert main(["draw", NON_GRASHOF, "--animate", str(gif), "--input", "input_joint", "--from", "0deg",
                 "--to", "180deg", "--steps", "18"]) == 0
    out = capsys.readouterr().out
    # the limit: coupler and output in line, |BD| = 0.09 + 0.075; law of cosines in triangle ABD
    phi = np.degrees(np.arccos((0.08 ** 2 + 0.1 ** 2 - 0.165 ** 2) / (2 * 0.08 * 0.1))) - 70
    assert f"input_joint stopped at {phi:.5g} deg (limit position" in out
    imgs = frames(gif)
    assert len(imgs) == 8 == len(drawn)  # 0, 10, ..., 60 deg and the limit position itself
    assert drawn[-1][0].endswith(f"input_joint = {phi:.5g} deg (limit position)")
    assert "8 frames, not the 19 asked" in out


def test_an_mp4_through_imageio_ffmpeg(tmp_path, capsys):
    ffmpeg = pytest.importorskip("imageio_ffmpeg")
    mp4 = tmp_path / "crank.mp4"
    assert main(["draw", FOURBAR, "--animate", str(mp4), "--from", "0", "--to", "1", "--steps", "4"]) == 0
    assert "5 frames" in capsys.readouterr().out
    reader = ffmpeg.read_frames(str(mp4))
    meta = next(reader)
    assert meta["size"] == (800, 512)
    assert sum(1 for _ in reader) == 5


def test_an_mp4_without_imageio_ffmpeg_is_a_usage_error(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # import fails as when not installed
    assert main(["draw", FOURBAR, "--animate", str(tmp_path / "a.mp4"), "--from", "0", "--to", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pip install imageio-ffmpeg" in err[0]
    assert not (tmp_path / "a.mp4").exists()


@pytest.mark.parametrize("args, message", [
    (["--animate", "a.png", "--from", "0", "--to", "1"], "ending in .gif or .mp4"),
    (["--animate", "a.gif", "--from", "0"], "--from A and --to B"),
    (["--animate", "a.gif", "--from", "0", "--to", "1", "--steps", "5000"], "from 1 to 500"),
    (["--animate", "a.gif", "--from", "0", "--to", "1", "--fps", "500"], "from 1 to 60"),
    (["--animate", "a.gif", "--from", "0", "--to", "1", "--png", "a.png"], "one animation"),
    (["--png", "a.png", "--from", "0"], "--from and --to go with --animate"),
])
def test_bad_animation_options_are_usage_errors(args, message, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["draw", FOURBAR, *args]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir())
