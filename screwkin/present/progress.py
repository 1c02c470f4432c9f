"""Progress of long work on a terminal: one line on stderr, redrawn every few seconds.

Only a terminal sees it: when stderr is a file or a pipe (a log, a test, CI) nothing is written
but what the caller prints when the work is done, so that captured output stays the answer
alone.  The analyses report their progress through a callable ``progress(done, total)`` (they
never print: tests/architecture/test_layers.py); an instance of :class:`Progress` is that callable.
"""

from __future__ import annotations

import sys
import time
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any

__all__ = ["Progress", "EVERY"]

#: Seconds between two redraws of the line (the first after as long: short work shows nothing).
EVERY = 2.0


class Progress:
    """``progress(done, total[, failed])`` of work counted in ``unit``, drawn as
    ``LABEL [####....] done/total UNIT, elapsed, left`` on ``stream`` (default stderr) when it is a
    terminal, at most every ``every`` seconds (0: at every call); ``finish(line)`` clears it and
    prints the line that stays (always, terminal or not), ``clear()`` only clears it (as leaving a
    ``with`` block does, however the work ended)."""

    def __init__(self, stream=None, width: int = 30, label: str = "study", unit: str = "designs",
                 every: float = 0.0) -> None:
        self.stream = stream or sys.stderr
        try:
            self.tty = self.stream.isatty()
        except (AttributeError, ValueError):
            self.tty = False
        self.width, self.label, self.unit, self.every = width, label, unit, every
        self.t0 = time.perf_counter()
        self.last = self.t0
        self.shown = False

    def __call__(self, done: int, total: int, failed: int | None = None) -> None:
        if not self.tty:
            return
        now = time.perf_counter()
        if self.every and now - self.last < self.every:
            return
        self.last = now
        filled = int(self.width * min(done, total) / max(total, 1))
        elapsed = now - self.t0
        eta = elapsed / done * (total - done) if done else 0.0
        bad = f", {failed} failed" if failed is not None else ""
        self.stream.write(f"\r{self.label} [{'#' * filled}{'.' * (self.width - filled)}] {done:,}/{total:,} "
                          f"{self.unit}{bad}, {elapsed:.0f} s, {eta:.0f} s left ")
        self.stream.flush()
        self.shown = True

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: Any) -> None:
        """Leaving a ``with`` block, on success or failure (an error, Ctrl-C), removes the line drawn:
        what is printed next (the result, or the one-line error) starts on a clean line."""
        self.clear()

    def clear(self) -> None:
        """Remove the line drawn (if any), so that what follows starts on a clean line."""
        if self.shown:
            self.stream.write("\r\x1b[K")
            self.stream.flush()
            self.shown = False

    def finish(self, line: str) -> None:
        self.clear()
        self.stream.write(line + "\n")
        self.stream.flush()
