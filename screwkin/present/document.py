"""The document of ``screwkin report``: sections of paragraphs, tables, preformatted text and
figures, written as one self-contained HTML page or as Markdown.

HTML: CSS inline, every picture a ``data:`` URI (SVG drawings and plots, the view a PNG), no
script that runs (the results ride along as ``<script type="application/json"
id="screwkin-data">``, which a browser never executes), nothing fetched: it opens offline.
Markdown: pictures as files in a folder beside it (``F_files/`` for ``F.md``), linked
relatively -- Markdown renderers (GitHub's among them) drop ``data:`` images -- and the
results as ``F_files/data.json``.

The content carries no date and no absolute path of its own: the same command on the same
file writes the same document (the view's PNG is Chromium's rendering, the one part that
may differ between machines).
"""

from __future__ import annotations

import base64
import io
import re
from dataclasses import dataclass, field
from html import escape

import numpy as np

from ..analysis.course.symbols import PlanarEquations
from .draw import wrapped_value
from .equations import Units, equations_text, greek, newton_text
from .tables import RateUnits, shown
from .motion import linkage_construction_text, links_rows, points_rows
from .report import slide_note, solution_rows
from .mobility import (
    JOINT_COLUMNS,
    count_rows,
    joint_rows,
    screw_theory_rows,
)
from .screws import screws_text
from .local import local_lines, redundancy_lines
from .jsonout import json_of
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.course.figures import SingularSearch
    from screwkin.analysis.course.newton import NewtonResult
    from screwkin.analysis.mobility import MobilityResult
    from screwkin.analysis.position.solution import PositionResult
    from screwkin.model.topology import Topology
    from collections.abc import Sequence

__all__ = ["Code", "Document", "Figure", "Note", "Section", "Table", "Text", "figure_bytes", "html", "markdown",
           "topology_section", "equations_section", "newton_section", "motion_section", "singular_section",
           "sweep_section", "view_section"]


# ------------------------------------------------------------------ the document's parts
@dataclass
class Text:
    text: str


@dataclass
class Note:
    """Something a section could not show, and why."""

    text: str


@dataclass
class Code:
    text: str


@dataclass
class Table:
    headers: list
    rows: list
    role: str = ""


@dataclass
class Figure:
    data: bytes
    fmt: str  # "svg" | "png"
    caption: str
    role: str  # "skeleton", "targets", "chain", "singular", "sweep", "view": the HTML class and the file name


@dataclass
class Section:
    id: str
    title: str
    blocks: list = field(default_factory=list)


@dataclass
class Document:
    title: str
    facts: list  # (what, value): file, version, configuration ...
    sections: list
    data: dict  # the results as JSON


