"""``screwkin report FILE --html F`` (and/or ``--md F``): one document of everything screwkin
says about a mechanism at one configuration -- topology and joint table, the counts with
their formulas, the equations, Newton's iterations, positions, velocities and accelerations,
the singular configurations with their drawings, the sweep plot and a view.

Each section comes from the analysis the command of its own runs (info/mobility, equations,
solve --start, solve, draw --singular, sweep --plot, view --png); one that cannot be made for
this mechanism (no planar loops, no single input, no Chromium) says why in the document
instead, and the rest is still written."""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from typing import TYPE_CHECKING

import numpy as np

from ..analysis.course.equations import equations
from ..analysis.course.newton import differing, start_estimates, textbook_newton
from ..analysis.course.vector_loops import VectorLoops
from ..analysis.mobility import analyze_mobility
from ..analysis.motion.links import strokes, sweep_motion
from ..analysis.position.modes import choose_mode
from ..analysis.motion.planar import identify, transmission_angles
from ..analysis.course.figures import default_output, singular_configurations
from ..analysis.course.skeleton import kinematic_chain, skeleton
from ..errors import OutputError, ScrewkinError, UsageError
from ..present.jsonout import json_of
from ..present.document import (
    Document,
    Figure,
    equations_section,
    figure_bytes,
    html,
    markdown,
    motion_section,
    newton_section,
    note_section,
    singular_section,
    sweep_section,
    topology_section,
    view_section,
)
from ..present.draw import draw_chain, draw_mechanism, value_label, wrapped_value
from ..present.draw_targets import design_drawing
from ..present.equations import equations_dict, newton_dict
from ..present.local import singularity_kind_text
from ..present.motion import motion_dict, strokes_dict, strokes_text
from ..present.outfile import os_reason, remove_partial, write_output
from ..present.plots import absolute_series, motion_figure
from ..present.report import position_dict
from ..present.mobility import mobility_dict
from ..present.view import (
    build_scene,
    chromium,
    page,
    screenshot,
    show,
)
from ..present.camera import PICTURE
from ..present.tables import RateUnits, input_rate_words
from ..present.viewserver import ViewerServer
from ..units import parse_typed_assignments
from ._configuration import add_configuration_options, input_solver, mode_line, near_values
from ._output_frame import add_point_option, named_points
from ._values import check_rate_names, joint_quantities, link_rates, rate_items, split_inputs, value_kind
from ._options import check_writable, count, screwkin_version

if TYPE_CHECKING:
    from ..analysis.position.solution import PositionResult
    from ..model.mechanism import Mechanism
    from ..model.topology import Topology
    from ..present.document import Section
    from collections.abc import Callable

NAME = "report"
NEEDS_MECHANISM = True

#: The default estimates of Newton's iterations: the solved unknowns, angles turned by this much ...
START_ANGLE = np.radians(10.0)
#: ... lengths (slider coordinates) increased by this fraction (of the characteristic length when 0)
START_FRACTION = 0.10


def add_parser(sub: argparse._SubParsersAction, common: Callable[..., None], scaled: Callable[..., None]) -> None:
    sp = sub.add_parser(NAME, help="one self-contained document (HTML and/or Markdown): topology, counts, equations, "
                                   "Newton iterations, motion, singular configurations with drawings, sweep, view")
    common(sp)
    sp.add_argument("--html", metavar="F.html", help="write the document as one self-contained HTML page")
    sp.add_argument("--md", metavar="F.md", help="write the document as Markdown, its pictures in F_files/ beside it")
    add_configuration_options(sp)
    sp.add_argument("--input", action="append", metavar="NAME",
                    help="input joint (repeat or comma-separate; default: the --set joints, else the actuated ones)")
    sp.add_argument("--sweep", metavar="NAME",
                    help="the input moved for the singular configurations and the sweep plot (default: the only "
                         "input; the others are held at their values)")
    sp.add_argument("--start", action="append", metavar="NAME=VALUE,...",
                    help="planar: the estimates Newton iterates from (as solve --start; default: the solved "
                         "unknowns, angles +10 deg and lengths +10 %%)")
    sp.add_argument("--iterations", type=count("iterations"), metavar="K", help="exactly K Newton iterations (default: to convergence)")
    sp.add_argument("--rate", action="append", metavar="NAME=VALUE", help="input rates (default 1 rad/s or m/s each; the tables in the unit typed: 10rpm, 90deg/s; a bare value "
                         "where there is one input)")
    sp.add_argument("--accel", action="append", metavar="NAME=VALUE", help="input accelerations (default 0; a bare value where there is one input)")
    sp.add_argument("--output", help="output link (its pose and twist; serial singularities; the chain of a serial arm)")
    add_point_option(sp)
    sp.add_argument("--steps", type=count("figure_steps"), default=360,
                    help="steps over the input's range (default 360, at most 20,000)")
    sp.add_argument("--no-view", action="store_true", help="leave the 3D view (headless Chromium) out")


