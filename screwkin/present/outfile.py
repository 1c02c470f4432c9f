"""Every file a command writes is written here: one way to write it, one way to fail.

The command line's outputs are checked before the work starts (commands/_options.py); what can
still fail is the writing itself, once the work is done: a full disk (``/dev/full``), a file-size
limit (``ulimit -f``: EFBIG), a folder that exists but takes no new file (``/proc``).  Each is
:class:`~screwkin.errors.OutputError` naming the path and the operating system's reason, exit 1,
never a traceback.

A regular file is written under a fresh name beside it, ``PATH.<random>.partial``, and renamed to
``PATH`` once whole: a file under the name asked for is always complete, a write that fails removes
the partial one (and says so) and leaves a file that was there before as it was, and a process
killed on the way (SIGKILL, a CPU limit) leaves only the partial file, named as what it is.  The
partial file is made new (``O_CREAT | O_EXCL | O_NOFOLLOW``): a link or a file planted under a
name it could have (``PATH.partial -> victim``) is neither followed nor reused, and a file of the
user's own named ``PATH.partial`` is left as it is.  Links, devices and pipes
(``/dev/null``, ``/dev/stdout``) are written as they are and never removed; a named pipe nothing
reads is an error, not a wait.

- :func:`write_output` writes a whole text or blob;
- :class:`OutputFile` is a file written piece by piece (a sweep streamed in chunks), also a binary
  file object for writers of their own (pyarrow's);
- :func:`write_figure` renders a matplotlib figure in memory, then writes it;
- :func:`output_failed` is what each of them raises, and :func:`remove_partial` what they remove.
"""

from __future__ import annotations

import errno as errnos
import io
import logging
import os
import stat
import sys

from ..errors import OutputError
from types import TracebackType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathlib import Path
    from typing import Any

__all__ = ["write_output", "OutputFile", "WholeOrNothing", "write_figure", "output_failed", "remove_partial", "os_reason", "PARTIAL", "open_partial"]

#: The suffix of a file being written (renamed to its own name once whole).
PARTIAL = ".partial"

#: The flags of a partial file: made new, never through a link, not inherited by a child process.
_FRESH = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)


def open_partial(path: str) -> tuple:
    """A new file beside ``path`` to write it under: ``(fd, name)``, the name ``PATH.<16 hex>.partial``
    (the file name cut to fit the system's limit of a name), made new with the umask's permissions, as
    ``open(..., "w")`` makes a file.  Never a link or a file that exists: a name taken is tried again."""
    folder, base = os.path.split(os.path.abspath(path))
    for _ in range(100):
        name = os.path.join(folder, f"{base[:200]}.{os.urandom(8).hex()}{PARTIAL}")
        try:
            return os.open(name, _FRESH, 0o666), name
        except FileExistsError:  # taken (one in 2**64): another name
            continue
    raise FileExistsError(errnos.EEXIST, "no fresh name for a partial file", path)


def os_reason(exc: BaseException) -> str:
    """The operating system's words for why ``exc`` happened (strerror of its errno)."""
    errno = getattr(exc, "errno", None)
    if errno == errnos.ENXIO:
        return "a named pipe that nothing reads"
    if errno:
        return os.strerror(errno)
    return getattr(exc, "strerror", None) or str(exc) or type(exc).__name__


def remove_partial(path: str) -> str | None:
    """Remove ``path`` when it is a regular file (not a link, a device or a pipe): "removed"; "left"
    when it could not be; None when there is no such file to remove."""
    try:
        if os.path.islink(path) or not os.path.isfile(path):
            return None
        os.remove(path)
        return "removed"
    except OSError:
        return "left"


def output_failed(path: str, exc: BaseException, partial=None) -> OutputError:
    """The error of a write to ``path`` that failed with ``exc``: the file being written (``partial``,
    default ``path``) removed, which the message says."""
    return OutputError(path, os_reason(exc), remove_partial(str(partial or path)))


class WholeOrNothing:
    """A writer used in a ``with`` block: ``close()`` when the block ends, ``discard()`` (nothing left
    under the name asked for) when it raises."""

    def __enter__(self):
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        if kind is None:
            self.close()
        else:
            self.discard()