def figure_bytes(fig, fmt: str = "svg") -> bytes:
    """A matplotlib Figure as SVG or PNG bytes, closed after; no date in it and fixed SVG ids,
    so that the same figure gives the same bytes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    try:
        with matplotlib.rc_context({"svg.hashsalt": "screwkin", "svg.fonttype": "path"}):
            fig.savefig(buf, format=fmt, dpi=100,
                        metadata={"Date": None} if fmt == "svg" else {"Software": None})
    finally:
        plt.close(fig)
    return buf.getvalue()


# ------------------------------------------------------------------ numbers as people read them
def _g(x: float, digits: int = 6) -> str:
    return f"{shown(x):.{digits}g}"


def _reading(value: float, angular: bool) -> str:
    return f"{np.degrees(value):.6g} deg" if angular else f"{value * 1000:.6g} mm"


# ------------------------------------------------------------------ sections
def topology_section(topo: Topology, mobility: MobilityResult, figures: list | tuple = ()) -> Section:
    """Joint table, the counts with their formulas, the screw-theory mobility."""
    s = Section("topology", "Topology and mobility")
    s.blocks.append(Text(f"links N = {topo.n_links} (ground: {topo.ground}), joints J = {topo.n_joints}, "
                         f"loops L = J - N + 1 = {topo.loops}, sum f = {topo.sum_dof}; "
                         f"motion space: {topo.motion_space} ({topo.motion_space_detail})"))
    s.blocks.append(Table(list(JOINT_COLUMNS), joint_rows(topo, limit=80), "joints"))
    if topo.textbook_planar:
        s.blocks.append(Text(f"full joints J1 = {topo.full_joints} (one DOF: lower pairs, rolling), half joints "
                             f"J2 = {topo.half_joints} (two DOF: sliding contacts)"))
    for c in topo.couplings:
        s.blocks.append(Text(f"coupling (mimic): {c.joint} = {c.multiplier:g} x {c.mimics} + {c.offset:g}"))
    s.blocks.append(Table(["count", "formula", "value"], count_rows(topo), "counts"))
    if mobility is not None:
        s.blocks.append(Table(["screw theory", "value"], screw_theory_rows(mobility), "mobility"))
        s.blocks.append(Text(f"classification: {mobility.classification}"))
        s.blocks += [Text(f"note: {n}") for n in mobility.notes]
        # the explanations the command's default text leaves to --explain: how the local analysis decided, the
        # redundant constraints by name and the exactly constrained alternative
        explained = (local_lines(mobility.local, mobility.local_where) if mobility.local is not None else []) + (
            redundancy_lines(mobility.redundant, "redundant constraints at a configuration of the generic rank")
            if mobility.redundant is not None else [])
        if explained:
            s.blocks.append(Code("\n".join(explained)))
    s.blocks += list(figures)
    return s


def equations_section(res) -> Section:
    """Planar: vector loops, A, B, c, det A and its singular conditions; otherwise the
    product-of-exponentials chains and the constraint Jacobian's rank conditions."""
    s = Section("equations", "Equations")
    if not isinstance(res, PlanarEquations):
        s.blocks.append(Text(f"{res.motion_space} mechanism: no planar vector loops; the product-of-exponentials "
                             "structure equations of each chain (the loops close where the chains to both sides of "
                             "each cut joint meet) and the rank of the constraint Jacobian K."))
        s.blocks.append(Code(screws_text(res.chains)))
        s.blocks.append(Text(f"constraint Jacobian K: {res.rows} rows x {res.columns} joint rates, rank {res.rank} "
                             f"here, {res.generic_rank} generic (dimensionless with L = {res.length:.4g} m)"))
        s.blocks.append(Table(["singular condition"], [[c] for c in res.singular_conditions], "conditions"))
        return s
    s.blocks.append(Code(equations_text(res)))
    if res.det_A is not None:
        s.blocks.append(Text(f"det A = {greek(res.det_A)}"))
        s.blocks.append(Text("det A in sympy syntax (as screwkin equations --json writes it):"))
        s.blocks.append(Code(res.det_A))
    rows = [[greek(c), greek(w)] for c, w in zip(res.singular_conditions, res.singular_words)]
    rows += [["", greek(w)] for w in res.singular_words[len(res.singular_conditions):]]
    if rows:
        s.blocks.append(Table(["singular where (det A = 0)", "in words"], rows, "conditions"))
    return s


def newton_section(res: NewtonResult, symbols, how: str, path: str) -> Section:
    """Newton's iterations on the loop equations from the estimates ``how`` describes."""
    s = Section("newton", "Newton iterations")
    s.blocks.append(Text(how))
    show = Units(True, {n: "mm" for n in res.unknowns if symbols[n].kind != "angle"})  # deg and mm
    rows = [[st.iteration, ", ".join(f"{greek(n)} = {show.value(n, symbols[n].kind, st.before[n])}"
                                     for n in res.unknowns),
             f"{np.linalg.norm(st.residual):.3e}",
             ", ".join(f"d{greek(n)} = {show.step(n, symbols[n].kind, d)}" for n, d in zip(res.unknowns, st.step))]
            for st in res.steps]
    s.blocks.append(Table(["iteration", "estimates", "|F| [m]", "step"], rows, "newton"))
    s.blocks.append(Code(newton_text(res, symbols, show, path)))
    return s


def motion_section(pres: PositionResult, rates_text: str, length: float, units: RateUnits = RateUnits(), analysed: int = 1) -> Section:
    """The assembly modes for the inputs: every coordinate (loop joints too) with its rate and acceleration,
    the moving links' absolute motion, named points -- the tables of ``solve`` (present/report.solution_rows,
    present/motion.links_rows and points_rows), rates in ``units`` (those typed)."""
    s = Section("motion", "Positions, velocities and accelerations")
    inputs = ", ".join([f"{n} = {_reading(v, n in pres.angular)}" for n, v in pres.inputs.items()]
                       + [f"angle of {k} = {_reading(v, True)}" for k, v in (pres.held or {}).items()])
    s.blocks.append(Text(f"inputs: {inputs or 'none'}; {rates_text}. {len(pres.solutions)} assembly mode(s) found; "
                         f"solution {analysed} is the configuration this report analyses (--mode K for another)."))
    for k, sol in enumerate(pres.solutions, 1):
        what = "" if sol.physical else f" (not reached by moving: {'; '.join(sol.labels)})"
        s.blocks.append(Text(f"solution {k}{what}: closure residual {sol.residual:.3g}, sigma_min {sol.sigma_min:.3g}"
                             + (" (singular)" if sol.singular else "")))
        # solve's joint table (loop joints too), links and points tables
        s.blocks.append(Table(*solution_rows(pres, sol, units=units), f"solution-{k}"))
        note = slide_note(pres, sol)
        if note:
            s.blocks.append(Text(note))
        if sol.links and any("angle" in m or "omega" in m for m in sol.links.values()):
            title, head, rows = links_rows(sol.links, units)  # the moving links, as solve lists them
            s.blocks += [Text(title), Table(head, rows, f"links-{k}")]
        if sol.points:  # named points (--point NAME=LINK:x,y,z), world axes
            title, head, rows = points_rows(sol.points, units)
            s.blocks += [Text(title), Table(head, rows, f"points-{k}")]
        if sol.linkage:
            s.blocks.append(Text(linkage_construction_text(sol.linkage)))
        if sol.output_pose is not None:
            p, rpy = sol.output_position, sol.output_rpy
            s.blocks.append(Text(f"output '{pres.output}': position {' '.join(_g(1000 * x) for x in p)} mm, roll pitch "
                                 f"yaw {' '.join(_g(np.degrees(x)) for x in rpy)} deg"
                                 + ("" if sol.output_twist is None else
                                    "; twist (v [m/s], w [rad/s]) " + " ".join(_g(x) for x in sol.output_twist))))
    return s


