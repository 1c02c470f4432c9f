"""The README's module map names every module of the package, in the bullet of its folder
(issue 23 item 8): a newcomer can find the room a change belongs in."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def bullets() -> dict:
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## How the code is laid out", 1)[1].split("\n## ", 1)[0]
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
    assert not missing, f"modules not named in the README's map (in their folder's bullet): {missing}"