def _writable(path: str | None, option: str) -> None:
    if not path:
        raise UsageError(f"{option} needs a file name")
    check_writable(path, option)


def _report_inputs(mech: Mechanism, args: argparse.Namespace, given: dict[str, float]):
    names = [n.strip() for item in (args.input or []) for n in item.split(",") if n.strip()]
    names = names or list(given) or list(mech.actuated)
    for n in names:
        mech.coordinate(n)  # a usage error when unknown
    extra = [n for n in given if n not in names]
    if extra:
        raise UsageError(f"{mech.path}: --set {', '.join(extra)}: not an input ({', '.join(names)})")
    return names


def _attempt(notes: dict[str, str], what: str, fn: Callable[[], object]):
    """fn() or None, the reason it could not be made kept in notes[what]."""
    try:
        return fn()
    except ScrewkinError as exc:
        notes[what] = str(exc)
        return None


def _check_args(mech: Mechanism, args: argparse.Namespace) -> None:
    """Usage errors before any work: a document to write, writable, and steps and iterations in range."""
    targets = [(p, o) for p, o in ((args.html, "--html"), (args.md, "--md")) if p is not None]
    if not targets:
        raise UsageError(f"{mech.path}: report writes a document: give --html F.html and/or --md F.md")
    for path, option in targets:
        _writable(path, option)
    if args.steps < 4:
        raise UsageError(f"{mech.path}: --steps must be at least 4")
    if args.iterations is not None and args.iterations < 1:
        raise UsageError("--iterations must be 1 or more")


def _rates(mech: Mechanism, args: argparse.Namespace, names: list[str], held: dict[str, float],
           pivots: dict) -> tuple[dict[str, dict], dict[str, float], dict[str, float] | None]:
    """(the --rate and --accel quantities as typed, the input rates (default 1 each), the input accelerations or
    None)."""
    links = (*held, *pivots)
    args.rate, args.accel = (rate_items(getattr(args, o), [*names, *held], f"--{o}") or None for o in ("rate", "accel"))
    typed = {o: joint_quantities(mech, getattr(args, o), f"--{o}", order=k, links=links)
             for k, o in ((1, "rate"), (2, "accel"))}  # the tables answer in the units typed
    rates = link_rates({n: q.value for n, q in typed["rate"].items()}, pivots, "--rate") \
        or {n: 1.0 for n in (*names, *held)}
    accels = link_rates({n: q.value for n, q in typed["accel"].items()}, pivots, "--accel") or None
    check_rate_names(rates, [*names, *held], "--rate")
    check_rate_names(accels, [*names, *held], "--accel")
    return typed, rates, accels


def _solve_configuration(mech: Mechanism, args: argparse.Namespace, values: dict[str, float],
                         near: dict[str, float] | None, given: dict[str, float], held: dict[str, float],
                         rates: dict[str, float], accels: dict[str, float] | None, points: tuple,
                         data: dict) -> tuple[PositionResult, np.ndarray]:
    """The configuration solved for the inputs' ``values``, in the mode analysed (--mode K, chosen and said as
    every command chooses and says it): (its position result, q)."""
    q0 = mech.generic_configurations()[0].q
    solver = input_solver(mech, values, held, output=args.output)
    q, k, n, pres = choose_mode(solver, values, args.mode, near=near if (near or given or held) else
                                mech.joint_values(q0), rates=rates, accels=accels, points=points)
    if n > 1:
        data["mode"] = {"index": k, "of": n}
        print(f"note: {mode_line(k, n)}", file=sys.stderr)
    if pres.free_dofs:  # a continuum: a sample of it, said as choose_mode says it
        data["continuum"] = {"free_dofs": pres.free_dofs}
        print(f"note: {pres.notes[-1]}", file=sys.stderr)
    data["solve"] = position_dict(pres)
    data["solve"]["characteristic_length"] = mech.length  # as solve --json writes it
    return pres, q


