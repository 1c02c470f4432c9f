"""view --interactive as a person sees it (issue 33 item 6): the page served on 127.0.0.1, opened in headless
Chromium and photographed.  It opens at the file's input values (the README's four-bar drawn with its crank at
0 deg; it opened at 18.4 deg, where the open drawing first assembled); its controls are painted (their labels'
pixels are text, not background); the control panel is docked beside the 3-D view, and the mechanism -- its
outline projected with the camera the browser reports, and the pixels of its links' colours -- lies in the
view, none of it under the panel (the floating panel hid the coupler's end).

Chromium is driven through its DevTools protocol (a websocket, the ``websockets`` package viser depends on): the
page is photographed once its controls are in the DOM and its camera has been framed for the browser's view,
and the controls' and the view's rectangles are read from the page itself."""

from __future__ import annotations

import base64
import io
import json
import math
import socket
import subprocess
import time

import numpy as np
import pytest

import screwkin
from conftest import DevTools, readme_fourbar
from screwkin.analysis.position.interactive import Interactive
from screwkin.present.view import chromium

pytestmark = [pytest.mark.chromium, pytest.mark.slow,
              pytest.mark.skipif(chromium() is None, reason="Chromium is not installed (.ci/run installs it)")]

# The README's first four-bar: every link along +x, the loop open at B (drawn at O2 = 0, not closed there)
FOURBAR = readme_fourbar()

LABELS = ("O2", "assembly mode", "relative sigma_min")

RECTS = """(() => {
  const out = {};
  const leaves = Array.from(document.querySelectorAll('body *')).filter(e => e.children.length === 0);
  for (const w of %s) {
    const el = leaves.find(e => e.textContent.trim().startsWith(w) && e.getBoundingClientRect().width > 0);
    out[w] = el ? (r => [r.left, r.top, r.right, r.bottom])(el.getBoundingClientRect()) : null;
  }
  const canvases = Array.from(document.querySelectorAll('canvas')).map(c => c.getBoundingClientRect());
  const big = canvases.sort((a, b) => b.width * b.height - a.width * a.height)[0];
  out.canvas = big ? [big.left, big.top, big.right, big.bottom] : null;
  out.size = [window.innerWidth, window.innerHeight, window.devicePixelRatio];
  return JSON.stringify(out);
})()"""


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _project(points, cam, width, height):
    """Pixel coordinates (x right, y down, in the 3-D view) of world points seen by a viser camera: look_at,
    position, up_direction, vertical fov [rad], the view's width and height [px]."""
    eye, target, up = (np.asarray(v, float) for v in (cam.position, cam.look_at, cam.up_direction))
    f = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(f, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, f)
    rel = np.asarray(points, float) - eye
    depth = rel @ f
    tan_v = math.tan(cam.fov / 2)
    x = (rel @ right) / (depth * tan_v * width / height)
    y = (rel @ true_up) / (depth * tan_v)
    return np.stack([(x + 1) * width / 2, (1 - y) * height / 2], axis=1)


