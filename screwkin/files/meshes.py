"""Mesh files named by mechanism files: where screwkin looks for them.

``package://`` URIs resolve against the file's folder and its parents, the
folders of ``ROS_PACKAGE_PATH`` and the ``--package-dir`` folders; ``file://`` and
relative paths as written.  A missing mesh is a warning (views draw stand-ins),
never a failure.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import quote, shorten
from .description import LIMITS

__all__ = ["resolve_uri", "find_mesh", "check_meshes"]


def _is_file(p: Path) -> bool:
    """Path.is_file that answers False for names the system refuses (too long, NUL bytes)."""
    try:
        return p.is_file()
    except (OSError, ValueError):
        return False


def _roots(base: Path, package_dirs=()) -> list:
    roots = [Path(d) for d in package_dirs or ()]
    roots += [base, *list(base.parents)[:2]]
    roots += [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    out = []
    for r in roots:
        if r not in out:
            out.append(r)
    return out


def resolve_uri(uri: str, base: Path, package_dirs=(), roots=None):
    """Candidate paths of a mesh URI: ``package://`` against ``package_dirs`` (the
    ``--package-dir`` folders), the file's folder and the two above it, and
    ``ROS_PACKAGE_PATH`` (``roots``: those folders, when already known); ``file://``
    as is, relative paths against the file."""
    if uri.startswith("package://"):
        rest = uri[len("package://"):]
        package, _, inside = rest.partition("/")
        inside = inside.lstrip("/")
        cands = []
        for r in roots if roots is not None else _roots(base, package_dirs):
            if package:
                cands += [r / package / inside, r / inside]
            else:
                cands.append(r / inside)
        return cands
    if uri.startswith("file://"):
        return [Path(uri[len("file://"):])]
    p = Path(uri)
    return [p if p.is_absolute() else base / p]


def find_mesh(uri: str, base: Path, package_dirs=(), roots=None):
    """The first existing file among the candidates of ``uri``, or None."""
    return next((c for c in resolve_uri(uri, base, package_dirs, roots) if _is_file(c)), None)


def check_meshes(path, root, package_dirs=()) -> list:
    """Warnings for mesh files that cannot be found (missing meshes do not fail a load)."""
    base = Path(path).resolve().parent
    roots = _roots(base, package_dirs)
    missing, checked = [], set()
    for mesh in root.iter("mesh"):
        uri = mesh.get("filename") or (mesh.findtext("uri") or "").strip()
        if not uri or uri.startswith("model://") or uri in checked:
            continue
        if len(checked) >= LIMITS.meshes:
            break
        checked.add(uri)
        if find_mesh(uri, base, package_dirs, roots) is None:
            missing.append(uri)
    if not missing:
        return []
    shown = ", ".join(quote(m, 60) for m in missing[:3]) + (f" and {len(missing) - 3} more" if len(missing) > 3 else "")
    msg = f"{len(missing)} mesh file(s) not found (views will use stand-ins): {shown}"
    if len(checked) >= LIMITS.meshes:
        msg += f" (only the first {LIMITS.meshes} mesh files were looked for)"
    if any(m.startswith("package://") for m in missing):
        looked = ", ".join(shorten(str(r), 60) for r in roots[:4]) + (f" and {len(roots) - 4} more" if len(roots) > 4
                                                                        else "")
        msg += f"; looked for packages in {looked} (set ROS_PACKAGE_PATH or use --package-dir DIR)"
    return [msg]