def _configuration_text(mech: Mechanism, names: list[str], values: dict[str, float], given: dict[str, float],
                        held: dict[str, float]) -> str:
    """The configuration analysed in words ('crank = 30 deg, angle of coupler = ...')."""
    if not (names or held):
        return "the file's assembled configuration"
    units = {n: ("rad" if not mech.translational[mech.coordinate_names.index(n)] else "m") for n in names}
    return (", ".join([value_label(n, v, units[n]) for n, v in values.items()]
                      + [f"angle of {value_label(k, v, 'rad')}" for k, v in held.items()])
            + ("" if given or held else " (the file's values)"))


def _topology(mech: Mechanism, args: argparse.Namespace, q: np.ndarray, names: list[str], configuration: str,
              topo: Topology, notes: dict[str, str], data: dict) -> Section:
    """The topology section: the counts and mobility, the skeleton at the configuration (and a synthesized
    design's targets), the kinematic chain."""
    mob = _attempt(notes, "mobility", lambda: analyze_mobility(mech, output=args.output, suggest=True))
    if mob is not None:
        data["mobility"] = mobility_dict(mob)
    figures = []
    skel = _attempt(notes, "skeleton", lambda: skeleton(mech, q, names))
    if skel is not None:
        fig = draw_mechanism(skel, title=f"{os.path.basename(str(mech.path))}: {configuration}",
                             subtitle=None if skel.planar else f"schematic projection of a {skel.motion_space} mechanism")
        figures.append(Figure(figure_bytes(fig), "svg", "skeleton diagram at the configuration analysed", "skeleton"))
        if mech.spec.targets:  # a synthesized design: what it was asked to do, as `draw FILE` shows it
            design = _attempt(notes, "targets", lambda: design_drawing(mech, q, names, skel, 360))
            if design is not None:
                marks, curve = design
                fig = draw_mechanism(skel, title=f"{os.path.basename(str(mech.path))}: the design's targets",
                                     traces={} if curve is None else {curve[0]: curve[1]}, marks=marks)
                figures.append(Figure(figure_bytes(fig), "svg", f"the {len(marks)} targets the file states "
                                      "(<screwkin:targets>) and the linkage at each", "targets"))
                data["targets"] = [{k: v for k, v in m.items() if k != "ghost"} for m in marks]
    chain = _attempt(notes, "chain", lambda: kinematic_chain(mech, q, names))
    if chain is not None:
        figures.append(Figure(figure_bytes(draw_chain(chain)), "svg", "kinematic chain: links as nodes, joints as "
                                                                      "edges", "chain"))
    return topology_section(topo, mob, figures)


def _equations(mech: Mechanism, args: argparse.Namespace, q: np.ndarray, names: list[str], held: dict[str, float],
               topo: Topology, notes: dict[str, str], data: dict) -> tuple[VectorLoops | None, object, Section]:
    """(the planar vector loops or None, the equations or None, their section)."""
    loops = eq = None
    if topo.motion_space == "planar":
        loops = _attempt(notes, "equations", lambda: VectorLoops(mech, q, names or None, links=list(held)))
        eq = loops.result() if loops is not None else None
    else:
        output = args.output or (default_output(mech, names[0], q) if names and not mech.cuts else None)
        eq = _attempt(notes, "equations", lambda: equations(mech, q, names, output=output))
    if eq is None:
        return loops, eq, note_section("equations", "Equations", f"no equations: {notes.get('equations')}")
    data["equations"] = equations_dict(eq)
    return loops, eq, equations_section(eq)


