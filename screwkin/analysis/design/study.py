"""Design-space studies: the designs of a family (a xacro file over its arguments) and the
metrics of each (running many of them at once, on Dask, is screwkin.parallel.study).

The designs are the grid of the parameters' values (first parameter slowest), or
``designs`` random or Latin-hypercube draws (``seed``).  Each design is loaded (the xacro
expanded with its values, in SI), assembled, and its metrics computed (:data:`METRICS`);
a design that fails -- the file refuses the values, the loops do not close, it is not a
four-bar for ``grashof`` -- is a row whose ``error`` says why, with its metric columns
empty: a study never loses a run to one design.

A chunk of designs is computed by :func:`run_chunk`, each design from its values alone (fresh
mechanism, seeded searches), so the table is the same whatever runs the chunks.

Values are SI: lengths in m, angles in rad (the transmission angles too; the CSV that
people read gives degrees: screwkin.present.study).
"""

from __future__ import annotations

import contextlib
import itertools
import math
import signal
import threading
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ...errors import ScrewkinError, UsageError, one_line, quote
from ...files.study import StudySpec, read_mechanism_text
from ...model.loader import load
from ..mobility import analyze_mobility
from ..motion.planar import identify
from ..position.modes import choose_mode
from ..position.position import PositionSolver
from .workspace import DEFAULT_THRESHOLD, workspace

if TYPE_CHECKING:
    from ...model.mechanism import Mechanism
    from collections.abc import Sequence

__all__ = [
    "COLUMNS",
    "MODE_METRICS",
    "METRICS",
    "DesignTimeout",
    "StudyResult",
    "designs",
    "pareto_front",
    "evaluate_design",
    "run_chunk",
    "study_task",
    "check_pareto",
    "failed_row",
    "failure_reason",
    "StudyDesign",
    "StudyTask",
    "grashof_short",
    "metric_columns",
    "DEFAULT_REQUIRE",
    "REQUIREMENTS_COLUMN",
    "Requirement",
    "requirements",
    "apply_requirements",
]

#: The columns each metric fills (keys of the rows, SI values).
COLUMNS = {
    "mobility": ("mobility", "mobility_count", "motion_space", "overconstraint", "idle_dofs", "effective_mobility",
                 "output_motion"),
    "grashof": ("linkage", "grashof", "grashof_margin"),
    "transmission_angle": ("transmission_angle_min", "transmission_angle_max", "transmission_restarts",
                           "transmission_deviation", "input_turns", "dead_points"),
    "workspace_volume": ("workspace_dimension", "workspace_volume", "workspace_truncated", "mode", "modes"),
    "singularity_free_volume": ("workspace_dimension", "singularity_free_volume", "workspace_truncated", "mode",
                                "modes"),
    "conditioning": ("conditioning_min", "conditioning_mean", "mode", "modes"),
}
#: The metrics that follow one assembly mode (their rows say which: ``mode`` K of ``modes`` N).  Not the
#: transmission angle: a four-bar's mu comes from the law of cosines in the diagonal from the crank tip to the
#: output pivot, which depends on the input alone, so it is the same on both circuits (a slider-crank's
#: likewise, mirrored), and its extremes are located from the lengths (analysis.motion.transmission).
MODE_METRICS = ("workspace_volume", "singularity_free_volume", "conditioning")

#: Short Grashof classes, from the start of analysis.motion.planar's class sentences.
_GRASHOF = (("change point", "change-point"), ("non-Grashof", "non-Grashof"),
            ("Grashof crank-rocker", "crank-rocker"), ("Grashof double crank", "double-crank"),
            ("Grashof double rocker", "double-rocker"), ("Grashof rocker-crank", "rocker-crank"),
            ("crank turns fully", "crank-turns"), ("crank cannot turn fully", "crank-rocks"))


def grashof_short(sentence: str) -> str | None:
    """The short Grashof class of a row (``crank-rocker``) of analysis.motion.planar's class sentence (None: a
    sentence this table does not know)."""
    return next((s for prefix, s in _GRASHOF if sentence.startswith(prefix)), None)

class DesignTimeout(ScrewkinError):
    """A design ran past the study's timeout (its row is failed, its metrics empty)."""


