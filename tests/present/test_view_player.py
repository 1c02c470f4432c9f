"""view --sweep ... --html: the page has a play/scrub bar (issue 27 item 3) that drives meshcat's own
animator; a frame scrubbed to in headless Chromium places the links where Pinocchio places them at
that step of the sweep."""

from __future__ import annotations

import json
import re
import subprocess

import numpy as np
import pinocchio as pin
import pytest

import screwkin
from conftest import ROBOTS
from screwkin.cli import main
from screwkin.present.view import build_scene, chromium

FILE = ROBOTS / "fourbar_crank_rocker.urdf"
PROBE = """<script>
(function wait() {
  if (!window.screwkinPlayer || !window.screwkinPlayer.ready()) { setTimeout(wait, 50); return; }
  var out = {ready: true, frames: {}};
  for (var k of %s) {
    window.screwkinPlayer.seek(k);
    var root = viewer.scene_tree.find(["meshcat", "screwkin", "visuals"]), at = {};
    for (var name in root.children) { var o = root.children[name].object;
      at[name] = [o.position.x, o.position.y, o.position.z]; }
    out.frames[k] = {links: at, slider: window.screwkinPlayer.frame(),
                     readout: document.querySelector("#screwkin-player .sk-readout").textContent};
  }
  var pre = document.createElement("pre"); pre.id = "probe"; pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
})();
</script>"""


def test_the_player_bar_is_in_the_sweep_page_only(tmp_path, capsys):
    swept, still = tmp_path / "sweep.html", tmp_path / "still.html"
    assert main(["view", str(FILE), "--sweep", "crank_joint=0deg:360deg:13", "--html", str(swept)]) == 0
    assert main(["view", str(FILE), "--html", str(still)]) == 0
    text = swept.read_text()
    assert 'id="screwkin-player"' in text and 'data-frames="13"' in text and 'class="sk-scrub"' in text
    assert "crank_joint = 30 deg" in text  # the frames' labels in the unit typed
    assert "screwkin-player" not in still.read_text()
    assert not re.search(r"""(src|href)=["']https?://""", text)  # nothing fetched: offline


@pytest.mark.chromium
@pytest.mark.slow
@pytest.mark.skipif(chromium() is None, reason="Chromium is not installed (.ci/run installs it)")
def test_scrubbing_shows_the_sweep_configuration(tmp_path):
    page = tmp_path / "sweep.html"
    assert main(["view", str(FILE), "--sweep", "crank_joint=0deg:360deg:13", "--html", str(page)]) == 0
    frames = [0, 4, 9]
    text = page.read_text()
    at = text.rfind("</body>")
    probe = tmp_path / "probe.html"
    probe.write_text(text[:at] + PROBE % json.dumps(frames) + text[at:])
    p = subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
                        "--enable-unsafe-swiftshader", "--no-first-run", "--disable-background-networking",
                        f"--user-data-dir={tmp_path / 'profile'}", "--virtual-time-budget=15000", "--dump-dom",
                        probe.as_uri()], capture_output=True, text=True, timeout=120)
    m = re.search(r'<pre id="probe">(.*?)</pre>', p.stdout)
    assert m, p.stderr[-500:]
    out = json.loads(m.group(1).replace("&quot;", '"'))
    mech = screwkin.load(FILE)
    res = screwkin.sweep(screwkin.PositionSolver(mech), "crank_joint", 0.0, 2 * np.pi, 12)
    geom = build_scene(mech, res.q[0]).geometry
    data, gdata = mech.model.createData(), pin.GeometryData(geom)
    for k in frames:
        shown = out["frames"][str(k)]
        assert shown["slider"] == k
        assert shown["readout"] == f"frame {k + 1} / 13: crank_joint = {30 * k:.4g} deg"
        pin.updateGeometryPlacements(mech.model, data, geom, gdata, res.q[k])
        for name in ("crank_0", "coupler_0", "rocker_0"):
            want = gdata.oMg[geom.getGeometryId(name)].translation
            np.testing.assert_allclose(shown["links"][name], want, rtol=0, atol=1e-6)  # float32 in the page
