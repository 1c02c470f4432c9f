"""Mesh files named by mechanism files: where screwkin looks for them.

``package://`` URIs resolve against the file's folder and its parents, the
folders of ``ROS_PACKAGE_PATH`` and the ``--package-dir`` folders; ``file://`` and
relative paths as written.  A missing mesh is a warning (views draw stand-ins),
never a failure.

Mesh files are read only from inside the robot file's folder tree, the
``--package-dir`` and ``ROS_PACKAGE_PATH`` folders, and the package the file
sits in (the folder, at most two above it, named like a ``package://`` URI's
package), after symbolic links and ``..`` are resolved; ``package://NAME/...``
stays inside NAME's folder.  A mesh elsewhere is a warning and is not read (a
hostile file cannot get another file's bytes into a ``view --html`` page).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from ..errors import quote, shorten
from .description import LIMITS
from .xmlsafe import inside_folder

__all__ = ["resolve_uri", "find_mesh", "locate_mesh", "check_meshes"]


def _is_file(p: Path) -> bool:
    """Path.is_file that answers False for names the system refuses (too long, NUL bytes)."""
    try:
        return p.is_file()
    except (OSError, ValueError):
        return False


def installed_package_roots() -> list:
    """Folders where pip-installed description packages keep their ROS packages: ``cmeel.prefix/share``
    beside the installed Python packages (example-robot-data: ``package://example-robot-data/robots/...``)."""
    out = []
    for entry in sys.path:
        share = Path(entry or ".") / "cmeel.prefix" / "share"
        try:
            if share.is_dir() and share not in out:
                out.append(share)
        except OSError:
            continue
    return out


def _roots(base: Path, package_dirs: list=()) -> list:
    roots = [Path(d) for d in package_dirs or ()]
    roots += [base, *list(base.parents)[:2]]
    roots += [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    roots += installed_package_roots()
    out = []
    for r in roots:
        if r not in out:
            out.append(r)
    return out


def resolve_uri(uri: str, base: Path, package_dirs: list=(), roots: list | None=None) -> list:
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


def _real(p: Path) -> Path | None:
    """p with symbolic links and ``..`` resolved, or None when the system refuses it."""
    try:
        return Path(os.path.realpath(p))
    except (OSError, ValueError):
        return None


def _allowed(uri: str, cand: Path, real: Path, base: Path, package_dirs: list) -> bool:
    """Whether the mesh candidate ``cand`` (``real`` once resolved) may be read: inside the file's folder,
    a --package-dir or ROS_PACKAGE_PATH folder, or the package the file is in; a ``package://NAME/``
    candidate also inside that package's folder (``package://NAME/../x`` does not leave it)."""
    folders = [base, *(package_dirs or ())]
    folders += [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    folders += installed_package_roots()
    if uri.startswith("package://"):
        package = uri[len("package://"):].partition("/")[0]
        # the package's own folder: cand is root/NAME/inside or root/inside (both written so)
        inside = uri[len("package://"):].partition("/")[2].lstrip("/")
        depth = len(Path(inside).parts) if inside else 0
        pkg_root = cand
        for _ in range(depth):
            pkg_root = pkg_root.parent
        if not inside_folder(real, pkg_root):
            return False
        own = [a for a in [base, *list(base.parents)[:2]] if package and a.name == package]
        folders += own
    return any(inside_folder(real, f) for f in folders)


def locate_mesh(uri: str, base: Path, package_dirs: list=(), roots: list | None=None) -> tuple:
    """(the first existing, allowed file among the candidates of ``uri`` or None, the resolved path
    of an existing candidate that was refused because it lies outside the allowed folders, or None)."""
    refused = None
    for c in resolve_uri(uri, base, package_dirs, roots):
        if not _is_file(c):
            continue
        real = _real(c)
        if real is not None and _allowed(uri, c, real, base, package_dirs):
            return c, None
        refused = refused or real or c
    return None, refused


def find_mesh(uri: str, base: Path, package_dirs=(), roots=None):
    """The first existing file among the candidates of ``uri`` inside the allowed folders, or None."""
    return locate_mesh(uri, base, package_dirs, roots)[0]


def check_meshes(path: str | Path, root, package_dirs=(), found_list: list | None = None) -> list:
    """Warnings for mesh files that cannot be found (missing meshes do not fail a load); ``found_list``
    (a list), when given, gets the path of each mesh file found."""
    meshes = list(root.iter("mesh"))
    if not meshes:  # (the folders to look in take a scan of sys.path: only when there is a mesh to find)
        return []
    base = Path(path).resolve().parent
    roots = _roots(base, package_dirs)
    missing, outside, checked = [], [], set()
    for mesh in meshes:
        uri = mesh.get("filename") or (mesh.findtext("uri") or "").strip()
        if not uri or uri.startswith("model://") or uri in checked:
            continue
        if len(checked) >= LIMITS.meshes:
            break
        checked.add(uri)
        found, refused = locate_mesh(uri, base, package_dirs, roots)
        if refused is not None and found is None:
            outside.append(uri)
        elif found is None:
            missing.append(uri)
        elif found_list is not None:
            found_list.append(str(found))
    warnings = [f"mesh {quote(m, 120)} is outside the robot's folder and the package folders "
                f"(--package-dir, ROS_PACKAGE_PATH): not read, views draw a stand-in" for m in outside[:3]]
    if len(outside) > 3:
        warnings.append(f"{len(outside) - 3} more mesh file(s) outside the robot's folder and the package folders")
    if not missing:
        return warnings
    shown = ", ".join(quote(m, 60) for m in missing[:3]) + (f" and {len(missing) - 3} more" if len(missing) > 3 else "")
    msg = f"{len(missing)} mesh file(s) not found (views will use stand-ins): {shown}"
    if len(checked) >= LIMITS.meshes:
        msg += f" (only the first {LIMITS.meshes} mesh files were looked for)"
    if any(m.startswith("package://") for m in missing):
        looked = ", ".join(shorten(str(r), 60) for r in roots[:4]) + (f" and {len(roots) - 4} more" if len(roots) > 4
                                                                        else "")
        msg += f"; looked for packages in {looked} (set ROS_PACKAGE_PATH or use --package-dir DIR)"
    return warnings + [msg]

