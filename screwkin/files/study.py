"""Study specifications (``screwkin study SPEC.yaml``): a family of mechanisms (a xacro
file), the parameters to vary and how, and the metrics to compute for each design.

    file: fourbar.urdf.xacro          # relative to the spec's folder
    parameters:                        # xacro arguments: a range, a list of values, or one value
      crank: {min: 20mm, max: 60mm, samples: 5}
      coupler: {values: [0.1, 0.12, 0.15]}
      ground: 0.1
    sampling: grid                     # grid | random | lhs (random and lhs: designs: N, seed: S)
    metrics: [mobility, grashof, transmission_angle]
    input: crank_joint                 # grashof and transmission_angle (default: the actuated joint)
    output: rocker                     # mobility's output motion, workspace metrics
    require: {dead_points: 0}          # what a design must meet to be on the Pareto front

The spec is untrusted YAML like a sidecar (bounded, no aliases, plain data) and is
checked whole before any design runs: every problem is a :class:`~screwkin.errors.UsageError`
naming the spec (``screwkin study`` exits with 2), so a typo never costs a cluster's time.
The parameters are xacro arguments the file must declare.  Nothing here runs a design.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import MechanismFileError, UsageError, quote
from ..units import Quantity, parse_quantity
from .description import LIMITS
from .xacro import declared_args, normalize_args
from .xmlsafe import load_yaml_text, read_regular_file
from typing import TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Sequence

__all__ = ["DESIGN_TIMEOUT", "MAX_DESIGNS", "METRICS", "SAMPLINGS", "WORKSPACE_METRICS", "Parameter", "StudySpec",
           "read_mechanism_text", "read_study_spec", "study_spec"]

#: The metrics a study may ask for (what each computes: screwkin.analysis.design.study).
METRICS = ("mobility", "grashof", "transmission_angle", "workspace_volume", "singularity_free_volume",
           "conditioning")
SAMPLINGS = ("grid", "random", "lhs")
#: Most designs one study runs.
MAX_DESIGNS = 1_000_000
#: Most values one parameter's list or range gives.
MAX_VALUES = 100_000
#: Seconds one design may take by default (the spec's ``timeout``); a design over it is a failed row.
DESIGN_TIMEOUT = 120.0
#: The metrics computed from screwkin.analysis.design.workspace (they need ``workspace: {resolution: H}``).
WORKSPACE_METRICS = ("workspace_volume", "singularity_free_volume", "conditioning")
_KEYS = ("file", "args", "parameters", "sampling", "designs", "seed", "metrics", "input", "output", "point",
         "workspace", "transmission", "pareto", "require", "chunk", "timeout", "mode")
_WORKSPACE_KEYS = ("point", "resolution", "threshold", "length")
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


@dataclass(frozen=True)
class Parameter:
    """One varied xacro argument: explicit ``values`` (SI), or a range ``low``..``high``
    with ``samples`` values (grid) or drawn (random, lhs)."""

    name: str
    values: tuple | None = None
    low: float | None = None
    high: float | None = None
    samples: int | None = None
    unit: str = ""  # the unit its values were typed in (the first one typed: "mm", "deg"), "" when bare


def _first_unit(quantities: Sequence[Quantity]) -> str:
    """The first unit typed among a parameter's values ("" when every value is a bare number)."""
    return next((q.unit for q in quantities if q.unit), "")


@dataclass(frozen=True)
class StudySpec:
    """A checked study specification; lengths and angles in SI."""

    path: str  # the spec file ("<dict>" for one given in Python)
    file: Path  # the xacro (or plain mechanism) file, resolved
    parameters: tuple  # Parameter
    metrics: tuple  # names from METRICS, in the order given
    sampling: str = "grid"
    designs: int | None = None  # random, lhs: how many
    seed: int = 0
    args: dict = field(default_factory=dict)  # fixed xacro arguments (text for xacro)
    input: str | None = None
    output: str | None = None
    point: bool = False  # mobility: the output link's origin as a point
    workspace: dict = field(default_factory=dict)  # point, resolution [m], threshold, length [m]
    transmission_steps: int | None = None  # accepted from earlier specs, unused: the extremes are located
    pareto: tuple | None = None  # ((metric, "max"|"min"), (metric, "max"|"min"))
    chunk: int | None = None  # designs per task (default: chosen from the number of designs and workers)
    timeout: float = DESIGN_TIMEOUT  # seconds per design: over it, the design is a failed row
    mode: int | None = None  # the assembly mode every design's motion and workspace follow (None: the first)
    # what a design must meet to be on the Pareto front: ((column, "equal" | "min" | "max", value, unit typed), ...);
    # None: not given (the default requirement of the metrics applies: screwkin.analysis.design.study)
    require: tuple | None = None


