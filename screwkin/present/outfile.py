"""Every file a command writes is written here: one way to write it, one way to fail.

The command line's outputs are checked before the work starts (commands/_options.py); what can
still fail is the writing itself, once the work is done: a full disk (``/dev/full``), a file-size
limit (``ulimit -f``: EFBIG), a folder that exists but takes no new file (``/proc``).  Each is
:class:`~screwkin.errors.OutputError` naming the path and the operating system's reason, exit 1,
never a traceback.  A regular file left partly written (a streamed sweep stopped by a full disk)
is removed, and the message says so; devices and pipes (``/dev/null``, ``/dev/stdout``) are
written as they are and never removed.

- :func:`write_output` writes a whole text or blob;
- :class:`OutputFile` is a file written piece by piece (a sweep streamed in chunks);
- :func:`write_figure` renders a matplotlib figure in memory, then writes it;
- :func:`output_failed` is what each of them raises, for writers of their own (pyarrow's), and
  :func:`remove_partial` what they remove.
"""

from __future__ import annotations

import io
import os

from ..errors import OutputError

__all__ = ["write_output", "OutputFile", "write_figure", "output_failed", "remove_partial", "os_reason"]


def os_reason(exc: BaseException) -> str:
    """The operating system's words for why ``exc`` happened (strerror of its errno)."""
    errno = getattr(exc, "errno", None)
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


def output_failed(path, exc: BaseException) -> OutputError:
    """The error of a write to ``path`` that failed with ``exc``, the partial file removed (said)."""
    return OutputError(path, os_reason(exc), remove_partial(str(path)))


class OutputFile:
    """A file written piece by piece: ``write(data)`` and ``close()``, as a context manager.  Opening,
    writing or closing it fails with OutputError (the partial file removed); leaving the ``with``
    block on any other exception (the work failed, or was interrupted) removes the partial file too,
    so that a file is never left half written as if whole."""

    def __init__(self, path, mode: str = "w"):
        self.path = str(path)
        try:
            self._f = open(path, mode, encoding=None if "b" in mode else "utf-8")
        except OSError as exc:
            raise OutputError(path, os_reason(exc)) from None

    def write(self, data) -> None:
        if self._f is None:
            raise ValueError(f"{self.path} is closed")
        try:
            self._f.write(data)
        except OSError as exc:
            self._drop()
            raise output_failed(self.path, exc) from None

    def close(self) -> None:
        f, self._f = self._f, None
        if f is None:
            return
        try:
            f.close()  # the last buffered bytes: a full disk often shows only here
        except OSError as exc:
            raise output_failed(self.path, exc) from None

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
            remove_partial(self.path)

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if kind is None:
            self.close()
        else:
            self.discard()


def write_output(path, data) -> None:
    """Write ``data`` (str, as UTF-8, or bytes) to ``path`` whole (OutputError when it cannot be)."""
    with OutputFile(path, "wb" if isinstance(data, (bytes, bytearray, memoryview)) else "w") as f:
        f.write(data)


def write_figure(fig, path, **savefig) -> None:
    """A matplotlib figure into ``path``, in the format of its suffix (PNG without one), rendered in
    memory first: matplotlib itself does not report every failed write (``/dev/full`` passed)."""
    fmt = os.path.splitext(str(path))[1][1:].lower() or "png"
    buf = io.BytesIO()
    fig.savefig(buf, format=fmt, **savefig)
    write_output(path, buf.getvalue())