class _Clock:
    """The deadline of one design, checked between its steps (loading, assembly, each metric)."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        self.end = time.perf_counter() + seconds

    def check(self) -> None:
        if time.perf_counter() > self.end:
            raise DesignTimeout(f"timed out: the design took more than {self.seconds:g} s (the study's timeout "
                                "per design)")


@contextlib.contextmanager
def _alarm(seconds: float):
    """In the main thread (a study in this process): SIGALRM raises DesignTimeout after ``seconds``
    even inside a step that never reaches a check (Python code between two C calls).  Elsewhere
    (a Dask worker's thread) nothing: the checks and the client's stall watch bound the design."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "setitimer"):
        yield
        return

    def fire(signum: int, frame: object):
        raise DesignTimeout(f"timed out: the design took more than {seconds:g} s (the study's timeout per design)")

    previous = signal.signal(signal.SIGALRM, fire)
    t0 = time.perf_counter()
    old_delay, old_interval = signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if old_delay > 0:  # someone else's timer (pytest-timeout ...): put it back with what is left of it
            signal.setitimer(signal.ITIMER_REAL, max(old_delay - (time.perf_counter() - t0), 1e-3), old_interval)


# ------------------------------------------------------------------ the designs
def _exact_steps(low: float, high: float, n: int) -> tuple:
    """n values from low to high, both ends exact (low (1 - t) + high t: 0.02..0.06 in 3 gives 0.04,
    where numpy's linspace gives 0.039999999999999994)."""
    if n == 1:
        return (float(low),)
    return tuple(float(low * (1 - k / (n - 1)) + high * (k / (n - 1))) for k in range(n))


def designs(spec: StudySpec) -> list:
    """The parameter values of every design (tuples in the order of ``spec.parameters``, SI)."""
    params = spec.parameters
    if spec.sampling == "grid":
        axes = [p.values if p.values is not None else _exact_steps(p.low, p.high, p.samples) for p in params]
        return [tuple(float(v) for v in combo) for combo in itertools.product(*axes)]
    n = spec.designs
    rng = np.random.default_rng(spec.seed)
    columns = []
    for p in params:
        if spec.sampling == "random":
            u = rng.uniform(size=n)
        else:  # Latin hypercube: one draw in each of n equal strata, strata in random order
            u = (rng.permutation(n) + rng.uniform(size=n)) / n
        if p.values is not None:
            k = np.minimum((u * len(p.values)).astype(int), len(p.values) - 1)
            columns.append([float(p.values[i]) for i in k])
        else:
            columns.append([float(p.low + x * (p.high - p.low)) for x in u])
    return list(zip(*columns)) if columns else []


# ------------------------------------------------------------------ one design
@dataclass(frozen=True)
class StudyTask:
    """What a worker needs for the designs of a study (picklable: sent with every chunk)."""

    file: str
    text: str  # the file's text, read once by the client: every design sees the same file
    args: dict
    parameters: tuple
    metrics: tuple
    input: str | None
    output: str | None
    point: bool
    workspace: dict
    timeout: float = 120.0  # seconds per design
    mode: int | None = None  # the K-th assembly mode (position.modes.choose_mode); None: the first


class StudyDesign:
    """One loaded design and what its metrics share (assembly, linkage, workspace)."""

    def __init__(self, task: StudyTask, mech: Mechanism, clock: _Clock) -> None:
        self.task, self.mech, self.clock = task, mech, clock
        self.q = mech.generic_configurations()[1][0]  # assembled (AssemblyError otherwise)
        clock.check()
        self._linkage = None
        self._workspace = None
        self.mode = None  # (K, N) once the mode is chosen (the metrics that follow one: MODE_METRICS)
        if any(m in MODE_METRICS for m in task.metrics):
            self._choose_mode()
            clock.check()

    def _choose_mode(self) -> None:
        """The assembly mode the design's motion and workspace follow: the task's ``mode`` K (default 1) of the
        inputs (the study's input, else the actuated joints) at their values in the assembled configuration,
        as ``solve`` lists them (the one rule of every command's --mode); ``self.q`` becomes its
        configuration.  Without inputs, the assembled configuration, one mode."""
        mech = self.mech
        inputs = [self.task.input] if self.task.input else [n for n in mech.actuated if mech.coordinate(n).nv == 1]
        if not inputs:
            self.mode = (1, 1)
            return
        values = mech.joint_values(self.q)
        self.q, k, n, _ = choose_mode(PositionSolver(mech, inputs), {j: values[j] for j in inputs}, self.task.mode)
        self.mode = (k, n)

    def mode_columns(self) -> dict:
        return {"mode": self.mode[0], "modes": self.mode[1]}

    @property
    def input(self) -> str:
        if self.task.input:
            self.mech.coordinate(self.task.input)  # a UsageError naming the joints when unknown
            return self.task.input
        if len(self.mech.actuated) != 1:
            raise UsageError(f"the file declares {len(self.mech.actuated)} actuated joints: give input: JOINT "
                             "in the study")
        return self.mech.actuated[0]

    def linkage(self):
        if self._linkage is None:
            info = identify(self.mech, self.mech.topology(self.q), self.q, self.input)
            if info is None:
                raise UsageError(f"not a planar four-bar or slider-crank driven by a revolute joint to the ground "
                                 f"({quote(self.input)}): no Grashof class or transmission angle")
            self._linkage = info
        return self._linkage

    def workspace(self):
        if self._workspace is None:
            ws = self.task.workspace
            # what `screwkin workspace FILE --output LINK [--point] --resolution H [--threshold T] [--length L]`
            # computes for this design (the spec checked that a resolution is given)
            looped = bool(self.mech.cuts or self.mech.extra_rows)  # (a chain without loops has one mode)
            self._workspace = workspace(self.mech, self.task.output, point=ws.get("point", False),
                                        resolution=ws["resolution"],
                                        threshold=ws.get("threshold", DEFAULT_THRESHOLD), length=ws.get("length"),
                                        q_start=self.q if looped else None)
        return self._workspace


def _mobility(d: StudyDesign) -> dict:
    r = analyze_mobility(d.mech, output=d.task.output, point=d.task.point)
    return {"mobility": r.mobility, "mobility_count": r.topology.count_in_motion_space,
            "motion_space": r.motion_space, "overconstraint": r.overconstraint, "idle_dofs": r.idle_dofs,
            "effective_mobility": r.effective_mobility, "output_motion": r.output.label if r.output else None}


def _grashof(d: StudyDesign) -> dict:
    info = d.linkage()
    short = grashof_short(info.grashof)
    if short is None:  # pragma: no cover - a class sentence of planar.py this table does not know
        raise RuntimeError(f"unknown Grashof class {info.grashof!r}")
    L = info.lengths
    if info.kind == "four-bar":
        values = sorted(L.values())
        margin = values[1] + values[2] - values[0] - values[3]  # (p + q) - (s + l)
    else:
        margin = L["rod"] - L["crank"] - L["offset"]
    return {"linkage": info.kind, "grashof": short, "grashof_margin": float(margin)}


def _transmission_angle(d: StudyDesign) -> dict:
    """The transmission angle over the input's whole motion (a full turn, or from limit position to
    limit position on the assembled configuration's circuit), its extremes located in closed form
    from the identified linkage's lengths (analysis.motion.transmission: the extremes of a
    four-bar's mu are at the input angles 0 and 180 deg or at its limit positions), as ``sweep
    --json`` gives them (``linkage.transmission_range``); the largest deviation from 90 deg, whether
    the input turns fully, and the dead points (mu = 0 or 180 deg).  ``transmission_restarts`` is
    0: no continuation is followed (the column of earlier, sampled studies).  No assembly mode is
    chosen: mu is the same on both circuits (MODE_METRICS says why)."""
    r = d.linkage().transmission
    return {"transmission_angle_min": r.low, "transmission_angle_max": r.high, "transmission_restarts": 0,
            "transmission_deviation": r.deviation, "input_turns": r.turns, "dead_points": r.dead_points}


def _workspace_volume(d: StudyDesign) -> dict:
    w = d.workspace()
    # truncated: MAX_POINTS cut the grid (a resolution too fine for the workspace): the volumes are lower bounds
    return {"workspace_dimension": w.dimension, "workspace_volume": w.volume, "workspace_truncated": w.truncated,
            **d.mode_columns()}


def _singularity_free_volume(d: StudyDesign) -> dict:
    w = d.workspace()
    return {"workspace_dimension": w.dimension, "singularity_free_volume": w.free_volume,
            "workspace_truncated": w.truncated, **d.mode_columns()}


def _conditioning(d: StudyDesign) -> dict:
    w = d.workspace()
    return {"conditioning_min": w.conditioning_min, "conditioning_mean": w.conditioning_mean, **d.mode_columns()}


#: metric name -> function of a loaded, assembled design returning its columns (COLUMNS).
METRICS = {"mobility": _mobility, "grashof": _grashof, "transmission_angle": _transmission_angle,
           "workspace_volume": _workspace_volume, "singularity_free_volume": _singularity_free_volume,
           "conditioning": _conditioning}


def metric_columns(metrics: Sequence[str]) -> tuple:
    """The metric columns of a study, in order, each once."""
    out = []
    for m in metrics:
        out += [c for c in COLUMNS[m] if c not in out]
    return tuple(out)


def failure_reason(exc: BaseException, path: str) -> str:
    """The one-line reason of a design's failure, without the file's path every row shares."""
    text = str(exc)
    for prefix in (f"{path}: ", f"{Path(path).name}: "):
        text = text.removeprefix(prefix)
    return one_line(text, 400)


def design_args(task: StudyTask, values: tuple) -> dict:
    """The xacro arguments of one design, as text: what ``--arg NAME=VALUE`` gives the file (a
    parameter's SI value written as repr(float), so the single commands reproduce a row exactly)."""
    args = dict(task.args)
    args.update({n: repr(float(v)) for n, v in zip(task.parameters, values)})
    return args


def evaluate_design(task: StudyTask, index: int, values: tuple, keep: list | None = None) -> dict:
    """The row of one design, from its values alone; ``keep`` (a list): the analysed design is appended
    to it (the family path reads its mechanism)."""
    row = {"design": index, **dict(zip(task.parameters, values))}
    columns = metric_columns(task.metrics)
    row.update(dict.fromkeys(columns))
    row["error"] = None
    clock = _Clock(task.timeout)
    try:
        with _alarm(task.timeout):
            mech = load(task.file, text=task.text, args=design_args(task, values), warn=lambda m: None)
            clock.check()
            d = StudyDesign(task, mech, clock)
            computed = {}
            for m in task.metrics:
                computed.update(METRICS[m](d))
                clock.check()  # a metric that ran past the deadline (one long workspace grid) fails the row
        row.update(computed)  # all metrics or none: a failed design never shows a number
        if keep is not None:
            keep.append(d)
    except ScrewkinError as exc:
        row["error"] = failure_reason(exc, task.file)
    except Exception as exc:  # noqa: BLE001 - a bug (or a missing module on a worker): the row says it, the run goes on
        row["error"] = f"internal error: {type(exc).__name__}: {one_line(str(exc), 300)}"
    return row


def run_chunk(task: StudyTask, chunk: list[tuple[int, tuple]]) -> list:
    """The rows of a chunk of designs [(index, values), ...], each design evaluated alone (what a Dask
    task computes when the family path does not apply: screwkin.analysis.design.family.chunk_rows)."""
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return [evaluate_design(task, i, v) for i, v in chunk]


# ------------------------------------------------------------------ the study
@dataclass(frozen=True)
class StudyResult:
    """The rows of a study, in design order: ``design`` (its index), the parameters' values,
    the metric columns (None when failed or not applicable) and ``error`` (None, or why the
    design failed).  SI values."""

    spec: StudySpec
    parameters: tuple  # parameter names
    columns: tuple  # metric columns
    rows: tuple  # dicts
    seconds: float
    workers: int
    scheduler: str  # "in process", "local cluster" or the scheduler's address
    chunks: int = 0
    extra: dict = field(default_factory=dict)

    @property
    def table(self) -> dict:
        """Column name -> list of values in design order (design, parameters, metrics, error)."""
        names = ("design", *self.parameters, *self.columns, "error")
        return {n: [r[n] for r in self.rows] for n in names}

    @property
    def failed(self) -> tuple:
        return tuple(r for r in self.rows if r["error"] is not None)

    @property
    def succeeded(self) -> tuple:
        return tuple(r for r in self.rows if r["error"] is None)


def study_task(spec: StudySpec) -> StudyTask:
    return StudyTask(str(spec.file), read_mechanism_text(spec), dict(spec.args), tuple(p.name for p in spec.parameters), spec.metrics,
                 spec.input, spec.output, spec.point, dict(spec.workspace), spec.timeout, spec.mode)


def _row_key(name: str, keys: tuple) -> str | None:
    """The row key of a column named as in the rows or as in the table (``..._deg``, ``..._m``)."""
    for cand in (name, name.removesuffix("_deg"), name.removesuffix("_m")):
        if cand in keys:
            return cand
    return None


def pareto_front(result: StudyResult, goals: Sequence[tuple[str, str]] | None=None) -> list:
    """Indices (into result.rows) of the designs on the Pareto front of two columns:
    ``goals`` ((column, "max" | "min"), (column, "max" | "min")), default the spec's
    ``pareto``.  Rows without both values, and rows that do not meet the study's requirements
    (REQUIREMENTS_COLUMN False), are left out; the front is ordered by the first column.  A design is on it when no other is at least as good in both and better in one."""
    goals = goals or result.spec.pareto
    if not goals:
        raise UsageError(f"{result.spec.path}: no pareto columns: give pareto: {{maximize: [...], minimize: [...]}}")
    keys = (*result.parameters, *result.columns)
    cols = []
    for name, goal in goals:
        key = _row_key(name, keys)
        if key is None or goal not in ("max", "min"):
            raise UsageError(f"{result.spec.path}: pareto column {quote(name)} is not a column of this study "
                             f"(columns: {', '.join(keys)})")
        cols.append((key, 1.0 if goal == "max" else -1.0))
    pts = []
    for k, r in enumerate(result.rows):
        vals = [r[c] for c, _ in cols]
        if r.get(REQUIREMENTS_COLUMN) is False:  # cannot do the job: never recommended
            continue
        if r["error"] is None and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                                      for v in vals):
            pts.append((k, vals[0] * cols[0][1], vals[1] * cols[1][1]))
    front = [k for k, a, b in pts
             if not any((a2 >= a and b2 >= b) and (a2 > a or b2 > b) for _, a2, b2 in pts)]
    return sorted(front, key=lambda k: result.rows[k][cols[0][0]])