def _fail(where: str, message: str):
    raise UsageError(f"{where}: {message}")


def _quantity(v: object, where: str, what: str) -> Quantity:
    """A number, or a number with a unit (text): its units.Quantity (SI value, the unit typed)."""
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        _fail(where, f"{what} must be a number (units allowed, e.g. 30mm), got {quote(v)}")
    if isinstance(v, str):
        try:
            return parse_quantity(v)
        except UsageError as exc:
            _fail(where, f"{what}: {exc}")
    if not math.isfinite(v):
        _fail(where, f"{what} must be finite, got {v!r}")
    return Quantity(float(v))


def _value(v: object, where: str, what: str) -> float:
    """A number, or a number with a unit (text), in SI."""
    return _quantity(v, where, what).value


def _count(v: object, where: str, what: str, low: int = 1, high: int=MAX_DESIGNS):
    if isinstance(v, bool) or not isinstance(v, int) or not low <= v <= high:
        _fail(where, f"{what} must be a whole number from {low} to {high}, got {quote(v)}")
    return v


def _parameter(name: str, item: object, where: str, sampling) -> Parameter:
    what = f"parameter {quote(name)}"
    if not isinstance(item, dict):
        q = _quantity(item, where, what)
        return Parameter(name, values=(q.value,), unit=q.unit)
    unknown = [k for k in item if k not in ("min", "max", "samples", "values")]
    if unknown:
        _fail(where, f"{what}: unknown key {quote(unknown[0])} (a range is min, max, samples; a list is values)")
    if "values" in item:
        if set(item) - {"values"}:
            _fail(where, f"{what}: give either values or min/max, not both")
        values = item["values"]
        if not isinstance(values, list) or not values:
            _fail(where, f"{what}: values must be a non-empty list, got {quote(values)}")
        if len(values) > MAX_VALUES:
            _fail(where, f"{what}: more than {MAX_VALUES} values")
        typed = [_quantity(v, where, f"{what} value") for v in values]
        return Parameter(name, values=tuple(q.value for q in typed), unit=_first_unit(typed))
    if "min" not in item or "max" not in item:
        _fail(where, f"{what}: a range needs min and max (or give values: [...])")
    typed = _quantity(item["min"], where, f"{what} min"), _quantity(item["max"], where, f"{what} max")
    low, high = (q.value for q in typed)
    if low > high:
        _fail(where, f"{what}: bad range, min {low:g} is above max {high:g}")
    samples = item.get("samples")
    if sampling == "grid":
        if samples is None:
            _fail(where, f"{what}: a grid range needs samples (how many values from min to max)")
        samples = _count(samples, where, f"{what} samples", 1, MAX_VALUES)
        if samples == 1 and low != high:
            _fail(where, f"{what}: 1 sample cannot span min {low:g} to max {high:g} (give 2 or more, or one value)")
    elif samples is not None:
        _count(samples, where, f"{what} samples", 1, MAX_VALUES)  # accepted, unused: designs says how many
    return Parameter(name, low=low, high=high, samples=samples, unit=_first_unit(typed))


def _metrics(value: object, where: str) -> tuple:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not value:
        _fail(where, f"metrics must be a list of {', '.join(METRICS)}, got {quote(value)}")
    out = []
    for m in value:
        if not isinstance(m, str) or m not in METRICS:
            _fail(where, f"unknown metric {quote(m)} (known: {', '.join(METRICS)})")
        if m in out:
            _fail(where, f"metric {quote(m)} is listed twice")
        out.append(m)
    return tuple(out)


def _spec_pareto(value: object, where: str) -> tuple | None:
    """``{maximize: [a], minimize: [b]}`` (two metrics in all) -> ((a, "max"), (b, "min"))."""
    if value is None:
        return None
    if not isinstance(value, dict) or set(value) - {"maximize", "minimize"}:
        _fail(where, "pareto must be a mapping with maximize and/or minimize, each a list of column names "
                     "(two in all)")
    picked = []
    for key, goal in (("maximize", "max"), ("minimize", "min")):
        names = value.get(key) or []
        names = [names] if isinstance(names, str) else names
        if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
            _fail(where, f"pareto {key} must be a list of column names, got {quote(value.get(key))}")
        picked += [(n, goal) for n in names]
    if len(picked) != 2 or picked[0][0] == picked[1][0]:
        _fail(where, f"pareto needs two different columns in all (maximize and minimize), got {len(picked)}")
    return tuple(picked)


