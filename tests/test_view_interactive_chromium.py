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
import re
import socket
import subprocess
import time
import urllib.request

import numpy as np
import pytest

import screwkin
from conftest import readme_fourbar
from screwkin.analysis.motion.interactive import Interactive
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


class DevTools:
    """Headless Chromium and one page, over the DevTools protocol."""

    def __init__(self, profile, size=(1000, 700)):
        from websockets.sync.client import connect

        self.proc = subprocess.Popen(
            [chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
             "--enable-unsafe-swiftshader", "--no-first-run", "--disable-background-networking",
             "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1", f"--user-data-dir={profile}",
             f"--window-size={size[0]},{size[1]}", "--remote-debugging-port=0", "about:blank"],
            stderr=subprocess.PIPE, text=True)
        port = None
        deadline = time.monotonic() + 60
        while port is None and time.monotonic() < deadline:
            line = self.proc.stderr.readline()
            m = re.search(r"DevTools listening on ws://127\.0\.0\.1:(\d+)/", line)
            port = int(m.group(1)) if m else None
        assert port, "Chromium did not open its DevTools port"
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as r:
            page = next(t for t in json.load(r) if t["type"] == "page")
        self.ws = connect(page["webSocketDebuggerUrl"], max_size=None, open_timeout=20)
        self.next_id = 0

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv(timeout=60))
            if msg.get("id") == self.next_id:
                assert "error" not in msg, msg
                return msg.get("result", {})

    def evaluate(self, expression):
        return self.call("Runtime.evaluate", expression=expression, returnByValue=True)["result"].get("value")

    def close(self):
        try:
            self.ws.close()
        finally:
            self.proc.terminate()
            self.proc.wait(timeout=30)


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
