"""A study's results for people: the table (CSV, or Parquet with pyarrow), a text summary,
JSON, plots (metrics against parameters, the Pareto front of two metrics); its progress bar is
present/progress.py's.

The rows of screwkin.analysis.design.study are SI (angles in rad); the table people read names
its columns with their units where they are not SI's obvious ones: the transmission
angles are ``transmission_angle_min_deg`` and ``transmission_angle_max_deg`` (degrees),
``grashof_margin_m`` is (p + q) - (s + l) in metres.  Parameters keep their names (the
values are the SI values given to the xacro file).
"""

from __future__ import annotations

import importlib.util
import math
from collections import Counter
from pathlib import Path

import numpy as np

from ..analysis.design.study import MODE_METRICS, REQUIREMENTS_COLUMN, pareto_front, requirements
from ..errors import UsageError, quote
from ..files.study import WORKSPACE_METRICS
from ..units import si_factor
from .plots import pyplot
from .jsonout import to_jsonable
from .tables import csv_text
from .outfile import write_figure, write_output
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.design.study import StudyResult
    from collections.abc import Sequence

__all__ = [
    "DISPLAY",
    "check_table_path",
    "LABELS",
    "mode_rule",
    "metrics_figure",
    "metrics_png",
    "pareto_figure",
    "pareto_png",
    "study_csv",
    "study_dict",
    "study_text",
    "table_columns",
    "write_table",
]

#: Row key -> (column name in the table, the unit it is written in: units.in_unit converts).
DISPLAY = {
    "transmission_angle_min": ("transmission_angle_min_deg", "deg"),
    "transmission_angle_max": ("transmission_angle_max_deg", "deg"),
    "transmission_deviation": ("transmission_deviation_deg", "deg"),
    "grashof_margin": ("grashof_margin_m", "m"),
}


def _display(key: str) -> tuple:
    """(column name, factor from SI) of a row key."""
    name, unit = DISPLAY.get(key, (key, ""))
    return name, si_factor(unit)


def table_columns(result: StudyResult) -> list:
    """[(row key, table column name, factor)] in the table's order."""
    keys = ("design", *result.parameters, *result.columns, "error")
    return [(k, *_display(k)) for k in keys]


def _cell(v: object, factor: float):
    if v is None:
        return None
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        v = float(v) * factor if factor != 1.0 else float(v)
        return None if math.isnan(v) else v  # no value: an empty cell (an infinite one is inf, as in JSON)
    return v


def _table_rows(result: StudyResult) -> tuple[list, list]:
    cols = table_columns(result)
    return [[_cell(r[k], f) for k, _, f in cols] for r in result.rows], [name for _, name, _ in cols]


def study_csv(result: StudyResult) -> str:
    """The table as CSV: one row per design, in design order; empty cells for missing values;
    floats written exactly (shortest round-trip form)."""
    rows, names = _table_rows(result)
    return csv_text(names, (["" if v is None else ("true" if v is True else "false" if v is False else
                                                   repr(v) if isinstance(v, float) else v) for v in row]
                            for row in rows))


def check_table_path(path: str) -> None:
    """Refuse an output the table cannot be written to, before the study runs."""
    suffix = Path(path).suffix.lower()
    if suffix not in (".csv", ".parquet"):
        raise UsageError(f"-o {quote(str(path))}: the table is written as .csv or .parquet")
    if suffix == ".parquet" and importlib.util.find_spec("pyarrow") is None:
        raise UsageError(f"-o {quote(str(path))}: Parquet needs pyarrow (pip install pyarrow); write a .csv instead")
    folder = Path(path).resolve().parent
    if not folder.is_dir():
        raise UsageError(f"-o {quote(str(path))}: the folder {quote(str(folder), 200)} does not exist")


def write_table(result: StudyResult, path: str) -> None:
    """The table into ``path``: CSV, or Parquet (``.parquet``, needs pyarrow)."""
    check_table_path(path)
    if Path(path).suffix.lower() == ".csv":
        write_output(path, study_csv(result))
        return
    import pyarrow as pa  # optional: only for Parquet
    import pyarrow.parquet as pq

    rows, names = _table_rows(result)
    buf = pa.BufferOutputStream()  # made in memory, then written (one way to fail: present/outfile.py)
    pq.write_table(pa.table({n: [row[i] for row in rows] for i, n in enumerate(names)}), buf)
    write_output(path, buf.getvalue().to_pybytes())