def _motion_section(mech: Mechanism, pres: PositionResult | None, typed: dict[str, dict], rates: dict[str, float],
            accels: dict[str, float] | None, points: tuple, data: dict) -> Section:
    """The positions, velocities and accelerations section."""
    if pres is None:
        return note_section("motion", "Positions, velocities and accelerations",
                            "no input joint (none declared actuated, none given with --input or --set): "
                            "nothing to solve for" + (" (the --point values need a solution)" if points else ""))
    given_rates = "input rates " + _input_rates_text(mech, typed["rate"], rates) + \
                  (", input accelerations as given" if accels else ", input accelerations 0")
    rate_units = RateUnits.typed(typed["rate"].values(), typed["accel"].values())  # the units typed
    return motion_section(pres, given_rates, mech.length, rate_units, data.get("mode", {}).get("index", 1))


def _write_markdown(path: str, doc: Document) -> None:
    """The Markdown document and its pictures in ``STEM_files/`` beside it: all or nothing (its pictures, and
    their folder when made here, go when one cannot be written)."""
    stem = os.path.splitext(os.path.basename(path))[0] or "report"
    folder = f"{stem}_files"
    text, files = markdown(doc, folder)
    where = os.path.join(os.path.dirname(path), folder)
    made = not os.path.isdir(where)
    try:
        os.makedirs(where, exist_ok=True)
    except OSError as exc:
        raise OutputError(where, os_reason(exc)) from None
    pictures = []
    try:
        for name, blob in files.items():
            pictures.append(os.path.join(where, name))
            write_output(pictures[-1], blob)
        write_output(path, text.encode("utf-8"))
    except OutputError:
        for picture in pictures:
            remove_partial(picture)
        if made:
            try:
                os.rmdir(where)
            except OSError:
                pass
        raise


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    _check_args(mech, args)
    # --set-angle of a link pinned to the ground is its joint's value; of a floating link (held), one more
    # loop equation: its angle is an input of the positions, the equations and Newton (not of the sweep)
    given, held, pivots = split_inputs(mech, args)
    names = _report_inputs(mech, args, given)
    near = near_values(mech, args)
    q0 = mech.generic_configurations()[0].q
    if args.output:
        mech.link_frame(args.output)
    points = named_points(mech, args)
    typed, rates, accels = _rates(mech, args, names, held, pivots)
    notes: dict[str, str] = {}
    data: dict = {"file": str(mech.path), "screwkin": screwkin_version()}
    # ---- the configuration: solved for the inputs (their file values when none are set)
    pres, q = None, q0
    values = {n: given.get(n, mech.joint_values(q0)[n]) for n in names}
    if names or held:
        pres, q = _solve_configuration(mech, args, values, near, given, held, rates, accels, points, data)
    topo = mech.topology(q)
    configuration = _configuration_text(mech, names, values, given, held)
    data["configuration"] = values
    sections = [_topology(mech, args, q, names, configuration, topo, notes, data)]
    loops, eq, section = _equations(mech, args, q, names, held, topo, notes, data)
    sections.append(section)
    sections.append(_newton(mech, args, loops, q, values, names, notes, data, held))  # from an estimate
    sections.append(_motion_section(mech, pres, typed, rates, accels, points, data))
    sections += _singular_and_sweep(mech, args, q, names, given, eq, notes, data, rates, held,
                                    typed_rates={pivots[k][0] if k in pivots else k: v
                                                 for k, v in typed["rate"].items()})
    sections.append(_view(mech, args, q, data))
    facts = [("file", str(mech.path)), ("screwkin", screwkin_version()), ("configuration", configuration),
             ("inputs", ", ".join(names) or "none"), ("motion space", topo.motion_space)]
    if args.output:
        facts.append(("output", args.output))
    data["notes"] = notes
    doc = Document(f"screwkin report: {os.path.basename(str(mech.path))}", facts, sections, data)
    written = []
    if args.html:
        write_output(args.html, html(doc).encode("utf-8"))
        written.append(args.html)
    if args.md:
        _write_markdown(args.md, doc)
        written.append(args.md)
    if args.json:
        print(json_of({"file": str(mech.path), "written": written, "sections": [s.id for s in sections],
                       "omitted": notes}))
    else:
        for path in written:
            print(f"wrote {path}")
        for what, why in notes.items():
            print(f"note: {what}: {why}")
    return 0


