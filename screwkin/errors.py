"""Exceptions raised by screwkin.

Every error a user can cause derives from :class:`ScrewkinError` and carries the
facts needed to fix it.  The command line prints ``str(error)`` as one line.
"""

from __future__ import annotations

__all__ = [
    "ScrewkinError",
    "UsageError",
    "MechanismFileError",
    "AssemblyError",
]


class ScrewkinError(Exception):
    """Base class of every error screwkin raises on purpose."""

    exit_code = 1


class UsageError(ScrewkinError):
    """The request is malformed (bad option value, unknown joint or link name)."""

    exit_code = 2


class MechanismFileError(ScrewkinError):
    """A mechanism file is missing, malformed, or describes something invalid.

    ``problems`` holds every problem found in the file (validation collects them
    all before failing); the message shows the first and counts the rest.
    """

    def __init__(self, path, problems):
        if isinstance(problems, str):
            problems = [problems]
        self.path = str(path)
        self.problems = list(problems)
        more = len(self.problems) - 1
        text = f"{self.path}: {self.problems[0]}"
        if more > 0:
            text += f" (and {more} more problem{'s' if more > 1 else ''}: " + "; ".join(self.problems[1:4])
            text += ", ...)" if more > 3 else ")"
        super().__init__(text)


class AssemblyError(MechanismFileError):
    """The loop-closure equations could not be solved.

    ``residual`` is the smallest closure residual norm reached (m and rad mixed,
    as the constraint rows are), after ``iterations`` Newton iterations (of the
    best start), from ``starts`` starting configurations when a search was made.
    """

    def __init__(self, path, residual: float, iterations: int, detail: str = "", starts: int | None = None):
        self.residual = float(residual)
        self.iterations = int(iterations)
        self.starts = starts
        how = (f"from {starts} starting configurations" if starts and starts > 1
               else f"after {self.iterations} iterations")
        msg = f"cannot assemble the mechanism: the loop-closure residual got down to {self.residual:.3g} {how}"
        if detail:
            msg += f" ({detail})"
        super().__init__(path, msg)
