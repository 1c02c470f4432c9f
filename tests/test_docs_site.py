"""The documentation site builds from docs/ with warnings as errors, and a person can read it (issue 45
items 1 and 4).

The build is the documented command, ``sphinx-build -W -b html docs OUT``, run in a fresh process into a
temporary folder: it runs every gallery script (examples/gallery/plot_*.py, sphinx-gallery), generates a
page per command from screwkin's parser (docs/_ext/screwkin_docs.py) and the API page from the docstrings
of screwkin/__init__.py's public names.  The pages are then opened in headless Chromium, driven through
its DevTools protocol as tests/test_view_interactive_chromium.py drives it: the index, a command's page
and a gallery page, whose pictures must be painted (each <img> decoded, naturalWidth > 0).

The docs packages come with the test extra (.ci/run installs them): a skip for them fails CI.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import DevTools
from screwkin.cli import COMMANDS

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    pytest.importorskip("sphinx")  # the docs packages come with the test extra
    pytest.importorskip("sphinx_gallery")
    pytest.importorskip("sphinxarg")
    pytest.importorskip("myst_parser")
    pytest.importorskip("pydata_sphinx_theme")
    out = tmp_path_factory.mktemp("site") / "html"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
               MPLBACKEND="Agg")
    start = time.monotonic()
    p = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-b", "html", "docs", str(out)],
                       cwd=ROOT, env=env, capture_output=True, text=True, timeout=1800)
    assert p.returncode == 0, (p.stdout[-3000:], p.stderr[-5000:])
    print(f"site built in {time.monotonic() - start:.0f} s: {len(list(out.rglob('*.html')))} pages")
    return out


def test_the_site_has_a_page_per_command_an_api_page_and_the_gallery(site):
    for name, _ in COMMANDS:
        page = site / "reference" / "commands" / f"{name}.html"
        assert page.is_file(), name
        text = page.read_text()
        assert f"screwkin {name}" in text and "--help" in text, name  # the parser's options are on the page
    sweep = (site / "reference" / "commands" / "sweep.html").read_text()
    for option in ("--input", "--from", "--steps", "--turn", "--plot"):
        assert option in sweep, option
    api = (site / "reference" / "api.html").read_text()
    import screwkin

    for name in screwkin.__all__:
        assert f'id="screwkin.{name}"' in api, name
    pictures = sorted((site / "_images").glob("sphx_glr_plot_*_001.png"))
    examples = {re.sub(r"_\d{3}\.png$", "", p.name) for p in pictures}
    assert len(examples) >= 6, examples
    assert len(list(site.rglob("*.html"))) >= 50


# ------------------------------------------------------------------ headless Chromium
def _chromium():
    from screwkin.present.view import chromium

    return chromium()


PICTURES = """JSON.stringify(Array.from(document.images).map(i => [i.getAttribute('src'), i.complete, i.naturalWidth,
    i.getBoundingClientRect().width]))"""


@pytest.mark.chromium
@pytest.mark.skipif(_chromium() is None, reason="Chromium is not installed (.ci/run installs it)")
def test_the_site_as_a_person_sees_it_in_chromium(site, tmp_path):
    pytest.importorskip("websockets.sync.client")
    browser = DevTools(tmp_path / "profile", size=(1200, 900))
    try:
        browser.call("Page.enable")
        browser.open((site / "index.html").as_uri())
        assert "screwkin" in browser.evaluate("document.title")
        links = browser.evaluate("Array.from(document.querySelectorAll('a')).map(a => a.textContent).join('|')")
        for words in ("Getting started", "Tutorials", "Gallery", "Reference"):
            assert words in links, words
        assert all(ok and width > 0 for _, ok, width, _ in json.loads(browser.evaluate(PICTURES))), "index picture"

        browser.open((site / "reference" / "commands" / "sweep.html").as_uri())
        text = browser.evaluate("document.body.innerText")
        assert "screwkin sweep" in text and "--steps" in text and "--turn" in text

        browser.open((site / "auto_examples" / "plot_coupler_curve.html").as_uri())
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            pictures = json.loads(browser.evaluate(PICTURES))
            if pictures and all(complete for _, complete, _, _ in pictures):
                break
            time.sleep(0.3)
        figures = [p for p in pictures if "sphx_glr_plot_coupler_curve_001" in (p[0] or "")]
        assert figures, pictures
        assert all(natural > 0 and shown > 0 for _, _, natural, shown in figures), figures
        assert "screwkin(" in browser.evaluate("document.body.innerText")  # its code beside its picture
        shot = browser.call("Page.captureScreenshot", format="png")["data"]
        assert len(shot) > 10000
    finally:
        browser.close()