def check_pareto(spec: StudySpec) -> None:
    if spec.pareto:
        keys = (*(p.name for p in spec.parameters), *metric_columns(spec.metrics))
        for name, _ in spec.pareto:
            if _row_key(name, keys) is None:
                raise UsageError(f"{spec.path}: pareto column {quote(name)} is not a column of this study "
                                 f"(columns: {', '.join(keys)})")


#: What a design must meet when the spec states no ``require``, by metric: a design whose motion has a dead
#: point (the transmission angle reaching 0 or 180 deg: an input that rocks between limit positions, a
#: change point folding flat) cannot be driven through its motion by its input.
DEFAULT_REQUIRE = {"transmission_angle": (("dead_points", "equal", 0, False),)}
#: The column a study with requirements adds: True (met), False (not met), None (a failed design).
REQUIREMENTS_COLUMN = "meets_requirements"


@dataclass(frozen=True)
class Requirement:
    """One requirement on a column: ``kind`` "equal", "min" or "max"; ``value`` SI; ``text`` as stated."""

    column: str
    kind: str
    value: object
    text: str

    def met(self, v: object) -> bool:
        if v is None:
            return False
        if self.kind == "equal":
            return v == self.value
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            return False
        return v >= self.value if self.kind == "min" else v <= self.value


