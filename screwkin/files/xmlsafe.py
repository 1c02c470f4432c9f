"""Safe reading of the files that come from users: XML, YAML, and the files themselves.

Mechanism files are untrusted:

* only regular files are read (a FIFO or a device would block or never end), and
  at most a bounded number of bytes (:data:`~screwkin.files.description.LIMITS`);
* XML: external entities are never resolved and any entity declaration (the
  basis of "billion laughs" expansion bombs) is refused before anything is
  expanded -- defusedxml does this on top of the standard library parser; the
  nesting depth is bounded (Pinocchio's XML parser recurses);
* YAML: the safe loader (plain data only), with aliases refused (a few hundred
  bytes of nested aliases expand to gigabytes) and the nesting depth bounded.
"""

from __future__ import annotations

import io
import os
import stat
import xml.etree.ElementTree as ET
from pathlib import Path

import defusedxml
import defusedxml.ElementTree as SafeET

from ..errors import MechanismFileError, shorten
from .description import LIMITS

__all__ = ["parse_xml_text", "read_regular_file", "load_yaml_text", "inside_folder", "MAX_DEPTH"]

#: Deepest element nesting accepted in XML and YAML (URDF and SDF need about 6, sidecars 3).
MAX_DEPTH = 100


def inside_folder(path: Path, folder: Path) -> bool:
    """Whether ``path`` lies in ``folder`` once both have their symbolic links and ``..`` resolved;
    False where the system refuses to resolve either (the one containment check of the readers:
    meshes, xacro includes)."""
    try:
        return Path(os.path.realpath(path)).is_relative_to(Path(os.path.realpath(folder)))
    except (OSError, ValueError):
        return False


def read_regular_file(path: Path | str, max_bytes: int, what: str = "file") -> bytes:
    """The bytes of ``path``, refusing what is not a regular file and files over ``max_bytes``.

    The file is opened without blocking and checked with fstat, so a named pipe is
    refused instead of waited on (and a file replaced between check and open is
    still the file checked)."""
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise MechanismFileError(path, "no such file") from None
    except IsADirectoryError:
        raise MechanismFileError(path, f"is a directory, not a {what}") from None
    except (OSError, ValueError) as exc:
        raise MechanismFileError(path, f"cannot read: {getattr(exc, 'strerror', None) or exc}") from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise MechanismFileError(path, f"is a directory, not a {what}")
        if not stat.S_ISREG(st.st_mode):
            raise MechanismFileError(path, f"is not a regular file (a pipe, socket or device), not a {what}")
        if st.st_size > max_bytes:
            raise MechanismFileError(path, f"is {st.st_size / 1e6:.3g} MB; screwkin reads {what}s of at most "
                                           f"{max_bytes / 1e6:g} MB")
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        chunks, size = [], 0
        while True:
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
            if size > max_bytes:  # the file grew while being read
                raise MechanismFileError(path, f"is over {max_bytes / 1e6:g} MB; screwkin reads {what}s of at "
                                               f"most {max_bytes / 1e6:g} MB")
        return b"".join(chunks)
    except OSError as exc:
        raise MechanismFileError(path, f"cannot read: {exc.strerror or exc}") from None
    finally:
        os.close(fd)


