"""Planar mechanisms look planar in view's pictures (issue 27.4): seen along the plane's normal
through an orthographic camera, one colour per link (those of `screwkin draw`), the ground grey."""

import numpy as np
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.cli import main
from screwkin.present.view import RecordingViewer, build_scene, chromium, show
from screwkin.present.viewplanar import GROUND

FOURBAR = ROBOTS / "fourbar_crank_rocker.urdf"  # every joint axis along z: the plane z = 0
DRAW = {"crank": "#d62728", "coupler": "#1f77b4", "rocker": "#2ca02c"}  # draw's colours of links 2, 3, 4


def rgba(hex_colour):
    return np.array([int(hex_colour[k:k + 2], 16) / 255 for k in (1, 3, 5)] + [1.0])


@pytest.fixture(scope="module")
def fourbar():
    mech = screwkin.load(FOURBAR)
    q = mech.assemble().q
    scene = build_scene(mech, q)
    viewer = RecordingViewer()
    show(mech, scene, viewer, q)
    return mech, q, scene, viewer


def test_the_camera_is_orthographic_on_the_planes_normal(fourbar):
    mech, q, scene, viewer = fourbar
    camera, _ = viewer.objects["/Cameras/default/rotated"]
    assert type(camera).__name__ == "OrthographicCamera"
    T = viewer.transforms["/screwkin"]
    R = T[:3, :3]
    np.testing.assert_allclose(R @ [0, 0, 1.0], [0, -1.0, 0], atol=1e-12)  # the normal z towards the camera (-y)
    np.testing.assert_allclose(R @ [1.0, 0, 0], [1.0, 0, 0], atol=1e-12)  # the drawing's x to the right
    np.testing.assert_allclose(R @ [0, 1.0, 0], [0, 0, 1.0], atol=1e-12)  # its y up (meshcat's z)
    # the camera in meshcat's y-up frame (x, z, -y): on world -y, that is on the mechanism's normal
    x, y, z = viewer.properties[("/Cameras/default/rotated/<object>", "position")]
    assert x == 0 and y == 0 and z > 0
    # everything drawn lies inside the camera's frame, and fills most of it along one side
    P = scene.points @ R.T + T[:3, 3]
    half_w, half_h = camera.right, camera.top
    assert np.all(np.abs(P[:, 0]) <= half_w) and np.all(np.abs(P[:, 2]) <= half_h)
    assert max(np.ptp(P[:, 0]) / (2 * half_w), np.ptp(P[:, 2]) / (2 * half_h)) == pytest.approx(0.8)


def test_one_colour_per_link_as_draw_gives_them(fourbar):
    mech, q, scene, viewer = fourbar
    model = mech.model
    joint_of = {name: model.frames[mech.link_frame(name)].parentJoint for name in DRAW}
    seen = {}
    for obj in scene.geometry.geometryObjects:
        if scene.roles[obj.name] != "link":
            continue
        if obj.parentJoint == 0:
            np.testing.assert_allclose(obj.meshColor, GROUND)
            seen["ground"] = True
            continue
        name = next(n for n, j in joint_of.items() if j == obj.parentJoint)
        np.testing.assert_allclose(obj.meshColor, rgba(DRAW[name]), atol=1e-12)
        seen[name] = True
    assert set(seen) == {"ground", *DRAW}


def test_spatial_mechanisms_keep_a_perspective():
    mech = screwkin.load(ROBOTS / "delta_parallelogram.urdf")
    q = mech.assemble().q
    viewer = RecordingViewer()
    show(mech, build_scene(mech, q), viewer, q)
    assert "/Cameras/default/rotated" not in viewer.objects


@pytest.mark.slow
@pytest.mark.skipif(chromium() is None, reason="Chromium is not installed (.ci/run installs it)")
def test_the_picture_shows_each_link_in_its_colour(tmp_path):
    from PIL import Image

    png = tmp_path / "fourbar.png"
    assert main(["view", str(FOURBAR), "--png", str(png)]) == 0
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    for name, colour in DRAW.items():
        c = (rgba(colour)[:3] * 255).astype(int)
        near = np.abs(img - c).max(axis=2) < 40
        assert near.sum() > 500, name  # shading varies across a cylinder: its lit middle is close
    dark = (img.max(axis=2) < 110) & (img.max(axis=2) - img.min(axis=2) < 10)  # the ground bar
    assert dark.sum() > 500
