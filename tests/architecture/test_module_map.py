"""The module map (docs/explanation/layout.md, "How the code is laid out"; it was the README's until
issue 45 cut the README to two screens) names every module of the package, in the bullet of its folder
(issue 23 item 8): a newcomer can find the room a change belongs in."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def bullets() -> dict:
    page = (ROOT / "docs" / "explanation" / "layout.md").read_text()
    section = page.split("# How the code is laid out", 1)[1].split("\n## ", 1)[0]
    out = {}
    for item in re.split(r"\n- ", section)[1:]:
        m = re.match(r"`(screwkin/[\w/]*)`", item)
        if m:
            out[m.group(1).rstrip("/")] = item
    return out


def test_every_module_is_named_in_its_folders_bullet():
    found = bullets()
    missing = []
    for path in sorted((ROOT / "screwkin").rglob("*.py")):
        folder = path.parent.relative_to(ROOT).as_posix()
        if path.name == "__init__.py" and folder != "screwkin":
            continue
        if f"`{path.name}`" not in found.get(folder, ""):
            missing.append(path.relative_to(ROOT).as_posix())
    assert not missing, f"modules not named in docs/explanation/layout.md's map (in their folder's bullet): {missing}"


def test_the_readme_fits_two_screens_and_starts_with_the_two_commands():
    """Issue 45: the README is what screwkin is, the two set-up commands first, a first four-bar and links
    into the site -- at most 150 lines; every page it links to exists."""
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 150, len(readme.splitlines())
    commands = re.findall(r"^    (pip install .*)$", readme, re.M)
    assert commands[:2] == ["pip install -e . && screwkin mobility robots/delta_parallelogram.urdf --output platform",
                            "pip install -c .ci/constraints.txt -e '.[test]' && python -m pytest -q"]
    links = re.findall(r"\]\((docs/[^)#]+)\)", readme)
    assert len(links) >= 10 and all((ROOT / link).is_file() for link in links), links
