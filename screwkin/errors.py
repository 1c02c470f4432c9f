"""Exceptions raised by screwkin, and the helpers that keep their messages one short line.

Every error a user can cause derives from :class:`ScrewkinError` and carries the
facts needed to fix it.  The command line prints ``str(error)`` as one line.

Text taken from a file (names, attribute values) goes into a message only through
:func:`quote` or :func:`shorten`: at most :data:`QUOTE_LIMIT` characters of it,
with control characters (newlines, escapes, bidirectional overrides) written as
Python escapes, so that a hostile file can neither flood the terminal nor
break the one-line contract.
"""

from __future__ import annotations

import reprlib
from typing import TYPE_CHECKING
if TYPE_CHECKING:
    from pathlib import Path

__all__ = [
    "ScrewkinError",
    "UsageError",
    "MechanismFileError",
    "AssemblyError",
    "OutputError",
    "QUOTE_LIMIT",
    "MESSAGE_LIMIT",
    "quote",
    "shorten",
    "one_line",
]

#: Most characters of a file's text quoted in a message (then "...").
QUOTE_LIMIT = 80
#: Most characters of one error message after the file's path (the first problem
#: is kept whole up to this length; the list of further problems is cut to fit).
MESSAGE_LIMIT = 300

_repr = reprlib.Repr()
_repr.maxlevel, _repr.maxlist, _repr.maxtuple, _repr.maxdict = 3, 6, 6, 6
_repr.maxstring, _repr.maxother = QUOTE_LIMIT, QUOTE_LIMIT


def _escape(text: str) -> str:
    """Control, format and separator characters as Python escapes (``\\n``, ``\\x1b``, ``\\u202e``)."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def shorten(value: str, limit: int = QUOTE_LIMIT) -> str:
    """``value`` (a string, or any object by its bounded repr) as at most ``limit``
    characters plus "...", control characters escaped (the limit counts the escapes:
    ``\U0001d246`` is ten characters); never contains a newline."""
    text = value if isinstance(value, str) else _repr.repr(value)
    out, used = [], 0
    for c in text[: limit + 1]:
        e = c if c.isprintable() else repr(c)[1:-1]
        if used + len(e) > limit:
            return "".join(out) + "..."
        out.append(e)
        used += len(e)
    return "".join(out) + ("..." if len(text) > limit + 1 else "")


def quote(value, limit: int = QUOTE_LIMIT) -> str:
    """``'value'`` for a message: :func:`shorten` between single quotes; a value that is
    not a string (a YAML list, None) as its bounded repr, without quotes."""
    return f"'{shorten(value, limit)}'" if isinstance(value, str) else shorten(value, limit)


def one_line(text: str, limit: int) -> str:
    """A whole message made safe for one terminal line (escaped, at most ``limit`` characters)."""
    text = _escape(str(text))
    return text if len(text) <= limit else text[: max(limit - 3, 0)] + "..."


class ScrewkinError(Exception):
    """Base class of every error screwkin raises on purpose."""

    exit_code = 1


class UsageError(ScrewkinError):
    """The request is malformed (bad option value, unknown joint or link name)."""

    exit_code = 2


class MechanismFileError(ScrewkinError):
    """A mechanism file is missing, malformed, or describes something invalid.

    ``problems`` holds every problem found in the file (validation collects them
    all before failing); the message shows the first and counts the rest, within
    :data:`MESSAGE_LIMIT` characters after the path.
    """

    def __init__(self, path: str, problems: str) -> None:
        if isinstance(problems, str):
            problems = [problems]
        self.path = str(path)
        self.problems = list(problems)
        more = len(self.problems) - 1
        first = one_line(self.problems[0], MESSAGE_LIMIT)
        text = first
        if more > 0:
            tail = f" (and {more} more problem{'s' if more > 1 else ''}: " + "; ".join(
                _escape(str(p)) for p in self.problems[1:4]) + (", ...)" if more > 3 else ")")
            room = MESSAGE_LIMIT - len(first)
            if len(tail) > room:
                head = f" (and {more} more problem{'s' if more > 1 else ''}"
                tail = one_line(tail[:-1], max(room - 1, len(head) + 4)) + ")" if room > len(head) + 5 else head + ")"
            text += tail
        super().__init__(f"{_escape(self.path)}: {text}")


class AssemblyError(MechanismFileError):
    """The loop-closure equations could not be solved.

    ``residual`` is the smallest closure residual norm reached (m and rad mixed,
    as the constraint rows are), after ``iterations`` Newton iterations (of the
    best start), from ``starts`` starting configurations when a search was made;
    ``proved``: no search was made, the lengths prove the loop cannot close and
    ``residual`` is how far apart its joint stays at least [m].
    """

    def __init__(self, path: str, residual: float, iterations: int, detail: str = "", starts: int | None = None,
                 reason: str | None = None, proved: bool = False, message: str | None = None) -> None:
        """``message``: the whole message where no search was made at all (a closed form's answer)."""
        self.residual = float(residual)
        self.iterations = int(iterations)
        self.starts = starts
        self.reason = reason
        how = (f"from {starts} starting configurations" if starts and starts > 1
               else f"after {self.iterations} iterations")
        if proved:  # the lengths alone prove it: ``residual`` is the least the loop can stay open, no search made
            msg = (f"cannot assemble the mechanism: {reason}; the loop-closure residual cannot get below "
                   f"{self.residual:.3g} (proved from the lengths: no assembly search)")
        else:
            msg = (f"cannot assemble the mechanism: {reason}; the loop-closure residual got down to "
                   f"{self.residual:.3g} {how}" if reason else
                   f"cannot assemble the mechanism: the loop-closure residual got down to {self.residual:.3g} {how}")
        if detail:
            msg += f" ({detail})"
        super().__init__(path, message or msg)


class OutputError(ScrewkinError):
    """An output file could not be written after the work was done (a full disk, a file-size limit,
    a folder where no file can be made): ``path``, the operating system's ``reason``, and what
    became of a partial file (``partial``: "removed", or None when nothing was left).  Exit 1:
    the command line was right, the place it named could not take the file."""

    def __init__(self, path: str | Path, reason: str, partial: str | None = None) -> None:
        self.path, self.reason, self.partial = str(path), str(reason), partial
        tail = f" (the partial file was {partial})" if partial else ""
        super().__init__(f"cannot write {quote(self.path, 200)}: {reason}{tail}")
