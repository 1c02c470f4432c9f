"""What every command line is checked for before any work starts.

* **Counts are bounded.** Every count a person types (steps, starts, samples,
  threads, iterations) has a documented range: ``count(lo, hi)`` is its argparse
  type, so ``--steps 100000000`` is a usage error naming the bound, not an hour
  of work.
* **Empty is not the default.** ``--length=`` or ``--resolution ''`` are usage
  errors (argparse would pass the empty string on, and most commands read it
  as "not given").
* **Outputs can be written.** Every file a command will write (``--csv``,
  ``--png``, ``--svg``, ``--plot``, ``--html``, ``--md``, ``-o`` ...) is checked
  before the work starts: its folder exists and is writable (a new file is
  tried there), the path is not a folder, and it is neither a file the command
  reads nor another output's file.
"""

from __future__ import annotations

import argparse
import os
import re
from importlib import metadata

from ..errors import UsageError, quote
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Callable

__all__ = ["screwkin_version", "check_writable", "check_folder_writable", "count", "whole", "seconds", "SECONDS", "check_parsed", "OUTPUT_DESTS", "check_outputs", "check_not_read", "check_picture", "PICTURES", "BOUNDS"]


def screwkin_version() -> str:
    """The version of screwkin installed (the package's metadata, as pip shows it)."""
    try:
        return metadata.version("screwkin")
    except metadata.PackageNotFoundError:  # pragma: no cover - run from a source tree never installed
        return "unknown (not installed)"


#: The bounds of the counts people type, (smallest, largest), by what they count.
BOUNDS = {
    "steps": (1, 100_000),            # sweep --steps: about 30 s of tracking at the largest (text, JSON, plots)
    # the three below: what finishes in about a minute on the 2 shared cores of the development machine
    # (measured 2026-11-27, CPU time; wall time about twice under its usual load); long work shows its
    # progress on a terminal (present/progress.py)
    "streamed_steps": (1, 2_000_000),  # sweep --steps writing --csv/--parquet alone, in chunks: a million in
                                       # 6.4 s (a four-bar in closed form), 11.3 s (MJCF four-bar, batched)
    "chunk": (1, 1_000_000),          # sweep --chunk: steps computed and written at a time
    "dynamics_steps": (1, 10_000),    # dynamics --steps: 0.85 ms a step on a four-bar, 1.9 on a six-bar
    "figure_steps": (2, 20_000),      # draw --singular / report --steps: a search for singular configurations
    "animation_steps": (1, 500),      # draw --animate --steps: frames drawn (steps + 1), 63 ms each
    "starts": (0, 1_000),             # solve / ik / synthesize --starts: random starting configurations
    "iterations": (0, 1_000),         # solve / report --iterations: Newton iterations shown
    "samples": (1, 10_000_000),       # scan --samples (100,000 take about 0.3 s)
    "threads": (1, 256),              # scan --threads
    "grid": (2, 2_000),               # map / view --sweep N: values along one input
    "local_samples": (1, 100_000),    # mobility --local-samples: tangent directions continued at a singular point
    "grid_total": (4, 100_000),       # map: both inputs together (about 25 s on the five-bar)
    "facets": (3, 1_000),             # grasp --facets: edges of a friction cone's pyramid
    "candidates": (1, 10_000),        # synthesize --candidates
    "links": (2, 12),                 # synthesize chains --links
    "dof": (0, 10),                   # synthesize chains --dof
    "seed": (0, 2**32 - 1),           # random seeds (numpy's range)
    "mode": (1, 1_000),               # --mode K: an assembly mode
    "workers": (0, 64),               # study / synthesize --workers: processes of the local cluster
    "best": (1, 50),                  # synthesize --best: designs listed
    "generations": (1, 10_000),       # synthesize --generations: of each differential-evolution run
    "workspace_samples": (1, 2_000_000),  # workspace --method sampling --samples: a 6R arm's 5,000,000 took 64 s
                                          # (CPU) and 870 MB, 2,000,000 about 26 s
}
#: The bounds of the durations people type [s], (smallest, largest).
SECONDS = {"timeout": (0.1, 3600.0), "design_timeout": (0.1, 86400.0)}


def seconds(what: str) -> Callable:
    """argparse type of a duration in seconds bounded by ``SECONDS[what]`` (a finite number)."""
    lo, hi = SECONDS[what]

    def parse(text: str) -> float:
        try:
            x = float(text.strip())
        except (ValueError, AttributeError):
            raise argparse.ArgumentTypeError(f"expected seconds, got {quote(text, 40)}") from None
        if not lo <= x <= hi:  # nan fails both comparisons
            raise argparse.ArgumentTypeError(f"must be between {lo:g} and {hi:g} s, got {quote(text, 40)}")
        return x

    parse.__name__ = f"seconds ({lo:g} to {hi:g})"
    return parse


_WHOLE = re.compile(r"[+-]?[0-9]+")