def test_the_interactive_page_as_a_person_sees_it(tmp_path):
    pytest.importorskip("viser")
    pytest.importorskip("websockets.sync.client")
    from PIL import Image

    from screwkin.present.interactive import InteractiveView
    from screwkin.present.view import build_scene
    from screwkin.present.viewplanar import colour_links, link_colours

    path = tmp_path / "fourbar.urdf"
    path.write_text(FOURBAR)
    mech = screwkin.load(path)
    live = Interactive(mech)
    assert live.state.inputs == {"O2": 0.0}  # the file's value: it assembles there
    assert live.opened == "opened at O2 = 0 deg (the file's value)"
    scene = build_scene(mech, live.state.q)
    colour_links(scene, link_colours(mech, live.state.q))
    view = InteractiveView(mech, live, scene, port=_free_port())
    browser = DevTools(tmp_path / "profile")
    try:
        browser.call("Page.enable")
        browser.call("Page.navigate", url=view.url)
        deadline = time.monotonic() + 90
        rects = None
        while time.monotonic() < deadline:  # the controls in the DOM and the camera framed for this browser
            rects = json.loads(browser.evaluate(RECTS % json.dumps(LABELS)) or "{}")
            clients = list(view.server.get_clients().values())
            framed = clients and clients[0].camera.image_width and all(rects.get(w) for w in LABELS)
            if framed:
                break
            time.sleep(0.5)
        assert rects and all(rects.get(w) for w in LABELS), rects
        time.sleep(3.0)  # the camera message sent back, and a few frames drawn with it
        rects = json.loads(browser.evaluate(RECTS % json.dumps(LABELS)))
        shot = browser.call("Page.captureScreenshot", format="png")["data"]
        cam = list(view.server.get_clients().values())[0].camera
        width, height = int(cam.image_width), int(cam.image_height)
    finally:
        browser.close()
        view.close()
    png = base64.b64decode(shot)
    (tmp_path / "interactive.png").write_bytes(png)
    image = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    scale = rects["size"][2]
    assert image.std() > 5, "a blank page"

    def box(r):  # CSS pixels -> the screenshot's pixels
        return [int(round(v * scale)) for v in r]

    # the controls are painted: each label's box holds dark text on the panel's light background
    for w in LABELS:
        x0, y0, x1, y1 = box(rects[w])
        patch = image[y0:y1 + 1, x0:x1 + 1]
        assert patch.size and patch.min() < 180 and patch.max() > 230, (w, rects[w])  # (labels are grey text)
    # the panel is docked beside the 3-D view, not over it
    cx0, cy0, cx1, cy1 = rects["canvas"]
    for w in LABELS:
        lx0, ly0, lx1, ly1 = rects[w]
        assert lx0 >= cx1 or lx1 <= cx0 or ly0 >= cy1 or ly1 <= cy0, (w, rects[w], rects["canvas"])
    assert (cx1 - cx0, cy1 - cy0) == pytest.approx((width / scale, height / scale), abs=2)
    # the mechanism, projected with the browser's camera, lies inside the view with a margin
    uv = _project(scene.points, cam, width, height)
    assert uv[:, 0].min() > 0.05 * width and uv[:, 0].max() < 0.95 * width, uv
    assert uv[:, 1].min() > 0.05 * height and uv[:, 1].max() < 0.95 * height, uv
    # ... and it is what is painted: the crank's, the coupler's and the rocker's colours are found there
    left, top = box(rects["canvas"])[:2]
    colours = link_colours(mech, live.state.q)
    for link in ("crank", "coupler", "rocker"):
        rgba = colours[mech.model.frames[mech.link_frame(link)].parentJoint]
        rgb = np.array(rgba[:3], float) * (255 if max(rgba[:3]) <= 1 else 1)
        view_pixels = image[top:top + height, left:left + width]  # the 3-D view (the panel has colours of its own)
        near = np.abs(view_pixels - rgb).sum(axis=2) < 60
        corner = int(90 * scale)  # viser's orientation gizmo (red, green, blue axes) in the view's lower left corner
        near[height - corner:, :corner] = False
        ys, xs = np.nonzero(near)
        assert len(xs) > 20, link
        margin = 0.05 * width
        assert uv[:, 0].min() - margin <= xs.min() and xs.max() <= uv[:, 0].max() + margin, link
        assert uv[:, 1].min() - margin <= ys.min() and ys.max() <= uv[:, 1].max() + margin, link


NOTICES = """JSON.stringify(Array.from(document.querySelectorAll('[class*="Notification-root"]'))
  .map(e => e.getBoundingClientRect()).map(r => [r.left, r.top, r.right, r.bottom]))"""


def _painted_box(image, rects, scale, colours, notices=()):
    """The box (x0, y0, x1, y1; the 3-D view's pixels) of the pixels painted in the links' colours, outside
    ``notices`` (the page's rectangles over the view: viser's "Software WebGL" card has an orange edge)."""
    image = image.copy()
    for r in notices:
        x0, y0, x1, y1 = (int(round(v * scale)) for v in r)
        image[max(y0, 0):y1 + 1, max(x0, 0):x1 + 1] = 255
    left, top, right, bottom = (int(round(v * scale)) for v in rects["canvas"])
    view_pixels = image[top:bottom, left:right]
    near = np.zeros(view_pixels.shape[:2], bool)
    for rgba in colours:
        rgb = np.array(rgba[:3], float) * (255 if max(rgba[:3]) <= 1 else 1)
        near |= np.abs(view_pixels - rgb).sum(axis=2) < 60
    corner = int(90 * scale)  # viser's orientation gizmo in the view's lower left corner
    near[-corner:, :corner] = False
    ys, xs = np.nonzero(near)
    assert len(xs) > 100, "no link painted"
    return np.array([xs.min(), ys.min(), xs.max(), ys.max()], float)