def study_dict(result: StudyResult) -> dict:
    """What ``--json`` prints: the study, the rows (SI, as the Python API gives them) and,
    when the spec names two columns, the designs on the Pareto front."""
    spec = result.spec
    d = {
        "spec": spec.path, "file": str(spec.file), "sampling": spec.sampling, "seed": spec.seed,
        "parameters": list(result.parameters), "metrics": list(spec.metrics), "columns": list(result.columns),
        "designs": len(result.rows), "analysed": len(result.succeeded), "failed": len(result.failed),
        "seconds": result.seconds, "workers": result.workers, "scheduler": result.scheduler, "chunks": result.chunks,
        "units": "SI (m, rad; workspace volumes in m^workspace_dimension)",
        "timeout": spec.timeout, "mode": spec.mode or 1, "mode_rule": mode_rule(result), "workspace": dict(spec.workspace) if _workspace_metrics(result) else None,
        "rows": [dict(r) for r in result.rows],
    }
    if spec.pareto and result.succeeded:
        d["pareto"] = {"columns": [{"column": c, "goal": g} for c, g in spec.pareto],
                       "designs": [result.rows[k]["design"] for k in pareto_front(result)]}
    d["paths"] = dict(result.extra.get("paths", {}))
    d["path_notes"] = list(result.extra.get("path_notes", ()))
    reqs, default = requirements(spec)
    if reqs:
        d["requirements"] = {"rules": [q.text for q in reqs], "default": default,
                             "unmet": {str(k): v for k, v in result.extra.get("unmet", {}).items()}}
    d["notes"] = list(result.extra.get("notes", ()))
    return to_jsonable(d)


def mode_rule(result: StudyResult) -> str | None:
    """The one line that says which assembly mode every design follows (the metrics of MODE_METRICS), or None."""
    if not any(m in MODE_METRICS for m in result.spec.metrics):
        if result.spec.mode is not None and "transmission_angle" in result.spec.metrics:
            return (f"assembly mode: --mode {result.spec.mode} does not apply: the transmission angle is the same on "
                    "every assembly mode of a four-bar or slider-crank (the law of cosines in the diagonal), and no "
                    "other metric of this study follows a mode")
        return None
    k = result.spec.mode or 1
    inputs = (f"its input {result.spec.input!r} at its value" if result.spec.input
              else "its actuated joints at their values")
    return (f"assembly mode: each design follows mode {k}{' (the default)' if result.spec.mode is None else ''} of "
            f"{inputs} in its assembled configuration, as solve lists them (--mode K); the columns mode and "
            "modes give it and how many each design has")


def _paths_line(result: StudyResult) -> list:
    """How the designs were evaluated: on the family path (expanded once per chunk, closed forms over the
    designs) or each alone, and why some were alone."""
    paths = result.extra.get("paths") or {}
    family, alone = paths.get("family", 0), paths.get("design", 0)
    if not family:
        why = result.extra.get("family")
        return [f"each design evaluated alone (loaded, assembled, analysed){f': {why}' if why else ''}"]
    lines = [f"{family} designs on the family path (the xacro file expanded once per chunk, each design's file read "
             "and checked, its four-bar's Grashof class and transmission angles in closed form over the designs, its "
             "mobility the chunk's reference design's -- assumed, the structure being the same; each chunk's "
             f"reference and one design drawn at random also evaluated alone and compared), {alone} evaluated alone"]
    lines += [f"  {n}" for n in result.extra.get("path_notes", ())[:5]]
    return lines


def _requirements_lines(result: StudyResult) -> list:
    """What the designs had to meet and which did not (left out of the Pareto front)."""
    reqs, default = requirements(result.spec)
    if not reqs:
        return []
    ok = [r for r in result.succeeded if r.get(REQUIREMENTS_COLUMN)]
    unmet = result.extra.get("unmet", {})
    how = (" (the default of " + ", ".join(m for m in result.spec.metrics if m == "transmission_angle")
           + ": a dead point, mu = 0 or 180 deg, stops the input driving the output; state require: in the spec "
           "to change it)") if default else ""
    lines = [f"requirements: {'; '.join(q.text for q in reqs)}{how}: {len(ok)} of {len(result.succeeded)} analysed "
             "designs meet them"]
    if unmet:
        shown = list(unmet.items())[:10]
        lines.append("  not met (marked in the table, left out of the Pareto front): "
                     + "; ".join(f"design {k}: {v}" for k, v in shown)
                     + (f"; ... and {len(unmet) - len(shown)} more" if len(unmet) > len(shown) else ""))
    return lines


def _workspace_metrics(result: StudyResult) -> bool:
    return any(m in WORKSPACE_METRICS for m in result.spec.metrics)


def _cell_text(v: object) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


#: Most rows the text output lists (the table file has them all).
TEXT_ROWS = 40