def whole(text: str) -> int:
    """A whole number as a person types it: ASCII digits with an optional sign, nothing else.  Python's int()
    also reads ``2_0`` as 20 and other scripts' digits (``٣``): a typo taken for a count.  The one parse of every
    count on the command line (count() below, --links, --port, --facets, --pick, --points)."""
    if not isinstance(text, str) or not _WHOLE.fullmatch(text.strip()):
        raise argparse.ArgumentTypeError(f"expected a whole number, got {quote(str(text), 40)}")
    return int(text.strip())


def count(what: str) -> Callable:
    """argparse type of a count bounded by ``BOUNDS[what]`` (whole numbers only: :func:`whole`)."""
    lo, hi = BOUNDS[what]

    def parse(text: str) -> int:
        n = whole(text)
        if not lo <= n <= hi:
            raise argparse.ArgumentTypeError(f"must be between {lo:,} and {hi:,}, got {n:,}")
        return n

    parse.__name__ = f"count ({lo:,} to {hi:,})"  # argparse names the type in its messages
    return parse


#: Destinations of options that name a file a command writes (or a prefix of such files).
OUTPUT_DESTS = ("csv", "parquet", "plot", "png", "svg", "html", "md", "cloud_png", "table", "out", "animate", "mjcf", "urdf",
                "draw")


#: Options whose file is a picture: dest -> the suffixes it takes, or MATPLOTLIB (a figure matplotlib writes in the
#: format its suffix names, PNG without one); (command, dest) where a command's option takes others.  A file that
#: is not a picture (study --plot is a prefix) is not listed.
MATPLOTLIB = "matplotlib"
PICTURES = {"plot": MATPLOTLIB, "png": MATPLOTLIB, "svg": (".svg",), "cloud_png": (".png",), "draw": (".png", ".svg"),
            "animate": (".gif", ".mp4"), ("draw", "png"): (".png",), ("view", "png"): (".png",), ("study", "plot"): None}

#: Formats matplotlib lists but cannot write here without more: PGF needs a TeX system (xelatex).
_NOT_MATPLOTLIB = {".pgf"}


def _matplotlib_formats() -> tuple:
    """The suffixes matplotlib writes (its own list, less _NOT_MATPLOTLIB); () without matplotlib (the
    command says it needs it)."""
    try:
        from matplotlib.backend_bases import FigureCanvasBase
    except ImportError:
        return ()
    return tuple(sorted("." + k for k in FigureCanvasBase.get_supported_filetypes() if "." + k not in _NOT_MATPLOTLIB))


def check_picture(path: str, option: str, formats: str | tuple) -> None:
    """Refuse a picture file whose suffix names a format its writer does not write (sweep --plot o.xml),
    naming the formats it does.  A device or a pipe (/dev/stdout) takes the writer's first format;
    a matplotlib figure without a suffix is a PNG."""
    if os.path.exists(path) and not os.path.isfile(path):
        return
    base = os.path.basename(path)
    ext = os.path.splitext(base)[1].lower()
    if formats == MATPLOTLIB:
        formats = _matplotlib_formats()
        if not formats or not ext:
            return
    if ext not in formats or len(base) <= len(ext):
        names = " or ".join(formats) if len(formats) < 3 else ", ".join(formats[:-1]) + " or " + formats[-1]
        raise UsageError(f"{option} expects a file name ending in {names}"
                         f"{' (a picture format matplotlib writes)' if len(formats) > 2 else ''}, got {quote(path, 200)}")


def _option_name(action) -> str:
    longs = [s for s in action.option_strings if s.startswith("--")]
    return (longs or action.option_strings or [action.dest])[0]


def check_writable(path: str, option: str) -> None:
    """Refuse an output file that cannot be written: a folder, in a missing folder, without permission."""
    where = f"{option} {quote(path, 200)}"
    if os.path.isdir(path):
        raise UsageError(f"{where}: cannot write, it is a folder, not a file")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise UsageError(f"{where}: cannot write, the folder {quote(folder, 200)} does not exist")
    if not os.access(folder, os.W_OK) or (os.path.exists(path) and not os.access(path, os.W_OK)):
        raise UsageError(f"{where}: cannot write, permission denied")
    if not os.path.lexists(path):  # a folder may exist and take no file (/proc, a read-only mount): try one
        try:
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        except FileExistsError:  # made meanwhile: it is checked when written
            return
        except OSError as exc:
            why = os.strerror(exc.errno) if exc.errno else str(exc)
            raise UsageError(f"{where}: cannot write, no file can be made in {quote(folder, 200)} ({why})") from None
        os.close(fd)
        os.remove(path)