def singular_section(search: SingularSearch, figures: list, descriptions: list, conditions: Sequence[str]=()) -> Section:
    """The singular configurations located along the input's range, each with its drawing."""
    s = Section("singular", "Singular configurations")
    if conditions:
        s.blocks.append(Text("where the equations are singular: " + "; ".join(greek(c) for c in conditions)))
    unit = search.unit
    lo, hi = (_reading(v, unit != "m") for v in (search.start, search.stop))
    held = ", ".join(f"{k} = {_g(v)}" for k, v in search.fixed.items())
    s.blocks.append(Text(f"located along {search.input} from {lo} to {hi}" + (f" (held: {held})" if held else "")
                         + (f", serial singularities of '{search.output}'" if search.output else "")
                         + f": {len(search.found)} singular configuration(s)"
                         + (" (the motion passes limit positions onto the other branch)" if search.turned else "")))
    if search.found:
        s.blocks.append(Table(["#", "kind", f"{search.input}", "relative sigma"],
                              [[k, kind, _reading(wrapped_value(f.input, unit), unit != "m"), f"{f.sigma:.2g}"]
                               for k, (f, kind) in enumerate(zip(search.found, descriptions), 1)],
                              "singular"))
    s.blocks += list(figures)
    return s


def sweep_section(search: SingularSearch, figure: Figure, lines: Sequence[str]=(), rate_words: str | None=None) -> Section:
    """The input moved over its range: the figure, and ``lines`` (each slider's stroke and time ratio,
    present/motion.strokes_text, as sweep prints them); ``rate_words``: the input's rate as typed
    (tables.input_rate_words, "at crank 120 rpm"; default: the sweep's rate in SI)."""
    s = Section("sweep", "Sweep of the input")
    res = search.motion
    x = _reading(res.values[-1], res.unit != "m") if len(res.values) else "-"
    first = _reading(res.values[0], res.unit != "m") if len(res.values) else "-"
    rate_words = rate_words or f"at {res.rate:g} {'rad/s' if res.unit != 'm' else 'm/s'}"
    s.blocks.append(Text(f"{search.input} moved from {first} in {len(res.values) - 1} steps {rate_words} "
                         f"(one assembly mode followed"
                         + (", through limit positions" if res.limits else "") + f"; last value {x})"
                         + (f"; stopped: {res.stop_reason}" if res.stopped_at is not None else "")))
    s.blocks += [Text(line) for line in lines]
    s.blocks.append(figure)
    return s


def view_section(png: bytes | None, note: str | None = None) -> Section:
    s = Section("view", "View")
    if png is not None:
        s.blocks.append(Figure(png, "png", "the mechanism at the configuration analysed (screwkin view, headless "
                                           "Chromium)", "view"))
    if note:
        s.blocks.append(Note(note))
    return s


def note_section(id: str, title: str, text: str) -> Section:
    return Section(id, title, [Note(text)])


# ------------------------------------------------------------------ HTML
_CSS = """
body {font: 15px/1.45 'DejaVu Sans', Arial, sans-serif; color: #222; max-width: 1100px; margin: 24px auto;
  padding: 0 16px;}
h1 {font-size: 1.6em;} h2 {border-bottom: 1px solid #ccc; padding-bottom: 3px; margin-top: 1.8em;}
table {border-collapse: collapse; margin: 0.6em 0;} td, th {border: 1px solid #ccc; padding: 2px 8px;
  text-align: left; vertical-align: top;} th {background: #f2f2f2;}
pre {background: #f7f7f7; border: 1px solid #e2e2e2; padding: 8px; overflow-x: auto; font-size: 12.5px;}
figure {margin: 1em 0;} figure img {max-width: 100%; border: 1px solid #eee;}
figcaption {font-size: 0.9em; color: #555;}
.note {background: #fff6dd; border-left: 4px solid #e6b800; padding: 4px 10px;}
nav a {margin-right: 12px;}
"""


