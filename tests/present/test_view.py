"""meshcat views: scene contents without a server, the loopback-only server, and a real render."""

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import CORPUS, ROBOTS
from screwkin.cli import main
from screwkin.present.view import COLORS, RecordingViewer, build_scene, chromium, show
from screwkin.present.viewserver import ViewerServer


@pytest.fixture(scope="module")
def delta():
    mech = screwkin.load(ROBOTS / "delta_parallelogram.urdf")
    return mech, mech.assemble().q


def test_scene_contents_and_colours(delta):
    mech, q = delta
    scene = build_scene(mech, q, output="platform")
    roles = list(scene.roles.values())
    assert roles.count("axis:actuated") == 3  # arm1..3
    assert roles.count("axis:cut") == 5  # the rod ends closed by spherical loop joints
    import xml.etree.ElementTree as ET

    visuals = len(ET.parse(ROBOTS / "delta_parallelogram.urdf").getroot().findall("link/visual"))
    assert roles.count("link") == visuals  # every <visual> of the file
    assert {"output:x", "output:y", "output:z"} <= set(roles)
    for obj in scene.geometry.geometryObjects:
        role = scene.roles[obj.name]
        if role == "axis:actuated":
            np.testing.assert_allclose(obj.meshColor, COLORS["actuated"])
        if role == "axis:cut":
            np.testing.assert_allclose(obj.meshColor, COLORS["cut"])


def test_every_drawn_transform_matches_the_solved_configuration(delta):
    """What is sent to meshcat for each object equals Pinocchio's placement of its
    joint at the solved configuration times the object's placement on it."""
    from screwkin.analysis.position.position import PositionSolver

    mech, _ = delta
    s = PositionSolver(mech).solve({"arm1": 0.2, "arm2": -0.1, "arm3": 0.05}).solutions[0]
    scene = build_scene(mech, s.q, output="platform")
    viewer = RecordingViewer()
    show(mech, scene, viewer, s.q)
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, s.q)
    for obj in scene.geometry.geometryObjects:
        T = viewer.transforms[f"/screwkin/visuals/{obj.name}"]
        expected = (data.oMi[obj.parentJoint] * obj.placement).homogeneous
        np.testing.assert_allclose(T[:3, 3], expected[:3, 3], atol=1e-12)
        # the rotation part may carry the mesh scale: compare directions
        np.testing.assert_allclose(T[:3, :3] / np.linalg.norm(T[:3, :3], axis=0), expected[:3, :3], atol=1e-12)
        assert f"/screwkin/visuals/{obj.name}" in viewer.objects


def test_motion_becomes_a_meshcat_animation(delta):
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.analysis.motion.sweep import sweep

    mech, q = delta
    res = sweep(PositionSolver(mech), "arm1", 0.0, 0.3, 12, fixed={"arm2": 0.0, "arm3": 0.0})
    viewer = RecordingViewer()
    show(mech, build_scene(mech, q), viewer, res.q[0], motion=res.q)
    anim = viewer.animation
    assert anim is not None and len(anim.clips) > 0
    clip = next(iter(anim.clips.values()))
    assert len(clip.tracks["position"].frames) == 13


def test_links_without_geometry_get_stand_ins():
    """talos_like's meshes are not shipped: every real link is drawn as a stand-in."""
    mech = screwkin.load(CORPUS / "talos_like" / "robot.urdf", warn=lambda m: None)
    scene = build_scene(mech, mech.assemble().q)
    balls = {n.split("/", 2)[2] for n in scene.roles if n.startswith("screwkin/standin/")}
    real = {n for n, link in mech.spec.links.items() if not link.is_massless(mech.tolerances.dummy_mass)}
    assert "link" not in scene.roles.values()
    assert balls == real - {mech.spec.root}


def listening(port):
    """Local addresses listening on a TCP port, from /proc/net/tcp and tcp6."""
    out = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = open(table).read().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            local, state = line.split()[1], line.split()[3]
            addr, p = local.split(":")
            if state == "0A" and int(p, 16) == port:
                out.append(addr)
    return out


def test_server_binds_only_to_loopback():
    with ViewerServer() as server:
        ports = [int(server.web_url.split(":")[2].split("/")[0]), int(server.zmq_url.rsplit(":", 1)[1])]
        for port in ports:
            addrs = listening(port)
            assert addrs, f"nothing listens on {port}"
            assert all(a == "0100007F" for a in addrs), addrs  # 127.0.0.1 only, no IPv6 or 0.0.0.0


@pytest.mark.skipif(chromium() is None, reason="Chromium is not installed (.ci/run installs it)")
def test_static_page_renders_the_mechanism(tmp_path):
    """The static HTML page, opened in headless Chromium, shows the red arms of the
    Delta on screwkin's grey background."""
    from PIL import Image

    html, png = tmp_path / "delta.html", tmp_path / "delta.png"
    assert main(["view", str(ROBOTS / "delta_parallelogram.urdf"), "--output", "platform", "--html", str(html)]) == 0
    assert html.stat().st_size > 10000 and "<html" in html.read_text()[:2000].lower()
    from screwkin.present.view import screenshot

    screenshot(html, png)
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    red = (img[..., 0] > 150) & (img[..., 1] < 120) & (img[..., 2] < 100)
    assert red.sum() > 200


def test_prismatic_axes_carry_an_arrow():
    mech = screwkin.load(ROBOTS / "planar_3rpr.urdf")
    scene = build_scene(mech, mech.assemble().q)
    arrows = [n for n in scene.roles if n.endswith("/arrow")]
    assert sorted(arrows) == [f"screwkin/axis/leg{k}/arrow" for k in (1, 2, 3)]


def test_view_helper_uses_the_viewer_it_is_given(delta):
    from screwkin.present.view import view

    mech, q = delta
    v = RecordingViewer()
    assert view(mech, q, viewer=v) is v
    assert any(p.startswith("/screwkin/visuals/") for p in v.objects)