def test_the_command_frames_the_mechanism_for_the_browser_without_a_traceback(tmp_path):
    """Issue 43 item 2: `view --interactive` raised KeyError: 'dist' at each camera report of the browser (a
    traceback on the command's stderr), and the re-framing for the browser's view never ran: the mechanism stayed
    framed for a square view.  The command is run as a user runs it, its page opened in a wide window (the view
    twice as wide as high, where the two framings differ), photographed, and the command stopped: its stderr holds
    no traceback, and the links are painted where the framing for the browser's view puts them."""
    pytest.importorskip("viser")
    pytest.importorskip("websockets.sync.client")
    import os
    import select
    import signal
    import sys
    from types import SimpleNamespace

    from PIL import Image

    from screwkin.present.camera import fit_camera
    from screwkin.present.interactive import CANVAS_ASPECT
    from screwkin.present.view import build_scene
    from screwkin.present.viewplanar import link_colours, planar_basis

    path = tmp_path / "fourbar.urdf"
    path.write_text(FOURBAR)
    port = _free_port()
    err_file = open(tmp_path / "stderr.txt", "w+")
    proc = subprocess.Popen([sys.executable, "-m", "screwkin", "view", str(path), "--interactive", "--port", str(port)],
                            stdout=subprocess.PIPE, stderr=err_file, text=True, start_new_session=True)
    browser = None
    try:
        for _ in range(300):  # its line (at most 300 waits of a second)
            assert proc.poll() is None, (tmp_path / "stderr.txt").read_text()
            if select.select([proc.stdout], [], [], 1.0)[0] and proc.stdout.readline().startswith("interactive view:"):
                break
        browser = DevTools(tmp_path / "profile", size=(1400, 560))
        browser.call("Page.enable")
        browser.call("Page.navigate", url=f"http://127.0.0.1:{port}")
        deadline = time.monotonic() + 90
        rects = {}
        while time.monotonic() < deadline and not (rects.get("canvas") and all(rects.get(w) for w in LABELS)):
            time.sleep(0.5)
            rects = json.loads(browser.evaluate(RECTS % json.dumps(LABELS)) or "{}")
        assert rects.get("canvas") and all(rects.get(w) for w in LABELS), rects
        time.sleep(4.0)  # the camera reports sent, the view framed for them, and a few frames drawn
        rects = json.loads(browser.evaluate(RECTS % json.dumps(LABELS)))
        notices = json.loads(browser.evaluate(NOTICES))
        png = base64.b64decode(browser.call("Page.captureScreenshot", format="png")["data"])
    finally:
        if browser is not None:
            browser.close()
        os.killpg(proc.pid, signal.SIGTERM)
        out, _ = proc.communicate(timeout=60)
    err_file.seek(0)
    err = err_file.read()
    err_file.close()
    assert proc.returncode == 0 and "stopped by SIGTERM" in out, (out, err)
    assert "Traceback" not in err and "Error" not in err, err

    (tmp_path / "interactive.png").write_bytes(png)
    image = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    scale = rects["size"][2]
    width, height = (int(round((rects["canvas"][k + 2] - rects["canvas"][k]) * scale)) for k in (0, 1))
    mech = screwkin.load(path)
    q = Interactive(mech).state.q
    scene = build_scene(mech, q)
    basis = planar_basis(mech, q)
    painted = _painted_box(image, rects, scale, link_colours(mech, q).values(), notices)

    def predicted(aspect):  # where the mechanism is drawn with a camera framed for a view of this aspect
        target, eye = fit_camera(scene.points, basis[2], fov_deg=75.0, aspect=aspect)  # (viser's field of view)
        cam = SimpleNamespace(position=eye, look_at=target, up_direction=basis[1], fov=math.radians(75.0))
        uv = _project(scene.points, cam, width, height)
        return np.array([*uv.min(axis=0), *uv.max(axis=0)])

    framed, square = predicted(width / height), predicted(CANVAS_ASPECT)
    assert width / height > 1.8  # a wide view ...
    assert np.abs(framed - square).max() > 0.1 * width  # ... where the two framings differ
    assert np.abs(painted - framed).max() < 0.04 * width, (painted, framed, square)  # framed for the browser