def parse_xml_text(text: str, path: Path | str) -> ET.Element:
    """Parse ``text`` (the contents of ``path``) and return the root element.

    The elements are counted and their nesting measured while parsing, so a file of a
    million elements is refused after ``LIMITS.elements`` of them, not after building them."""

    if not text.strip():
        raise MechanismFileError(path, "the file is empty")
    root, depth, count = None, 0, 0
    try:
        for event, elem in SafeET.iterparse(io.StringIO(text), events=("start", "end"), forbid_dtd=False,
                                            forbid_entities=True, forbid_external=True):
            if event == "end":
                depth -= 1
                continue
            if root is None:
                root = elem
            depth += 1
            count += 1
            if depth > MAX_DEPTH:
                raise MechanismFileError(path, f"XML nested deeper than {MAX_DEPTH} elements (refused: no mechanism "
                                               "file needs it)")
            if count > LIMITS.elements:
                raise MechanismFileError(path, f"more than {LIMITS.elements} XML elements (refused: the largest "
                                               "robots have a few thousand)")
    except defusedxml.EntitiesForbidden:
        raise MechanismFileError(path, "XML entity declarations are not allowed (refused for safety)") from None
    except defusedxml.ExternalReferenceForbidden:
        raise MechanismFileError(path, "XML external references are not allowed (refused for safety)") from None
    except defusedxml.DTDForbidden:  # pragma: no cover - forbid_dtd is False
        raise MechanismFileError(path, "XML document type declarations are not allowed") from None
    except ET.ParseError as exc:
        dashes = _dashes_in_comment(text, *getattr(exc, "position", (0, 0)))
        if dashes is not None:
            raise MechanismFileError(path, f"malformed XML: a comment cannot contain '--' (line {dashes[0]}, in the "
                                           f"comment opened at line {dashes[1]}): write it without the double "
                                           "hyphen") from None
        raise MechanismFileError(path, f"malformed XML: {shorten(str(exc), 120)}") from None
    if root is None:  # pragma: no cover - expat reports "no element found" first
        raise MechanismFileError(path, "malformed XML: no element found")
    return root


def _dashes_in_comment(text: str, line: int, column: int) -> tuple | None:
    """(line of the ``--``, line of its ``<!--``) when the parse error at (line, column) is a
    ``--`` inside a comment (XML forbids it; expat says only "invalid token"), else None."""
    if line < 1:
        return None
    lines = text.splitlines(keepends=True)
    offset = sum(len(x) for x in lines[:line - 1]) + column
    start = text.rfind("<!--", 0, offset)
    if start < 0:
        return None
    dashes = text.find("--", start + 4, offset + 1)
    if dashes < 0 or text.startswith("-->", dashes):  # no "--" before the error, or the comment was closed
        return None
    return text.count("\n", 0, dashes) + 1, text.count("\n", 0, start) + 1


def _safe_loader() -> type:
    import yaml  # lazily: only sidecars and study specs are YAML (7 ms)

    class _NoAliasLoader(yaml.SafeLoader):
        """SafeLoader without aliases (``*a``) and with a bounded nesting depth."""

        _depth = 0

        def compose_node(self, parent, index: int):
            if self.check_event(yaml.AliasEvent):
                event = self.peek_event()
                raise yaml.composer.ComposerError(None, None, "YAML aliases (*name) are not allowed (refused for "
                                                  "safety: sidecars never need them)", event.start_mark)
            self._depth += 1
            try:
                if self._depth > MAX_DEPTH:
                    raise yaml.composer.ComposerError(None, None, f"nested deeper than {MAX_DEPTH} levels",
                                                      self.peek_event().start_mark)
                return super().compose_node(parent, index)
            finally:
                self._depth -= 1

    return _NoAliasLoader


def load_yaml_text(text: str, path: Path | str) -> dict:
    """The plain data of a YAML document from a user (see the module's notes)."""
    import yaml  # lazily: only sidecars and study specs are YAML (7 ms)

    loader = _safe_loader()(text)
    try:
        return loader.get_single_data()
    except yaml.YAMLError as exc:
        problem = getattr(exc, "problem", None)
        mark = getattr(exc, "problem_mark", None)
        first = f"{problem} (line {mark.line + 1}, column {mark.column + 1})" if problem and mark else \
            (str(exc).splitlines() or ["?"])[0]
        raise MechanismFileError(path, f"malformed YAML: {shorten(first, 160)}") from None
    except (ValueError, OverflowError, TypeError) as exc:  # e.g. a timestamp out of range, a 5,000-digit integer
        raise MechanismFileError(path, f"malformed YAML: {shorten(str(exc), 120)}") from None
    except RecursionError:  # pragma: no cover - the depth is bounded above
        raise MechanismFileError(path, f"malformed YAML: nested deeper than {MAX_DEPTH} levels") from None
    finally:
        loader.dispose()