def _data_uri(f: Figure) -> str:
    mime = "image/svg+xml" if f.fmt == "svg" else "image/png"
    return f"data:{mime};base64,{base64.b64encode(f.data).decode('ascii')}"


def _html_block(b) -> str:
    if isinstance(b, Text):
        return f"<p>{escape(b.text)}</p>"
    if isinstance(b, Note):
        return f'<p class="note">{escape(b.text)}</p>'
    if isinstance(b, Code):
        return f"<pre>{escape(b.text)}</pre>"
    if isinstance(b, Table):
        head = "".join(f"<th>{escape(str(h))}</th>" for h in b.headers)
        body = "".join("<tr>" + "".join(f"<td>{escape(str(c))}</td>" for c in r) + "</tr>" for r in b.rows)
        cls = f' class="{escape(b.role)}"' if b.role else ""
        return f"<table{cls}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
    if isinstance(b, Figure):
        return (f'<figure class="{escape(b.role)}"><img src="{_data_uri(b)}" alt="{escape(b.caption)}">'
                f"<figcaption>{escape(b.caption)}</figcaption></figure>")
    raise TypeError(type(b).__name__)  # pragma: no cover


def html(doc: Document) -> str:
    """The document as one self-contained HTML page."""
    nav = " ".join(f'<a href="#{s.id}">{escape(s.title)}</a>' for s in doc.sections)
    facts = "".join(f"<tr><th>{escape(k)}</th><td>{escape(str(v))}</td></tr>" for k, v in doc.facts)
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
             f"<title>{escape(doc.title)}</title>", f"<style>{_CSS}</style></head><body>",
             f"<h1>{escape(doc.title)}</h1>", f'<table class="facts">{facts}</table>', f"<nav>{nav}</nav>"]
    for s in doc.sections:
        parts.append(f'<section id="{escape(s.id)}"><h2>{escape(s.title)}</h2>')
        parts += [_html_block(b) for b in s.blocks]
        parts.append("</section>")
    # < > & as JSON escapes: no name can close the script element or open a comment in it
    data = (json_of(doc.data, indent=1, sort_keys=True)
            .replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026"))
    parts.append(f'<script type="application/json" id="screwkin-data">{data}</script>')
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


# ------------------------------------------------------------------ Markdown
def _md_text(t: str) -> str:
    """Text for Markdown: HTML escaped (a Markdown viewer renders raw HTML: a link named
    ``<script>`` must stay text) and Markdown's emphasis, code and link characters escaped."""
    return escape(re.sub(r"([*`\\\[\]])", r"\\\1", str(t)), quote=False)


def _md_cell(c) -> str:
    return _md_text(c).replace("|", "\\|").replace("\r", " ").replace("\n", " ")


def _fence(text: str) -> str:
    """A code fence longer than any run of backticks in ``text``."""
    return "`" * max(3, 1 + max((len(r) for r in re.findall(r"`+", text)), default=0))


def _md_table(headers: Sequence[str], rows: Sequence[Sequence]) -> str:
    out = ["| " + " | ".join(_md_cell(h) for h in headers) + " |", "|" + "---|" * len(headers)]
    out += ["| " + " | ".join(_md_cell(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def markdown(doc: Document, folder: str) -> tuple:
    """(Markdown text, {file name in ``folder``: bytes}): the pictures and data.json go into
    ``folder`` (a name relative to the Markdown file), which the text links to."""
    files = {}
    lines = [f"# {_md_cell(doc.title)}", "", _md_table(["", ""], doc.facts), ""]
    for s in doc.sections:
        lines += [f"## {_md_cell(s.title)}", ""]
        for b in s.blocks:
            if isinstance(b, Text):
                lines.append(_md_text(b.text))
            elif isinstance(b, Note):
                lines.append("> " + _md_text(b.text).replace("\n", "\n> "))
            elif isinstance(b, Code):
                lines += [_fence(b.text) + "text", b.text, _fence(b.text)]
            elif isinstance(b, Table):
                lines.append(_md_table(b.headers, b.rows))
            elif isinstance(b, Figure):
                name = f"{len(files) + 1:02d}-{b.role}.{b.fmt}"
                files[name] = b.data
                lines.append(f"![{_md_cell(b.caption)}]({folder}/{name})")
                lines.append("")
                lines.append(f"*{_md_cell(b.caption)}*")
            lines.append("")
    files["data.json"] = (json_of(doc.data, indent=1, sort_keys=True) + "\n").encode()
    lines.append(f"The results as JSON: [{folder}/data.json]({folder}/data.json)")
    return "\n".join(lines) + "\n", files
