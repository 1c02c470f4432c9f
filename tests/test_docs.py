"""Every code block of the documentation site runs (issue 45 item 2): the docs cannot lie.

Each page of docs/ is read for its fenced blocks: ```bash blocks are shell commands (`screwkin ...`,
`cat > FILE <<EOF`), run whole with ``bash -e`` and checked for exit 0 and no traceback; ```python
blocks are executed, one namespace per page in page order.  A page's blocks run in one fresh folder
that has the repository's robots/ and examples/ beside them (the pages are written from the
repository's root), so one block can read the file another wrote.  A block preceded by
``<!-- needs: MODULE -->`` runs where MODULE imports (mujoco, example_robot_data: the test extra has
both) and skips naming it elsewhere.  ```text and ```console blocks are shown, never run (install lines,
a server that waits, output).

The fast part runs one short page (howto/units.md); every page is the slow part: 44 bash blocks (65
`screwkin` commands) and 12 Python blocks, 390 s on the loaded 2-core machine (141 s of CPU).  The site's own build --
the gallery's scripts run by sphinx-gallery, the command pages generated from the parser, warnings as
errors -- and what Chromium shows of it are tests/test_docs_site.py.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import runpy  # noqa: F401  (the pages' Python runs as a script would: exec in a fresh namespace)
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
FENCE = re.compile(r"(?:<!-- needs: (?P<needs>[\w.]+) -->\n)?^```(?P<lang>[\w-]*)[^\n]*\n(?P<body>.*?)^```\s*$",
                   re.S | re.M)


def pages():
    """Every Markdown page of the site, as written (the generated command pages are the parser's)."""
    skip = {DOCS / "README.md", DOCS / "reference" / "api.md"}  # (api.md: generated, autodoc only)
    return sorted(p for p in DOCS.rglob("*.md")
                  if p not in skip and "_build" not in p.parts and "commands" not in p.relative_to(DOCS).parts)


def blocks(page: Path):
    """(lang, body, needs) of each fenced block of ``page``, in order; the {eval-rst}, {toctree} and
    other directives are not code."""
    for m in FENCE.finditer(page.read_text()):
        yield m.group("lang"), m.group("body"), m.group("needs")


def workdir(tmp_path: Path) -> Path:
    for name in ("robots", "examples"):
        (tmp_path / name).symlink_to(ROOT / name)
    return tmp_path


def env():
    return dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
                MPLBACKEND="Agg", SCREWKIN_CACHE=os.environ.get("SCREWKIN_CACHE", ""))


#: What a block may need (``<!-- needs: NAME -->``): the test extra installs each, so under CI=true a
#: skip for one fails the run (tests/conftest.py).
#: example-robot-data 6 installs its robots under cmeel.prefix with no importable module: it is found
#: as the other tests find it (conftest.ROBOT_DATA), not by importing it.
NEEDS = {"mujoco": lambda: pytest.importorskip("mujoco"),
         "example_robot_data": lambda: pytest.skip("example-robot-data is not installed")}


def available(module: str) -> bool:
    import importlib.util

    if module == "example_robot_data":
        from conftest import ROBOT_DATA

        return ROBOT_DATA is not None
    return importlib.util.find_spec(module) is not None


def run_page(page: Path, cwd: Path):
    """Run ``page``'s bash and python blocks in ``cwd``; return how many ran.  The blocks that need a
    module that is missing are left out, the others run, then the test skips naming the module."""
    ran = 0
    missing = []
    namespace = {"__name__": "__main__"}
    for lang, body, needs in blocks(page):
        if lang not in ("bash", "python"):
            continue
        if needs:
            assert needs in NEEDS, f"{page.name}: needs {needs!r}: add it to NEEDS"
            if not available(needs):
                missing.append(needs)
                continue
        where = f"{page.name}: block {ran + 1}:\n{body}"
        if lang == "bash":
            p = subprocess.run(["bash", "-e", "-c", body], cwd=cwd, env=env(), capture_output=True, text=True,
                               timeout=900)
            assert p.returncode == 0, f"{where}\nexit {p.returncode}\n{p.stderr[-3000:]}"
            assert "Traceback" not in p.stdout + p.stderr, f"{where}\n{p.stderr[-3000:]}"
        else:
            old = Path.cwd()
            os.chdir(cwd)
            try:
                with contextlib.redirect_stdout(io.StringIO()):
                    exec(compile(body, str(page), "exec"), namespace)  # noqa: S102  (the page's own code)
            finally:
                os.chdir(old)
        ran += 1
    for module in missing:
        NEEDS[module]()  # skips: "could not import 'MODULE'"
    return ran


def test_the_pages_have_blocks_to_run():
    names = {p.relative_to(DOCS).as_posix() for p in pages()}
    assert {"start.md", "tutorials/student.md", "howto/stewart-fk.md"} <= names
    langs = [lang for p in pages() for lang, _, _ in blocks(p)]
    assert langs.count("bash") >= 20 and langs.count("python") >= 5


def test_a_failing_block_fails(tmp_path):
    """The runner sees a command that fails and a Python block that raises."""
    page = tmp_path / "bad.md"
    page.write_text("```bash\nscrewkin mobility no_such_file.urdf\n```\n")
    with pytest.raises(AssertionError, match="exit 1"):
        run_page(page, tmp_path)
    page.write_text("```python\nraise ValueError('x')\n```\n")
    with pytest.raises(ValueError):
        run_page(page, tmp_path)


def test_a_few_commands_run(tmp_path):
    """The fast part: one short page's commands (units as typed), run as the slow part runs every page."""
    assert run_page(DOCS / "howto" / "units.md", workdir(tmp_path)) == 1  # one block, two commands


@pytest.mark.slow
@pytest.mark.parametrize("page", [p.relative_to(DOCS).as_posix() for p in pages()])
def test_every_block_of_every_page_runs(tmp_path, page):
    run_page(DOCS / page, workdir(tmp_path))