def check_folder_writable(path: str, option: str) -> None:
    """Refuse an output folder that cannot be made or written: a file, in a missing folder, without permission."""
    where = f"{option} {quote(path, 200)}"
    if os.path.exists(path) and not os.path.isdir(path):
        raise UsageError(f"{where}: cannot write, it is a file; this output is a folder")
    parent = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(path) and not os.path.isdir(parent):
        raise UsageError(f"{where}: cannot write, the folder {quote(parent, 200)} does not exist")
    if not os.access(path if os.path.isdir(path) else parent, os.W_OK):
        raise UsageError(f"{where}: cannot write, permission denied")
    if not os.path.lexists(path):  # a folder may exist and take no new folder (/proc): try one
        try:
            os.mkdir(path)
        except FileExistsError:
            return
        except OSError as exc:
            why = os.strerror(exc.errno) if exc.errno else str(exc)
            raise UsageError(f"{where}: cannot write, no folder can be made in {quote(parent, 200)} ({why})") from None
        os.rmdir(path)


#: Destinations of the files a command reads (the mechanism, its sidecar, a study's or a grasp's spec).
INPUT_DESTS = ("file", "yaml", "spec")


def _same_file(a: str, b: str) -> bool:
    """Whether paths ``a`` and ``b`` name one file: the same path once links and ``..`` are resolved, or
    one file under two names (hard links)."""
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist yet: different files
        return False


def _overwritten(args: argparse.Namespace, outputs: list) -> None:
    """Refuse an output that would overwrite a file the command reads (the mechanism file, its sidecar
    given or found beside it, a spec) or another output of the same command line.  A device or a pipe
    (/dev/null, /dev/stdout) is written, not overwritten: it may take several outputs."""
    inputs = [(f"the file read ({quote(getattr(args, d), 200)})", getattr(args, d)) for d in INPUT_DESTS
              if isinstance(getattr(args, d, None), str) and getattr(args, d)]
    mechanism = getattr(args, "file", None)
    if isinstance(mechanism, str) and mechanism and getattr(args, "yaml", None) is None:
        for suffix in (".yaml", ".yml"):  # the sidecar read beside the file (model/loader._find_sidecar)
            side = os.path.splitext(mechanism)[0] + suffix
            if os.path.isfile(side):
                inputs.append((f"the sidecar read beside it ({quote(side, 200)})", side))
    seen = []
    for option, path in outputs:
        if os.path.exists(path) and not os.path.isfile(path):
            continue
        for what, other in inputs:
            if _same_file(path, other):
                raise UsageError(f"{option} {quote(path, 200)}: is {what}: it would be overwritten; write elsewhere")
        for first, other in seen:
            if _same_file(path, other):
                raise UsageError(f"{option} {quote(path, 200)}: the same file as {first} {quote(other, 200)}: "
                                 "give each output a file of its own")
        seen.append((option, path))


def check_outputs(parser, args: argparse.Namespace) -> None:
    """Refuse, before any work, an output file whose folder is missing or not writable, that is a folder,
    that is a file the command reads, or that another output of the command line names too."""
    outputs, pictures = [], []
    for action in parser._actions:
        if action.dest in OUTPUT_DESTS and action.option_strings and isinstance(getattr(args, action.dest), str):
            if getattr(args, "kind", None) == "chains" and action.dest == "out":  # synthesize chains -o: a folder
                check_folder_writable(getattr(args, action.dest), _option_name(action))
                continue
            check_writable(getattr(args, action.dest), _option_name(action))
            outputs.append((_option_name(action), getattr(args, action.dest)))
            pictures.append((action, getattr(args, action.dest)))
    _overwritten(args, outputs)
    words = parser.prog.split()
    for action, path in pictures:  # a file name no picture format has (sweep --plot o.xml)
        picture = next((PICTURES[w, action.dest] for w in words if (w, action.dest) in PICTURES),
                       PICTURES.get(action.dest))
        if picture is not None:
            check_picture(path, _option_name(action), picture)
    if outputs:  # (the (sub)parser that has them: kept for check_not_read, once the model is read)
        args.output_files = outputs


def check_not_read(args: argparse.Namespace, files: list) -> None:
    """Refuse, once the model is read and before the work, an output that is one of ``files``: every file
    the model was read from (MechanismSpec.files_read: its MJCF or xacro includes, its meshes, its sidecar),
    which only reading the model finds."""
    for option, path in getattr(args, "output_files", ()):
        if os.path.exists(path) and not os.path.isfile(path):  # a device or a pipe: written, not overwritten
            continue
        for other in files:
            if _same_file(path, other):
                raise UsageError(f"{option} {quote(path, 200)}: is {quote(str(other), 200)}, a file the model was read "
                                 "from: it would be overwritten; write elsewhere")


def check_parsed(parser, args: argparse.Namespace) -> None:
    """Refuse empty option values, then unwritable outputs (see the module's docstring)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            continue
        value = getattr(args, action.dest, None)
        values = value if isinstance(value, list) else [value]
        for v in values:
            if isinstance(v, str) and not v.strip():
                name = _option_name(action) if action.option_strings else action.dest.upper()
                raise UsageError(f"{name}: empty value (leave the option out for its default)")
    check_outputs(parser, args)
