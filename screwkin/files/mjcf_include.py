"""MJCF ``<include file="...">`` expanded as MuJoCo expands it, with the bounds of untrusted input.

MuJoCo replaces an ``<include>`` by the children of the included file's ``<mujoco>`` root, wherever
the element stands; the file's path is relative to the folder of the main model file (nested
includes too).  Here an included file must lie in that folder or below it (a model reads only
files beside it), be a regular file, and the files together stay within the limits of one file
(:class:`~screwkin.files.description.Limits`: bytes and XML elements, and the nesting depth of
:data:`~screwkin.files.xmlsafe.MAX_DEPTH` over the whole model, an included file's elements as deep
as they stand once included, not as deep as in their own file); at most
:data:`~screwkin.files.xacro.MAX_INCLUDES` files; a file that includes itself, directly or not, is
refused as MuJoCo refuses it.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import MechanismFileError, quote, shorten
from .description import LIMITS
from .xacro import MAX_INCLUDES
from .xmlsafe import MAX_DEPTH, inside_folder, parse_xml_text, read_regular_file
from typing import TYPE_CHECKING
if TYPE_CHECKING:
    from xml.etree.ElementTree import Element

__all__ = ["expand_includes"]


def expand_includes(root: Element, path: str | Path, read: list | None = None) -> int:
    """Replace every ``<include>`` under ``root`` (the main file's ``<mujoco>``, read from ``path``)
    by the included file's content, in place.  Returns the number of files included; ``read`` (a list),
    when given, gets the path of each file included."""
    path = Path(path)
    folder = Path(os.path.realpath(path.parent if str(path.parent) else "."))
    state = {"files": 0, "bytes": 0, "elements": sum(1 for _ in root.iter())}

    def included(spec: str, chain: tuple, depth: int) -> list:
        if not spec:
            raise MechanismFileError(path, "<include> has no file")
        target = Path(spec) if os.path.isabs(spec) else folder / spec
        real = Path(os.path.realpath(target))
        if not inside_folder(real, folder):
            raise MechanismFileError(path, f"<include file={quote(spec, 60)}> is outside the folder of "
                                           f"{quote(path.name)} (refused: a model reads only files beside it or below)")
        if real in chain:
            raise MechanismFileError(path, f"<include file={quote(spec, 60)}> includes itself (through "
                                           f"{' -> '.join(quote(p.name, 30) for p in chain[1:]) or 'itself'})")
        state["files"] += 1
        if state["files"] > MAX_INCLUDES:
            raise MechanismFileError(path, f"more than {MAX_INCLUDES} files included (refused)")
        try:
            raw = read_regular_file(real, LIMITS.file_bytes, "included file")
        except MechanismFileError as exc:
            raise MechanismFileError(path, f"<include file={quote(spec, 60)}>: {exc.problems[0]}") from None
        state["bytes"] += len(raw)
        if state["bytes"] > LIMITS.file_bytes:
            raise MechanismFileError(path, f"the file and its includes are over {LIMITS.file_bytes / 1e6:g} MB")
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError:
            raise MechanismFileError(real, "not a text file (not UTF-8)") from None
        sub = parse_xml_text(text, real)
        if sub.tag != "mujoco":
            raise MechanismFileError(path, f"<include file={quote(spec, 60)}>: its root element is "
                                           f"<{shorten(str(sub.tag), 30)}>, not <mujoco>")
        state["elements"] += sum(1 for _ in sub.iter())
        if state["elements"] > LIMITS.elements:
            raise MechanismFileError(path, f"the file and its includes hold more than {LIMITS.elements:,} XML elements")
        if read is not None:
            read.append(str(real))
        expand(sub, chain + (real,), depth)  # its root's children take the place of the <include>
        return list(sub)

    def expand(elem, chain, depth) -> None:  # depth: elem's, in the whole model (the main file's root: 1)
        k = 0
        while k < len(elem):
            child = elem[k]
            if child.tag == "include":
                content = included(child.get("file"), chain, depth)
                elem.remove(child)
                for j, c in enumerate(content):
                    elem.insert(k + j, c)
                k += len(content)
            else:
                if depth + 1 > MAX_DEPTH:
                    raise MechanismFileError(path, f"XML nested deeper than {MAX_DEPTH} elements once its includes "
                                                   "are in place (refused: no mechanism file needs it)")
                expand(child, chain, depth + 1)
                k += 1

    expand(root, (Path(os.path.realpath(path)),), 1)
    return state["files"]