def _input_rates_text(mech: Mechanism, typed: dict, rates: dict) -> str:
    """The input rates as typed (``crank_joint = 10 rpm (1.0472 rad/s)``; ``typed``: joint_quantities of
    --rate), or the default 1 in SI."""
    si = {n: "m/s" if value_kind(mech, n) == "length" else "rad/s" for n in rates}
    if not typed:
        return ", ".join(f"{n} = {v:g} {si[n]}" for n, v in rates.items()) + " (default: 1 each)"

    def shown(n: int, v: float) -> str:
        q = typed.get(n)
        if q is None or q.shown_unit in ("", si[n]):
            return f"{n} = {v:.6g} {si[n]}"
        return f"{n} = {q.text(v)} ({v:.6g} {si[n]})"  # --rate crank=90deg: 90 deg/s

    return ", ".join(shown(n, v) for n, v in rates.items())


def _newton(mech: Mechanism, args: argparse.Namespace, loops: VectorLoops, q: np.ndarray, values: dict, names: list[str], notes: dict[str, str], data: dict, held: dict[str, float] | None=None) -> Section:
    title = "Newton iterations"
    if loops is None:
        why = notes.get("equations") or "the mechanism is not planar: Newton's iterations are shown on the planar " \
                                         "vector-loop equations only (solve --trace shows the closure solver's)"
        return note_section("newton", title, why)
    solved = loops.values(q)
    if args.start:
        typed = parse_typed_assignments(args.start, "--start")
        solver = input_solver(mech, values, held)
        start, _ = start_estimates(mech, loops, solver, solver.set_inputs(q, values), {**values, **(held or {})},
                                   typed)
        how = "from the estimates given with --start: " + ", ".join(f"{n}={q.value}" for n, q in typed)
    else:
        start = {}
        for n in loops.unknowns:
            v = solved[n]
            if loops.symbol_info[n].kind == "angle":
                start[n] = v + START_ANGLE
            else:
                size = abs(v) if abs(v) > mech.tolerances.equal * mech.length else mech.length
                start[n] = v + START_FRACTION * size
        how = (f"from a default estimate: the solved unknowns, each angle +{np.degrees(START_ANGLE):g} deg and each "
               f"length +{100 * START_FRACTION:g} % (of L = {mech.length:.4g} m when 0); give --start NAME=VALUE,... "
               "for other estimates")
    held = {n: solved[n] for n in loops.input_syms}
    res = _attempt(notes, "newton", lambda: textbook_newton(loops, held, start, args.iterations))
    if res is None:  # the mechanism's own (more unknowns than equations: fewer inputs than DOF), said here
        return note_section("newton", title, f"not run: {notes['newton']}")
    far = differing(mech, loops, res.values, solved)
    how += (f". {len(res.steps)} iteration(s) to |F| = {res.residual:.3g} m"
            + ("; the values reached are the solved configuration's" if res.closes and not far else
               f"; the values reached differ from the solved configuration's ({', '.join(far)}: another "
               "assembly mode)" if res.closes else "; the loops are not closed by the last estimates"))
    data["newton"] = newton_dict(res)
    return newton_section(res, loops.symbol_info, how, str(mech.path))