def study_text(result: StudyResult, table_path: str | None=None) -> str:
    """A summary: counts, the failures' reasons, each metric's range and the design reaching
    each end; the rows themselves when there are few."""
    spec = result.spec
    n, ok, bad = len(result.rows), result.succeeded, result.failed
    what = (f"grid over {', '.join(result.parameters)}" if spec.sampling == "grid"
            else f"{spec.sampling} sampling of {', '.join(result.parameters)} (seed {spec.seed})")
    lines = [(f"study of {spec.file} ({what}): {n} designs, {len(ok)} analysed, {len(bad)} failed; "
              f"{result.seconds:.2f} s on {result.workers} worker{'s' if result.workers != 1 else ''} "
              f"({result.scheduler}), timeout {spec.timeout:g} s per design")]
    lines += _paths_line(result)
    if _workspace_metrics(result):
        ws = spec.workspace
        lines.append(f"workspace metrics of {result.spec.output!r}"
                     + (" (its origin as a point)" if ws.get("point") else " (at its assembled orientation)")
                     + f" on a grid of step {ws['resolution']:g} m (the spec's workspace resolution), threshold "
                     + f"{ws.get('threshold', 0.01):g}")
    line = mode_rule(result)
    if line:
        lines.append(line)
    if bad:
        reasons = Counter(r["error"] for r in bad)
        lines.append("failed designs:")
        for reason, count in reasons.most_common(5):
            lines.append(f"  {count} x {reason}")
        if len(reasons) > 5:
            lines.append(f"  ... and {len(reasons) - 5} other reasons")
    cols = table_columns(result)
    params = [(k, name, f) for k, name, f in cols if k in result.parameters]
    for k, name, f in cols:
        if k not in result.columns:
            continue
        vals = [(r, _cell(r[k], f)) for r in ok if r[k] is not None]
        if not vals:
            continue
        if all(isinstance(v, (int, float)) and not isinstance(v, bool) for _, v in vals):
            lo = min(vals, key=lambda t: t[1])
            hi = max(vals, key=lambda t: t[1])

            def at(r) -> str:
                return ", ".join(f"{p}={_cell_text(r[pk])}" for pk, p, _ in params)

            if lo[1] == hi[1]:
                lines.append(f"{name}: {_cell_text(lo[1])} in all {len(vals)}")
            else:
                lines.append(f"{name}: {_cell_text(lo[1])} (design {lo[0]['design']}: {at(lo[0])}) .. "
                             f"{_cell_text(hi[1])} (design {hi[0]['design']}: {at(hi[0])})")
        else:
            counts = Counter(str(v) for _, v in vals)
            lines.append(f"{name}: " + ", ".join(f"{v} {c}" for v, c in counts.most_common()))
    lines += _requirements_lines(result)
    if spec.pareto and ok:
        front = pareto_front(result)
        names = [f"{g} {_display(c)[0] if c in DISPLAY else c}" for c, g in spec.pareto]
        among = " among the designs that meet the requirements" if requirements(spec)[0] else ""
        lines.append(f"Pareto front ({', '.join(names)}){among}: designs "
                     f"{', '.join(str(result.rows[k]['design']) for k in front) or 'none'}")
    lines += [f"note: {n}" for n in result.extra.get("notes", ())]
    rows, names = _table_rows(result)
    if n <= TEXT_ROWS:
        table = [names] + [[_cell_text(v) for v in row] for row in rows]
        widths = [max(len(row[i]) for row in table) for i in range(len(names) - 1)]
        lines.append("")
        for row in table:
            lines.append("  ".join(c.ljust(w) for c, w in zip(row[:-1], widths)) + ("  " + row[-1] if row[-1] != "-"
                                                                                     else ""))
    elif table_path is None:
        lines.append(f"({n} rows: write them with -o results.csv)")
    if table_path is not None:
        lines.append(f"table: {table_path}")
    return "\n".join(line.rstrip() for line in lines)


def _numeric(result: StudyResult) -> list:
    """[(row key, label, factor)] of the metric columns with numbers."""
    out = []
    for k, name, f in table_columns(result):
        if k in result.columns and k not in ("workspace_dimension", "transmission_restarts"):
            vals = [r[k] for r in result.succeeded if r[k] is not None]
            if vals and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals):
                out.append((k, name, f))
    return out


