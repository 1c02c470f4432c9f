"""Pictures worth looking at (issue 17 part 4): view --png with a neutral background, the camera
fitted to the mechanism, meshcat's controls hidden and a legend."""

import numpy as np
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.cli import main
from screwkin.present.view import (
    RecordingViewer,
    build_scene,
    chromium,
    legend_entries,
    page,
    show,
)
from screwkin.present.camera import (
    BACKGROUND,
    FOV,
    fit_camera,
    view_direction,
)


def _project(points, target, eye, aspect, fov=FOV):
    """Pixel-free image coordinates (-1..1 across the frame) of points seen by a pinhole camera
    at eye looking at target with z up: the textbook perspective division, written again here."""
    f = (target - eye) / np.linalg.norm(target - eye)
    r = np.cross(f, [0, 0, 1.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    d = points - eye
    depth = d @ f
    t = np.tan(np.radians(fov) / 2)
    return (d @ r) / depth / (t * aspect), (d @ u) / depth / t


def test_fit_camera_fills_seventy_percent_and_centres():
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(200, 3)) * [0.3, 0.1, 0.05] + [1.0, -2.0, 0.5]
    d = np.array([1.0, -1.0, 0.7])
    target, eye = fit_camera(pts, d, aspect=9 / 7, fill=0.7)
    np.testing.assert_allclose((eye - target) / np.linalg.norm(eye - target), d / np.linalg.norm(d), atol=1e-12)
    x, y = _project(pts, target, eye, 9 / 7)
    extent = max(np.abs(x).max(), np.abs(y).max())
    assert extent == pytest.approx(0.7, abs=1e-9)  # the binding point is at 70% of the half-frame
    # centred: the two sides of the tighter direction are within a few percent of each other
    assert abs(x.max() + x.min()) < 0.05 and abs(y.max() + y.min()) < 0.05


def test_flat_mechanisms_are_seen_from_above():
    d = view_direction(np.array([[0, 0, -0.01], [1.0, 0.5, 0.01]]))  # flat in z
    assert d[2] > 0.85
    d = view_direction(np.array([[0, -0.01, 0], [1.0, 0.01, 0.5]]))  # flat in y: seen from -y (VIEW's side)
    assert d[1] < -0.85


def test_scene_is_moved_to_the_target_and_background_neutral():
    mech = screwkin.load(ROBOTS / "delta_parallelogram.urdf")
    q = mech.assemble().q
    scene = build_scene(mech, q, output="platform")
    v = RecordingViewer()
    show(mech, scene, v, q)
    target, eye = fit_camera(scene.points, view_direction(scene.bounds))
    np.testing.assert_allclose(v.transforms["/screwkin"][:3, 3], -target)
    w = eye - target  # in meshcat's y-up camera frame: (x, z, -y)
    np.testing.assert_allclose(v.properties[("/Cameras/default/rotated/<object>", "position")], [w[0], w[2], -w[1]])
    assert v.properties[("/Grid", "visible")] is False and v.properties[("/Axes", "visible")] is False
    for key, value in BACKGROUND.items():
        assert v.properties[("/Background", key)] == value
        assert max(value) - min(value) < 0.02  # grey, not meshcat's blue


def test_legend_lists_what_the_scene_shows():
    mech = screwkin.load(ROBOTS / "delta_parallelogram.urdf")
    scene = build_scene(mech, mech.assemble().q, output="platform")
    labels = [label for label, _ in legend_entries(scene)]
    assert labels[:3] == ["actuated joints", "passive joints", "cut (loop) joints"]
    assert {"output link: frame x", "y", "z"} <= set(labels)
    assert "higher pairs" not in labels
    html = page("<html><body><div id='meshcat-pane'></div></body></html>", scene, "delta", controls=False,
                size=(900, 700))
    assert 'id="screwkin-legend"' in html and "actuated joints" in html and "output link frame" in html
    assert "display: none" in html  # dat.gui's panel
    assert html.index("screwkin-legend") < html.index("</body>")
    gears = screwkin.load(ROBOTS / "gear_train_idler.urdf")
    assert "higher pairs" in [label for label, _ in legend_entries(build_scene(gears, gears.assemble().q))]


@pytest.mark.skipif(chromium() is None, reason="Chromium is not installed (.ci/run installs it)")
def test_png_neutral_background_fitted_camera_and_legend(tmp_path):
    from PIL import Image

    png, html = tmp_path / "delta.png", tmp_path / "delta.html"
    assert main(["view", str(ROBOTS / "delta_parallelogram.urdf"), "--output", "platform", "--png", str(png),
                 "--html", str(html)]) == 0
    text = html.read_text()
    assert "screwkin-legend" in text and "delta_parallelogram.urdf" in text
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    h, w, _ = img.shape
    corner = img[3, w - 4]  # top right: background (the legend is bottom left, the controls hidden)
    assert corner.max() - corner.min() < 8 and corner.min() > 200  # light grey, not meshcat's sky blue
    # meshcat's "Open Controls" bar (black, top right) is hidden
    assert (img[:25, w - 240:].sum(axis=2) < 100).sum() == 0
    # the mechanism: pixels far from the background's grey (coloured or dark), outside the legend box
    grey = (img.max(axis=2) - img.min(axis=2) < 12) & (img.min(axis=2) > 180)
    thing = ~grey
    thing[h - 140:, :260] = False  # the legend
    ys, xs = np.nonzero(thing)
    width, height = (xs.max() - xs.min()) / w, (ys.max() - ys.min()) / h
    assert max(width, height) > 0.55  # fitted: before, the Delta filled about a third of the width
    assert abs((xs.max() + xs.min()) / 2 / w - 0.5) < 0.1 and abs((ys.max() + ys.min()) / 2 / h - 0.5) < 0.1
    # the legend's box is there: dark text pixels in the bottom left corner
    assert (img[h - 120:, :240].sum(axis=2) < 200).sum() > 50