def _singular_and_sweep(mech: Mechanism, args: argparse.Namespace, q: np.ndarray, names: list[str], given: dict[str, float], eq, notes: dict[str, str], data: dict, rates: dict[str, float], held: dict[str, float] | None=None, typed_rates: dict | None = None) -> list:
    conditions = eq.singular_conditions if hasattr(eq, "det_A") else ()  # planar: det A = 0 where
    moved = args.sweep or (names[0] if len(names) == 1 else None)
    if moved is None:
        why = ("no input joint: nothing to move" if not names else
               f"{len(names)} inputs ({', '.join(names)}): give --sweep NAME to move one of them, the others held")
        return [note_section("singular", "Singular configurations", f"not located: {why}"),
                note_section("sweep", "Sweep of the input", f"no sweep: {why}")]
    search = _attempt(notes, "singular configurations", lambda: singular_configurations(
        mech, moved, output=args.output, q=q, steps=args.steps,
        fixed={k: v for k, v in given.items() if k != moved}, near=mech.joint_values(q),
        rate=rates.get(moved) or 1.0, held=held))  # the positions section's input rate (a rate 0 gives no strokes: 1)
    if search is None:
        why = notes["singular configurations"]
        return [note_section("singular", "Singular configurations", f"not located: {why}"),
                note_section("sweep", "Sweep of the input", f"no sweep: {why}")]
    figures, descriptions, found = [], [], []
    base = os.path.basename(str(mech.path))
    for k, s in enumerate(search.found, 1):
        at = value_label(search.input, wrapped_value(s.input, search.unit), search.unit)
        what = singularity_kind_text(s)
        skel = skeleton(mech, s.q, [search.input, *search.fixed])
        fig = draw_mechanism(skel, title=f"{base}: singular configuration {k} of {len(search.found)} at {at}",
                             subtitle=what)
        figures.append(Figure(figure_bytes(fig), "svg", f"singular configuration {k}: {what} at {at}", "singular"))
        descriptions.append(what)
        found.append({"kind": s.kind, "limit": s.limit, "output": s.output, "input": s.input, "sigma": s.sigma,
                      "description": what})
    data["singular_configurations"] = {"input": search.input, "unit": search.unit, "range": [search.start, search.stop],
                                       "output": search.output, "found": found}
    out = [singular_section(search, figures, descriptions, conditions)]
    res = search.motion
    mus = None
    info = identify(mech, mech.topology(q), q, moved)
    if info is not None:
        mus = transmission_angles(mech, info, res.q).tolist()
    motion = sweep_motion(mech, res, named_points(mech, args))  # what sweep shows: links, loop joints, points
    # each slider's ends located on the mechanism, with the inputs the search held (as figures does)
    ins = ([moved, *(k for k in given if k != moved)] if held else
           list(mech.actuated) if moved in mech.actuated else [moved])
    slider_strokes = strokes(res, motion, mech, input_solver(mech, ins, held))
    # the rates as typed (--rate crank=120rpm: "at crank 120 rpm", omega in rpm and alpha in rpm/s), as the
    # positions section shows them; the default 1 rad/s (or a rate 0, moved at 1): per 1 rad/s of the input
    typed_rates = typed_rates or {}
    typed_moved = typed_rates.get(moved) if rates.get(moved) else None
    rate_words = input_rate_words(moved, typed_moved, bool(mech.translational[mech.coordinate(moved).idx_v]))
    units = RateUnits.typed(typed_rates.values()) if typed_rates else None
    fig = motion_figure(res, mus, singularities=search.found, linear=mech.translational, motion=motion,
                        title=f"{base}: {moved} over its range, {rate_words}", rate_words=rate_words, units=units)
    what = ("the links' absolute angle, omega and alpha and the slider coordinates" if absolute_series(
        res, motion, mech.translational) is not None else "joint values, rates and accelerations")
    out.append(sweep_section(search, Figure(figure_bytes(fig), "svg", f"{what} against {moved}", "sweep"),
                             strokes_text(slider_strokes, res.unit == "rad"), rate_words))
    data["sweep"] = {"input": moved, "steps": len(res.values) - 1, "values": res.values, "names": list(res.names),
                     "coordinates": list(res.names), "joints": res.joints, "rates": res.rates,
                     "accelerations": res.accelerations,
                     "input_rate": res.rate, **motion_dict(motion), "strokes": strokes_dict(slider_strokes)}
    return out


def _view(mech: Mechanism, args: argparse.Namespace, q: np.ndarray, data: dict) -> Section:
    if args.no_view:
        return view_section(None, "the view is left out (--no-view)")
    if chromium() is None:
        data["view"] = False
        return view_section(None, "no view: headless Chromium is not installed (Debian: apt-get install chromium); "
                                  "screwkin view FILE shows the mechanism in meshcat")
    try:
        scene = build_scene(mech, q, output=args.output)
        with ViewerServer() as server, tempfile.TemporaryDirectory() as d:
            show(mech, scene, server.viewer, q)
            path, png = os.path.join(d, "scene.html"), os.path.join(d, "scene.png")
            with open(path, "w") as f:
                f.write(page(server.viewer.static_html(), scene, os.path.basename(str(mech.path)), controls=False,
                             size=PICTURE))
            screenshot(path, png)
            with open(png, "rb") as f:
                blob = f.read()
    except (ScrewkinError, OSError, RuntimeError) as exc:  # the view is an extra: the document goes on without it
        data["view"] = False
        return view_section(None, f"no view: {exc}")
    data["view"] = True
    return view_section(blob)