#: Metric key -> (axis label, the unit it is shown in: units.in_unit converts; "" for none) on the
#: study's plots; the label says the unit (in brackets after the name when it is one of units.py's).
LABELS = {
    "transmission_angle_min": ("smallest transmission angle", "deg"),
    "transmission_angle_max": ("largest transmission angle", "deg"),
    "transmission_deviation": ("largest |90 deg - transmission angle|", "deg"),
    "dead_points": ("dead points [-]", ""),
    "grashof_margin": ("Grashof margin (p+q)-(s+l)", "mm"),
    "mobility": ("mobility [DOF]", ""),
    "mobility_count": ("mobility by counting [DOF]", ""),
    "overconstraint": ("overconstraint [constraints]", ""),
    "idle_dofs": ("idle DOFs [DOF]", ""),
    "effective_mobility": ("effective mobility [DOF]", ""),
    "workspace_volume": ("workspace volume [m^{dim}]", ""),
    "singularity_free_volume": ("singularity-free volume [m^{dim}]", ""),
    "conditioning_min": ("smallest conditioning [-]", ""),
    "conditioning_mean": ("mean conditioning [-]", ""),
}
FAILED_COLOR = "crimson"


def _label(key: str, result: StudyResult | None = None) -> tuple:
    """(axis label, factor from SI) of a metric column; a volume's unit from the designs' workspace
    dimension (m^2 or m^3; m^d when they differ)."""
    if key in LABELS:
        label, unit = LABELS[key]
        label, factor = (f"{label} [{unit}]" if unit else label), si_factor(unit)
    else:
        label, factor = _display(key)
    if "{dim}" in label:
        dims = {r.get("workspace_dimension") for r in (result.succeeded if result is not None else ())} - {None}
        label = label.replace("{dim}", str(dims.pop()) if len(dims) == 1 else "d")
    return label, factor


def _parameter_axis(result: StudyResult, name: str) -> tuple:
    """(axis label, factor from SI) of a parameter: in the unit its values were typed in (the study
    file's ``30mm``), else as given (xacro arguments are SI, the file does not say m or rad)."""
    unit = next((getattr(p, "unit", "") for p in result.spec.parameters if p.name == name), "")
    if unit:
        return f"{name} [{unit}]", si_factor(unit)
    return f"{name} (as given, SI: no unit typed)", 1.0


def _classes(result: StudyResult) -> dict:
    """The colour of each design (row index -> (class, colour)): its Grashof class when the study
    has one, failed designs in FAILED_COLOR."""
    out = {}
    names = sorted({r["grashof"] for r in result.succeeded if r.get("grashof")})
    colors = {n: f"C{k}" for k, n in enumerate(names)}
    for k, r in enumerate(result.rows):
        if r["error"] is not None:
            out[k] = ("failed", FAILED_COLOR)
        else:
            c = r.get("grashof")
            out[k] = (c, colors[c]) if c else ("analysed", "C0")
    return out


def metrics_figure(result: StudyResult):
    """The figure of :func:`metrics_png` (not yet saved): each numeric metric against each parameter,
    one panel per pair, axes with their units, points coloured by Grashof class (when the study has
    it), failed designs as crosses along the bottom of each panel at their parameter values."""
    plt = pyplot("--plot")
    numeric = _numeric(result)
    params = list(result.parameters)
    if not numeric:
        raise UsageError("--plot: no design has a numeric metric to draw")
    ok = result.succeeded
    # a metric with one value for every design (a four-bar family's mobility) gets no panel, only a mention
    constant = [(k, name, f) for k, name, f in numeric if len({r[k] for r in ok if r[k] is not None}) == 1]
    metrics = [m for m in numeric if m not in constant] or numeric
    same = ", ".join(f"{name} = {_cell_text(_cell(next(r[k] for r in ok if r[k] is not None), f))}"
                     for k, name, f in constant if (k, name, f) not in metrics)
    classes = _classes(result)
    fig, axes = plt.subplots(len(metrics), len(params), squeeze=False,
                             figsize=(3.2 * len(params) + 0.5, 2.6 * len(metrics) + 1.0))
    handles = {}
    for i, (k, _name, _f) in enumerate(metrics):
        label, f = _label(k, result)
        for j, p in enumerate(params):
            ax = axes[i][j]
            plabel, pf = _parameter_axis(result, p)
            for cls, colour in dict(classes.values()).items():  # class -> its colour, in the rows' order
                rows = [r for n, r in enumerate(result.rows) if classes[n][0] == cls and r[k] is not None
                        and r["error"] is None]
                if rows:
                    (h,) = ax.plot([r[p] * pf for r in rows], [r[k] * f for r in rows], "o", ms=4, alpha=0.8,
                                   color=colour, label=cls)
                    handles.setdefault(cls, h)
            failed = [r for r in result.rows if r["error"] is not None]
            if failed:
                (h,) = ax.plot([r[p] * pf for r in failed], [0.0] * len(failed), "x", ms=6,
                               color=FAILED_COLOR, label="failed", transform=ax.get_xaxis_transform(), clip_on=False)
                handles.setdefault("failed", h)
            if i == len(metrics) - 1:
                ax.set_xlabel(plabel, fontsize=8)
            if j == 0:
                ax.set_ylabel(label, fontsize=8)
    title = f"{Path(result.spec.file).name}: {len(ok)} of {len(result.rows)} designs analysed"
    fig.suptitle(title + (f"\nin all: {same}" if same else ""), fontsize=9)
    if len(handles) > 1 or "failed" in handles:
        fig.legend(list(handles.values()), list(handles), loc="lower center", ncol=min(len(handles), 4), fontsize=8,
                   title="Grashof class" if any(r.get("grashof") for r in ok) else None, title_fontsize=8)
    fig.tight_layout(rect=(0, 0.06 if len(handles) > 1 or "failed" in handles else 0, 1, 0.96 if same else 0.98))
    return fig


