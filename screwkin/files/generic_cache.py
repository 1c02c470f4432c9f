"""Where screwkin keeps the generic solution sets of the mechanisms it has solved (the start systems of
model.homotopy.parameter's homotopy), and how they are read back.

The folder: ``$SCREWKIN_CACHE`` if set, else ``$XDG_CACHE_HOME/screwkin/generic`` (``~/.cache/screwkin/
generic`` when XDG_CACHE_HOME is not set).  One JSON file per architecture, named by the SHA-256 of the
architecture's description (``key``).  Clearing it: delete the folder (``rm -rf ~/.cache/screwkin``);
``SCREWKIN_CACHE=off`` neither reads nor writes one.  The bundled robots' sets ship in
``screwkin/files/generic_sets/`` and are read (and checked) the same way.

The files are ours but are read as untrusted input: at most 1 MiB, JSON only (no pickle), every field
checked for its type and shape, numbers finite, the SHA-256 of its numbers and claim as written
(a file cut short or edited); a file that fails any check is ignored (and the set computed again).  The caller checks the roots themselves against its own system before using them.
Nothing is written when the process has a file-size limit (RLIMIT_FSIZE), the folder cannot be made
or written, or the write fails in any way: the answer never depends on the cache, only its time.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np

try:
    import resource
except ImportError:  # no such module on Windows: no limit to read, nothing written
    resource = None

__all__ = ["folder", "key", "read", "write", "VERSION"]

#: Bumped when the stored formulation changes: older files are ignored.
VERSION = 1
#: Sets shipped with screwkin (the bundled robots'), read like the cache's, never written.
SHIPPED = Path(__file__).parent / "generic_sets"
_MAX_BYTES = 1 << 20


def folder() -> Path | None:
    """The cache folder, or None when caching is off."""
    own = os.environ.get("SCREWKIN_CACHE", "")
    if own.lower() in ("off", "0", "no", "false"):
        return None
    if own:
        return Path(own)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "screwkin" / "generic"


def key(kind: str, arrays) -> str:
    """The SHA-256 of an architecture: its kind and its numbers rounded to 12 significant digits."""
    text = json.dumps([kind, VERSION] + [np.format_float_scientific(float(v), 11) for a in arrays
                                         for v in np.asarray(a, float).ravel()])
    return hashlib.sha256(text.encode()).hexdigest()


def _complex(rows, width: int):
    """A (n, width) complex array from [[re, im], ...] rows, or None when the data has another shape."""
    a = np.asarray(rows, dtype=float)
    if a.ndim != 3 or a.shape[1:] != (width, 2) or not np.isfinite(a).all():
        return None
    return a[..., 0] + 1j * a[..., 1]


def read(name: str, width: int, n: int) -> tuple | None:
    """(c0 (n,), X (N, width), how, path) stored under ``name`` -- in the cache folder, else among the
    sets shipped with screwkin (``SHIPPED``) --, or None (absent, unreadable or malformed)."""
    if len(name) != 64 or not all(ch in "0123456789abcdef" for ch in name):
        return None
    where = folder()
    for path in ([where / f"{name}.json"] if where is not None else []) + [SHIPPED / f"{name}.json"]:
        got = _read(path, name, width, n)
        if got is not None:
            return (*got, path)
    return None


def _read(path: Path, name: str, width: int, n: int) -> tuple | None:
    try:
        if not path.is_file() or path.stat().st_size > _MAX_BYTES:
            return None
        data = json.loads(path.read_text(encoding="utf-8"))
        if not isinstance(data, dict) or data.get("version") != VERSION or data.get("key") != name:
            return None
        how = data.get("certified_by")
        if not isinstance(how, str) or len(how) > 200:
            return None
        if data.get("digest") != _digest(data["c0"], data["roots"], how):  # a file cut short or edited
            return None
        c0 = _complex([data["c0"]], n)
        X = _complex(data["roots"], width)
        if c0 is None or X is None or not 1 <= len(X) <= 4096:
            return None
        return c0[0], X, how
    except (OSError, ValueError, TypeError, KeyError, IndexError):
        return None


def _digest(c0, roots, how) -> str:
    """SHA-256 of the stored numbers and the claim: a set cut short or edited is not read."""
    return hashlib.sha256(json.dumps([c0, roots, how]).encode()).hexdigest()


def _may_write() -> bool:
    if resource is None:
        return False
    try:
        soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
        return soft == resource.RLIM_INFINITY
    except (OSError, ValueError, AttributeError):
        return False


def write(name: str, c0, X: np.ndarray, how: str) -> Path | None:
    """Store a generic solution set (atomically); its path, or None when nothing was written."""
    where = folder()
    if where is None or not _may_write():
        return None
    pair = lambda a: [[float(v.real), float(v.imag)] for v in a]  # noqa: E731
    c0, roots = pair(np.ravel(c0)), [pair(x) for x in np.asarray(X)]
    text = json.dumps({"version": VERSION, "key": name, "certified_by": how, "c0": c0, "roots": roots,
                       "digest": _digest(c0, roots, how)})
    try:
        where.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=where, prefix=".tmp-", suffix=".json")
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                f.write(text)
            os.replace(tmp, where / f"{name}.json")
        except BaseException:  # any failure or Ctrl-C: the temporary file goes, and the error goes on (raise)
            try:
                os.unlink(tmp)
            except OSError:
                pass
            raise
        return where / f"{name}.json"
    except (OSError, ValueError):
        return None