def _require(value: object, where: str) -> tuple | None:
    """``{column: value, column: {min: x, max: y}}`` -> ((column, "equal", value, False), (column, "min", x,
    unit typed), ...); the columns are checked against the study's in screwkin.analysis.design.study."""
    if value is None:
        return None
    if not isinstance(value, dict):
        _fail(where, "require must be a mapping of column names to a value (dead_points: 0) or bounds "
                     f"({{min: X, max: Y}}), got {quote(value)}")
    out = []
    for name, rule in value.items():
        if not isinstance(name, str) or not _NAME.match(name):
            _fail(where, f"require: {quote(name)} is not a column name")
        if isinstance(rule, dict):
            if not rule or set(rule) - {"min", "max"}:
                _fail(where, f"require {quote(name)}: bounds are min and/or max, got {quote(rule)}")
            for bound in ("min", "max"):
                if bound in rule:
                    v = rule[bound]
                    q = _quantity(v, where, f"require {name} {bound}")
                    out.append((name, bound, q.value, bool(q.unit)))
        elif isinstance(rule, (bool, int, float, str)):
            if isinstance(rule, float) and not math.isfinite(rule):
                _fail(where, f"require {quote(name)} must be finite, got {rule!r}")
            out.append((name, "equal", rule, False))
        else:
            _fail(where, f"require {quote(name)}: give a value or {{min: X, max: Y}}, got {quote(rule)}")
    return tuple(out)


def _workspace(value: object, where: str) -> dict:
    if value is None:
        return {}
    if not isinstance(value, dict):
        _fail(where, f"workspace must be a mapping ({', '.join(_WORKSPACE_KEYS)}), got {quote(value)}")
    out = {}
    for k, v in value.items():
        if k not in _WORKSPACE_KEYS:
            _fail(where, f"workspace: unknown key {quote(k)} (known: {', '.join(_WORKSPACE_KEYS)})")
        if k == "point":
            if not isinstance(v, bool):
                _fail(where, f"workspace point must be true or false, got {quote(v)}")
            out[k] = v
        elif v is not None:
            out[k] = _value(v, where, f"workspace {k}")
            if out[k] <= 0:
                _fail(where, f"workspace {k} must be positive, got {out[k]:g}")
    return out


def study_spec(data: object, where: str = "<dict>", base: Path | None = None) -> StudySpec:
    """Check a study given as plain data (the YAML document, or a dict in Python); ``base``
    is the folder ``file`` is relative to (default: the current folder)."""
    if not isinstance(data, dict):
        _fail(where, f"a study is a mapping with file, parameters and metrics, got {quote(data)}")
    for k in data:
        if k not in _KEYS:
            _fail(where, f"unknown key {quote(k)} (known: {', '.join(_KEYS)})")
    for k in ("file", "parameters", "metrics"):
        if k not in data:
            _fail(where, f"{k} is missing (a study needs file, parameters and metrics)")
    file = data["file"]
    if not isinstance(file, str) or not file.strip():
        _fail(where, f"file must be the path of a mechanism file, got {quote(file)}")
    path = Path(os.path.normpath(Path(file) if Path(file).is_absolute() or base is None else Path(base) / file))
    if not path.is_file():
        _fail(where, f"file {quote(file)} does not exist" + (f" (looked for {quote(str(path), 200)})"
                                                              if str(path) != file else ""))
    sampling = data.get("sampling", "grid")
    if sampling not in SAMPLINGS:
        _fail(where, f"sampling must be one of {', '.join(SAMPLINGS)}, got {quote(sampling)}")
    designs = data.get("designs")
    if sampling == "grid":
        if designs is not None:
            _fail(where, "designs is for random and lhs sampling (a grid has the product of the samples)")
    else:
        if designs is None:
            _fail(where, f"{sampling} sampling needs designs: N (how many designs to draw)")
        designs = _count(designs, where, "designs")
    seed = _count(data.get("seed", 0), where, "seed", 0, 2**32 - 1)
    params = data["parameters"]
    if not isinstance(params, dict) or not params:
        _fail(where, f"parameters must be a mapping of xacro argument names to ranges or values, got {quote(params)}")
    parameters = []
    for name, item in params.items():
        if not isinstance(name, str) or not _NAME.match(name):
            _fail(where, f"parameter {quote(name)} is not a xacro argument name (letters, digits, _)")
        parameters.append(_parameter(name, item, where, sampling))
    if sampling == "grid":
        total = 1
        for p in parameters:
            total *= len(p.values) if p.values is not None else p.samples
        if total > MAX_DESIGNS:
            _fail(where, f"the grid has {total} designs; a study runs at most {MAX_DESIGNS}")
    metrics = _metrics(data["metrics"], where)
    fixed = data.get("args") or {}
    if not isinstance(fixed, dict):
        _fail(where, f"args must be a mapping of xacro argument names to values, got {quote(fixed)}")
    clash = [p.name for p in parameters if p.name in fixed]
    if clash:
        _fail(where, f"{quote(clash[0])} is both a parameter and a fixed argument (args)")
    fixed = normalize_args(fixed, where)
    for key in ("input", "output"):
        if data.get(key) is not None and not isinstance(data[key], str):
            _fail(where, f"{key} must be a joint or link name, got {quote(data[key])}")
    point = data.get("point", False)
    if not isinstance(point, bool):
        _fail(where, f"point must be true or false, got {quote(point)}")
    if point and not data.get("output"):
        _fail(where, "point needs output: LINK")
    workspace = _workspace(data.get("workspace"), where)
    if any(m in metrics for m in WORKSPACE_METRICS):
        if not data.get("output"):
            _fail(where, "the workspace metrics need output: LINK (the link whose workspace is measured)")
        if "resolution" not in workspace:
            # one grid step for every design, so that their volumes compare; screwkin workspace's own default
            # (about 24 steps across, from a first pass) takes 5-20 s per design and differs between designs
            _fail(where, "the workspace metrics need workspace: {resolution: H}, the grid step of every design "
                         "(e.g. 20mm: a 3-D grid of about (size / H)^3 inverse kinematics per design)")
    transmission = data.get("transmission") or {}
    if not isinstance(transmission, dict) or set(transmission) - {"steps"}:
        _fail(where, f"transmission must be a mapping with steps, got {quote(transmission)}")
    steps = transmission.get("steps")  # (earlier specs sampled the motion; the extremes are now located)
    if steps is not None:
        steps = _count(steps, where, "transmission steps", 4, 100_000)
    chunk = data.get("chunk")
    if chunk is not None:
        chunk = _count(chunk, where, "chunk", 1, 100_000)
    timeout = data.get("timeout", DESIGN_TIMEOUT)
    if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not 0 < timeout <= 86400:
        _fail(where, f"timeout must be the seconds one design may take, more than 0 and at most 86400, got "
                     f"{quote(timeout)}")
    mode = data.get("mode")
    if mode is not None:
        mode = _count(mode, where, "mode (the K-th assembly mode, as solve lists them)", 1, 1000)
    spec = StudySpec(where, path, tuple(parameters), metrics, sampling, designs, seed, fixed, data.get("input"),
                     data.get("output"), point, workspace, steps, _spec_pareto(data.get("pareto"), where), chunk,
                     float(timeout), mode, _require(data.get("require"), where))
    _check_arguments(spec, where)
    return spec