def metrics_png(result: StudyResult, path: str) -> None:
    """Each numeric metric against each parameter (see :func:`metrics_figure`)."""
    plt = pyplot("--plot")
    fig = metrics_figure(result)
    try:
        write_figure(fig, path, dpi=100, metadata={"Title": fig._suptitle.get_text()})
    finally:
        plt.close(fig)


def pareto_figure(result: StudyResult, goals: Sequence[tuple[str, str]] | None=None):
    """The figure of :func:`pareto_png` (not yet saved): the designs in the plane of two columns with
    their units, coloured by Grashof class (when the study has it), the Pareto front drawn over them;
    the failed designs, which have no place in this plane, counted in the title."""
    plt = pyplot("--plot")
    goals = goals or result.spec.pareto
    front = pareto_front(result, goals)
    keys = (*result.parameters, *result.columns)
    (a, ga), (b, gb) = [(c if c in keys else c.removesuffix("_deg").removesuffix("_m"), g) for c, g in goals]
    axis = {c: _parameter_axis(result, c) if c in result.parameters else _label(c, result) for c in (a, b)}
    (la, fa), (lb, fb) = axis[a], axis[b]
    classes = _classes(result)
    fig, ax = plt.subplots(figsize=(6.5, 4.8))
    for cls, colour in dict(classes.values()).items():  # class -> its colour, in the rows' order
        if cls == "failed":
            continue
        rows = [r for n, r in enumerate(result.rows) if classes[n][0] == cls and r[a] is not None and r[b] is not None]
        for meets, style in ((True, {}), (False, {"markerfacecolor": "none"})):
            some = [r for r in rows if (r.get(REQUIREMENTS_COLUMN) is not False) == meets]
            if some:
                ax.plot([r[a] * fa for r in some], [r[b] * fb for r in some], "o", ms=4, alpha=0.8, color=colour,
                        label=(cls if cls != "analysed" else "designs") + ("" if meets else ", requirements not met"),
                        **style)
    fx = [result.rows[k][a] * fa for k in front]
    fy = [result.rows[k][b] * fb for k in front]
    ax.plot(fx, fy, "-", color="k", linewidth=1.0, label="Pareto front")
    ax.plot(fx, fy, "o", ms=7, markerfacecolor="none", markeredgecolor="k")
    for k, x, y in zip(front, fx, fy):
        ax.annotate(str(result.rows[k]["design"]), (x, y), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xlabel(f"{la} ({ga}imize)" if ga in ("max", "min") else f"{la} ({ga})")
    ax.set_ylabel(f"{lb} ({gb}imize)" if gb in ("max", "min") else f"{lb} ({gb})")
    nfail = len(result.failed)
    unmet = sum(r.get(REQUIREMENTS_COLUMN) is False for r in result.rows)
    ax.set_title(f"{Path(result.spec.file).name}: {len(result.succeeded)} designs"
                 + (f", {nfail} failed (not drawn)" if nfail else "")
                 + (f"; {unmet} not meeting the requirements (hollow, off the front)" if unmet else ""), fontsize=9)
    ax.legend(fontsize=8, title="Grashof class" if any(r.get("grashof") for r in result.succeeded) else None,
              title_fontsize=8)
    fig.tight_layout()
    return fig


def pareto_png(result: StudyResult, path: str, goals: Sequence[tuple[str, str]] | None=None) -> None:
    """The designs in the plane of two columns, the Pareto front drawn over them (see :func:`pareto_figure`)."""
    plt = pyplot("--plot")
    fig = pareto_figure(result, goals)
    try:
        write_figure(fig, path, dpi=100, metadata={"Title": fig.axes[0].get_title()})
    finally:
        plt.close(fig)