class OutputFile(WholeOrNothing):
    """A file written piece by piece: ``write(data)`` and ``close()``, as a context manager (see the
    module: a regular file is written as PATH.<random>.partial and renamed once whole).  Opening, writing or
    closing it fails with OutputError (the partial file removed); leaving the ``with`` block on any
    other exception (the work failed, or was interrupted) removes the partial file too."""

    def __init__(self, path: str, mode: str = "w") -> None:
        self.path = str(path)
        self._partial = None
        encoding = None if "b" in mode else "utf-8"
        try:
            st = os.stat(self.path) if os.path.exists(self.path) else None
            if os.path.islink(self.path) or (st is not None and not stat.S_ISREG(st.st_mode)):
                if st is not None and stat.S_ISFIFO(st.st_mode):  # ENXIO at once when nothing reads it
                    fd = os.open(self.path, os.O_WRONLY | os.O_NONBLOCK)
                    os.set_blocking(fd, True)
                    self._f = os.fdopen(fd, mode, encoding=encoding)
                else:
                    self._f = open(self.path, mode, encoding=encoding)
            else:
                fd, self._partial = open_partial(self.path)
                if st is not None:  # a file replaced keeps its permissions (a private one stays private)
                    os.fchmod(fd, stat.S_IMODE(st.st_mode))
                self._f = os.fdopen(fd, mode, encoding=encoding)
        except OSError as exc:
            raise OutputError(self.path, os_reason(exc)) from None

    def write(self, data: str | bytes) -> int:
        if self._f is None:
            raise ValueError(f"{self.path} is closed")
        try:
            return self._f.write(data)
        except OSError as exc:
            self._drop()
            raise output_failed(self.path, exc, self._partial) from None

    # a writable binary file object for pyarrow's ParquetWriter (PythonFile)
    def flush(self) -> None:
        if self._f is not None:
            try:
                self._f.flush()
            except OSError as exc:
                self._drop()
                raise output_failed(self.path, exc, self._partial) from None

    def tell(self) -> int:
        return self._f.tell()

    @property
    def closed(self) -> bool:
        return self._f is None

    def writable(self) -> bool:
        return True

    def readable(self) -> bool:
        return False

    def seekable(self) -> bool:
        return False

    def close(self) -> None:
        f, self._f = self._f, None
        if f is None:
            return
        try:
            f.close()  # the last buffered bytes: a full disk often shows only here
            if self._partial:
                os.replace(self._partial, self.path)
        except OSError as exc:
            raise output_failed(self.path, exc, self._partial) from None

    def _drop(self) -> None:
        f, self._f = self._f, None
        if f is not None:
            try:
                f.close()
            except OSError:
                pass

    def discard(self) -> None:
        """Stop writing and remove the partial file (a regular file; see remove_partial)."""
        if self._f is not None:
            self._drop()
            if self._partial:
                remove_partial(self._partial)


def write_output(path: str | Path, data: str | bytes) -> None:
    """Write ``data`` (str, as UTF-8, or bytes) to ``path`` whole (OutputError when it cannot be)."""
    with OutputFile(path, "wb" if isinstance(data, (bytes, bytearray, memoryview)) else "w") as f:
        f.write(data)


#: The formats whose files matplotlib writes a ``metadata`` title into (it refuses one for JPEG, GIF, TIFF...).
_METADATA = ("png", "pdf", "svg", "svgz", "ps", "eps")


def write_figure(fig, path: str, **savefig: Any) -> None:
    """A matplotlib figure into ``path``, in the format of its suffix (PNG without one), rendered in
    memory first: matplotlib itself does not report every failed write (``/dev/full`` passed).  A title
    in ``metadata`` is written where the format has room for one, left out elsewhere."""
    fmt = os.path.splitext(str(path))[1][1:].lower() or "png"
    if fmt not in _METADATA:  # matplotlib refuses metadata (a title) for the others: "not supported for format"
        savefig.pop("metadata", None)
    elif fmt == "pdf" and "Description" in savefig.get("metadata", {}):  # PDF's word for it (else a UserWarning)
        savefig["metadata"] = {("Subject" if k == "Description" else k): v for k, v in savefig["metadata"].items()}
    buf = io.BytesIO()
    said = _Said()  # what matplotlib logs as it writes (PostScript: "does not support transparency")
    logger = logging.getLogger("matplotlib")
    logger.addHandler(said)
    propagate, logger.propagate = logger.propagate, False
    try:
        fig.savefig(buf, format=fmt, **savefig)
    finally:
        logger.removeHandler(said)
        logger.propagate = propagate
    write_output(path, buf.getvalue())
    for message in dict.fromkeys(said.messages):  # as every warning is said: one line, naming the file
        print(f"warning: {path}: matplotlib: {message}", file=sys.stderr)


class _Said(logging.Handler):
    """The warnings a logger gives while a figure is written, kept to be said as screwkin says warnings."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.messages = []

    def emit(self, record) -> None:
        self.messages.append(" ".join(record.getMessage().split()))