def _check_arguments(spec: StudySpec, where: str) -> None:
    """The parameters and fixed arguments must be arguments the xacro file declares, and
    every argument without a default must be given."""
    text = read_regular_file(spec.file, LIMITS.file_bytes, "mechanism file")
    try:
        declared = declared_args(spec.file, text.decode("utf-8-sig"))
    except UnicodeDecodeError:
        raise MechanismFileError(spec.file, "not a text file (not UTF-8)") from None
    except MechanismFileError as exc:  # the family's file itself is refused: no design could run
        _fail(where, f"file {quote(str(spec.file), 200)} is refused: {str(exc).removeprefix(str(spec.file) + ': ')}")
    names = [p.name for p in spec.parameters] + list(spec.args)
    known = ", ".join(sorted(declared)) or "none"
    for n in names:
        if n not in declared:
            _fail(where, f"parameter {quote(n)} is not an argument of {quote(spec.file.name)} (its xacro arguments: "
                         f"{known})")
    missing = [n for n, d in declared.items() if d is None and n not in names]
    if missing:
        _fail(where, f"{quote(spec.file.name)} needs argument {quote(missing[0])} (no default): add it to "
                     "parameters or args")


def read_study_spec(path: str | Path) -> StudySpec:
    """Read and check a study spec file (YAML; see the module docstring)."""
    path = Path(path)
    try:
        raw = read_regular_file(path, LIMITS.yaml_bytes, "study spec")
        text = raw.decode("utf-8-sig")
        data = load_yaml_text(text, path)
    except UnicodeDecodeError:
        _fail(path, "not a text file (not UTF-8)")
    except MechanismFileError as exc:  # no such file, too big, malformed YAML: the request is at fault
        raise UsageError(str(exc)) from None
    return study_spec(data, str(path), path.parent)


def read_mechanism_text(spec: StudySpec) -> str:
    """The text of the study's mechanism file, read once (every design of the study sees the same file): a
    regular file within LIMITS.file_bytes, UTF-8; a usage error naming the study otherwise."""
    raw = read_regular_file(spec.file, LIMITS.file_bytes, "mechanism file")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise UsageError(f"{spec.path}: file {quote(str(spec.file), 200)} is not a text file (not UTF-8)") from None