def _spec_text(v: object) -> str:
    """A cell as the spec writes it (YAML's true and false)."""
    return str(v).lower() if isinstance(v, bool) else repr(v) if isinstance(v, str) else f"{v:.6g}" \
        if isinstance(v, float) else str(v)


def requirements(spec: StudySpec) -> tuple:
    """(requirements, default): the spec's ``require`` resolved against the study's columns (a
    column written with ``_deg`` takes a bare number in degrees; values with a unit are SI), or,
    when it states none, DEFAULT_REQUIRE of its metrics (default True).  UsageError for a column the
    study does not have."""
    stated = spec.require
    default = stated is None
    if default:
        stated = tuple(r for m in spec.metrics for r in DEFAULT_REQUIRE.get(m, ()))
    keys = (*(p.name for p in spec.parameters), *metric_columns(spec.metrics))
    out = []
    for name, kind, value, unit_typed in stated:
        key = _row_key(name, keys)
        if key is None:
            raise UsageError(f"{spec.path}: require: {quote(name)} is not a column of this study (columns: "
                             f"{', '.join(keys)})")
        if kind != "equal" and (isinstance(value, bool) or not isinstance(value, (int, float))):
            raise UsageError(f"{spec.path}: require {quote(name)} {kind}: a number, got {quote(value)}")
        si = math.radians(value) if (name.endswith("_deg") and not unit_typed and isinstance(value, (int, float))
                                     and not isinstance(value, bool)) else value
        sign = {"equal": "=", "min": ">=", "max": "<="}[kind]
        out.append(Requirement(key, kind, si, f"{name} {sign} {_spec_text(value)}"))
    return tuple(out), default


def apply_requirements(spec: StudySpec, rows: tuple) -> tuple:
    """(rows with REQUIREMENTS_COLUMN, the column added or None, {design: what it does not meet}).
    Nothing is added when there is no requirement."""
    reqs, _ = requirements(spec)
    if not reqs:
        return tuple(rows), None, {}
    out, unmet = [], {}
    for r in rows:
        r = dict(r)
        if r["error"] is not None:
            r[REQUIREMENTS_COLUMN] = None
        else:
            missed = [f"{q.text} (has {_spec_text(r[q.column])})" for q in reqs if not q.met(r[q.column])]
            r[REQUIREMENTS_COLUMN] = not missed
            if missed:
                unmet[r["design"]] = "; ".join(missed)
        out.append(r)
    return tuple(out), REQUIREMENTS_COLUMN, unmet


def failed_row(task, index: int, values: Sequence[float], reason: str) -> dict:
    row = {"design": index, **dict(zip(task.parameters, values))}
    row.update(dict.fromkeys(metric_columns(task.metrics)))
    row["error"] = reason
    return row
