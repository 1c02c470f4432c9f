"""Turning results into text tables, JSON-ready dictionaries and CSV (the edge).

Analysis results (screwkin.analysis) are plain data; this is the one place that knows
how they are written out, for the command line and for ``screwkin.to_dict``.
"""

from __future__ import annotations

import numpy as np

from ..analysis.singularities.maps import SingularityMap
from ..analysis.mobility import MobilityResult
from ..analysis.motion.planar import LinkageInfo
from ..analysis.position.modes import continuum_words
from ..analysis.position.solution import NEWTON_FROM_FILE, PositionResult, search_method
from ..analysis.singularities.scan import ScanResult
from ..analysis.screws import Screw
from ..analysis.singular import SingularityReport
from ..analysis.motion.sweep import SweepResult, SweepSingularity
from ..model.topology import Topology
from ..units import in_unit
from .motion import linkage_construction_text, links_table, points_table
from .screws import screw_dict
from .tables import RateUnits, column_text, csv_text, table
from .tables import fmt_vec as _fmt_vec
from ..tolerances import DEFAULT
from .numtext import csv_rows
from .jsonout import to_jsonable
from .mobility import mobility_dict, topology_dict
from .singular import singularity_dict
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.position.solution import Solution

__all__ = ["to_dict", "position_dict", "position_text", "modes_dict", "modes_line", "joint_types_dict", "joint_types_text", "sweep_dict", "sweep_csv", "sweep_text",
           "scan_dict", "scan_csv", "map_csv", "slide_note"]


def position_dict(res: PositionResult) -> dict:
    sols = []
    for s in res.solutions:
        # every coordinate under its name, loop joints too (also kept apart under "loop_joints")
        d = {"joints": _with_loop(s.joints, s.loop_joints), "residual": s.residual, "iterations": s.iterations, "singular": s.singular,
             "sigma_min": s.sigma_min, "outside_limits": list(s.outside_limits),
             "physical": s.physical, "labels": list(s.labels), "continuum": s.continuum, "merged": s.merged,
             "simple": s.simple, "angle_sets": s.angle_sets}
        if s.sigmas is not None:
            d["sigmas"] = s.sigmas
        if s.link_angles is not None:
            d["link_angles"] = s.link_angles
        if s.coupled:
            d["coupled_joints"] = s.coupled
        if s.loop_joints:
            d["loop_joints"] = s.loop_joints
            if s.loop_rates is not None:
                d["loop_rates"], d["loop_accelerations"] = s.loop_rates, s.loop_accelerations
        if s.links:
            d["links"] = s.links
        if s.points:
            d["points"] = s.points
        if s.leg_lengths:
            d["leg_lengths"] = s.leg_lengths
        if s.guide_angles:
            d["guide_angles"] = s.guide_angles
        if s.guide_positions:
            d["guide_positions"] = s.guide_positions
        if s.linkage:
            d["four_bar" if s.linkage["kind"] == "four-bar" else "slider_crank"] = s.linkage
        if s.output_pose is not None:
            d["output_pose"] = s.output_pose.tolist()
            d["output_position"] = s.output_position.tolist()
            d["output_rpy"] = s.output_rpy.tolist()
        if s.rates is not None:
            d["rates"] = _with_loop(s.rates, s.loop_rates)
            d["accelerations"] = _with_loop(s.accelerations, s.loop_accelerations)
        if s.output_twist is not None:
            d["output_twist"] = s.output_twist.tolist()
            d["output_acceleration"] = s.output_acceleration.tolist()
        sols.append(d)
    return {"inputs": res.inputs, "input_joints": list(res.input_joints), "output": res.output,
            "free_dofs": res.free_dofs, "starts": res.starts, "solutions": sols,
            "physical_solutions": sum(s.physical for s in res.solutions), "notes": list(res.notes),
            **({"held_angles": res.held} if res.held else {}), **({"modes": modes_dict(res.modes)} if res.modes else {}),
            # how the solutions were found, and whether they are every mode there is
            "method": res.method or search_method(res.modes),
            "complete": bool(res.modes is not None and res.modes.complete)}


def modes_dict(c) -> dict:
    """analysis.position.certified.ModeCount as JSON: found, complete, method, real, complex, certificate,
    reason (null when certified) and what the search did."""
    return {"found": c.found, "complete": c.complete, "method": c.method, "real": c.real, "complex": c.complex,
            "certificate": c.certificate, "reason": c.reason or None, "search": dict(c.detail),
            "certificate_check": dict(c.check) or None}


def modes_line(res: PositionResult, n: int) -> str:
    """How many assembly modes, and how that is known: "all 4 assembly modes (certified: trace test);
    36 more solutions are complex", or "3 found ...; completeness not certified because ..."."""
    c = res.modes
    s = "s" if n != 1 else ""
    if res.free_dofs:  # a continuum: what was found are samples of it, not modes to count
        return (f"{n} configuration{s} found from {res.starts} starting configurations: "
                f"{continuum_words(res.free_dofs)}: they are samples of it, not assembly modes")
    if c is None:
        return f"{n} assembly mode{s} found from {res.starts} starting configurations"
    if c.method == "every joint given":
        return "1 configuration, the one the values give: every joint given, nothing solved or searched"
    if c.method == NEWTON_FROM_FILE:
        return ("1 assembly mode: the one Newton reaches from the file's configuration (no search; --all lists "
                "every mode, with how complete the list is)")
    sets = {x.angle_sets for x in res.solutions}
    each = (f"; each reached by {sets.pop()} joint-angle sets (universal and spherical joints written as "
            "revolutes, wrists flipped: one placement of the links)" if len(sets) == 1 and None not in sets
            and max(sets) > 1 else "")
    if c.method == "closed form (Pieper)":  # a serial arm: every joint solution is an answer
        more = f"; {c.complex} more {'are' if c.complex != 1 else 'is'} complex (no real solution)" if c.complex else ""
        return f"all {n} joint solution{s} ({c.certificate}){more}"
    if c.method == "closed form (legs)":
        return (f"{n} solution{s} of {c.found} listed ({c.certificate}): the physical one first (every leg extended, "
                "each leg's angle set within the joint limits where one exists), then "
                + ("every other combination of the legs' branches" if c.found == n else "each leg's other branch"))
    kept = c.detail.get("generic_set")
    kept = (f"; generic solution set {'reused from' if c.detail.get('generic_set_reused') else 'kept in'} {kept}"
            if kept else "")
    if c.complete:
        more = (f"; {c.complex} more solution{'s are' if c.complex != 1 else ' is'} complex (no real assembly)"
                if c.complex else "")
        head = f"all {n} assembly modes" if n != 1 else "1 assembly mode, the only one"
        return f"{head} (certified: {c.certificate}){more}{each}{kept}"
    how = (f"from {res.starts} starting configurations" if c.method == "random starts" else
           f"by homotopy continuation and from {res.starts} starting configurations")
    more = f"; {c.complex} more solution{'s are' if c.complex != 1 else ' is'} complex" if c.complex else ""
    return f"{n} assembly mode{s} found {how}{more}; completeness not certified because {c.reason}{each}{kept}"


def _with_loop(tree: dict, loop: dict | None) -> dict:
    """Tree coordinates, then the loop joints' (one dict, as the user names them)."""
    return {**tree, **{k: v for k, v in (loop or {}).items() if k not in tree}}


def value_text(name: str | int, value: float, angular: bool) -> str:
    """A coordinate value in its own unit: angles in rad and deg, lengths in m."""
    if angular:
        return f"{value:.9g} rad ({np.degrees(value):.8g} deg)"
    return f"{value:.9g} m"


def trace_text(res: PositionResult, row_labels: list, passive_names: list) -> str:
    lines = ["Newton iterations from the first start (rows: closure residual; columns: passive joints)"]
    for st in res.trace:
        lines.append(f"\niteration {st.iteration}: |r| = {np.linalg.norm(st.residual):.3e}"
                     f"{'' if st.accepted else '  (step rejected: damping increased)'}")
        lines.append("  r  = [" + _fmt_vec(st.residual) + " ]")
        lines.append("  K  = " + " ".join(f"{n:>11.11}" for n in passive_names))
        for lab, row in zip(row_labels, st.jacobian):
            lines.append(f"       {_fmt_vec(row)}   {lab}")
        lines.append("  dq = [" + _fmt_vec(st.step) + " ]")
    return "\n".join(lines)


def solution_rows(res: PositionResult, s: Solution, degrees: bool = True, units: RateUnits = RateUnits()) -> tuple:
    """(headers, rows) of one solution's coordinates -- every tree joint, then every loop (cut) joint
    as ``NAME (loop)`` -- with value [rad or m], the angle in deg (a slide not along the ground's x
    axis: its guide's angle), rate and acceleration when solved with rates, in ``units`` (those typed
    with --rate/--accel; SI by default).  The one joint table of ``solve``'s text and ``report``'s
    document."""
    rows = []
    guides = {n: a for n, a in (s.guide_angles or {}).items()  # a slide not along the ground's x axis
              if abs(np.sin(a)) > DEFAULT.equal}

    placed = s.guide_positions or {}

    def along(name: str) -> str:
        where = f"d = {placed[name]:.9g} m" if name in placed else ""
        at = f"along the guide at {np.degrees(guides[name]):.6g} deg" if name in guides else ""
        return ", ".join(w for w in (where, at) if w)

    rates, accs = [], []
    for name, v in s.joints.items():
        row = [name, f"{v:.9g}"]
        row.append(f"{np.degrees(v):.6g} deg" if degrees and name in res.angular else along(name))
        rows.append(row)
        if s.rates is not None:
            linear = name not in res.angular
            rates.append(in_unit(s.rates.get(name, float("nan")), units.rate(linear)))
            accs.append(in_unit(s.accelerations.get(name, float("nan")), units.acceleration(linear)))
    for name, v in (s.loop_joints or {}).items():  # the loop (cut) joints' coordinates, as the tree's
        row = [f"{name} (loop)", f"{v:.9g}"]
        row.append(f"{np.degrees(v):.6g} deg" if degrees and name in res.angular_loop else along(name))
        rows.append(row)
        if s.rates is not None:
            linear = name not in res.angular_loop
            rates.append(in_unit(s.loop_rates[name], units.rate(linear)) if s.loop_rates else float("nan"))
            accs.append(in_unit(s.loop_accelerations[name], units.acceleration(linear))
                        if s.loop_accelerations else float("nan"))
    if s.rates is not None:  # round-off (a loop joint's 4e-16 rad/s) written as 0
        rows = [row + [r, a] for row, r, a in zip(rows, column_text(rates), column_text(accs))]
    slides = any(name not in res.angular for name in s.joints) or any(
        name not in res.angular_loop for name in (s.loop_joints or {}))
    headers = ["joint", "value [rad or m" + ("*]" if slides else "]"), "(deg" + (", d*)" if placed else ")")] + (
        [f"rate [{units.rate(False)} or {units.rate(True)}]",
         f"acceleration [{units.acceleration(False)} or {units.acceleration(True)}]"] if s.rates is not None else [])
    return headers, rows


def slide_note(res: PositionResult, s: Solution) -> str | None:
    """The footnote of a joint table with slides: what a slide's value is measured from, and its ``d``."""
    if all(n in res.angular for n in s.joints) and all(n in res.angular_loop for n in (s.loop_joints or {})):
        return None
    note = "* a slide's value is measured from where the file placed its joint"
    if s.guide_positions:
        note += ("; d is the slider's position along its guide (on the ground) from the foot of the perpendicular "
                 "from the world origin: the slider distance of a slider-crank whose crank pivots at the origin")
    return note


def position_text(res: PositionResult, degrees: bool=True, show_all: bool=False, length: float | None=None, units: RateUnits = RateUnits(),
                  leg_lengths: dict | None = None) -> str:
    """The solutions of a position analysis; without ``show_all`` only the physically meaningful
    ones (no labels) when there are any, with a line saying how many more exist; rates and
    accelerations in ``units`` (those typed with --rate/--accel); ``leg_lengths``: the inputs given
    as leg lengths (--set-length), said as typed beside the joint's value."""
    legs = leg_lengths or {}

    def given(k: int, v) -> str:
        text = value_text(k, v, k in res.angular)
        return f"{k} = {legs[k]:.9g} m long (joint {text})" if k in legs else f"{k} = {text}"

    inputs = ", ".join([given(k, v) for k, v in res.inputs.items()
                        if isinstance(v, float)] + [f"angle of {k} = {value_text(k, v, True)}"
                                                    for k, v in (res.held or {}).items()])
    shown = list(res.solutions) if show_all else [s for s in res.solutions if s.physical] or list(res.solutions)
    hidden = len(res.solutions) - len(shown)
    n = len(res.solutions)
    lines = [f"inputs: {inputs}" if inputs else "inputs: -",
             modes_line(res, n) + (f"; measures dimensionless with L = {length:.4g} m" if length else "")]
    if hidden:
        why = sorted({lab.split(":")[0].split(" (")[0] for s in res.solutions if not s.physical for lab in s.labels})
        lines.append(f"of the {n}, {n - hidden} reachable by moving from the drawn configuration and shown; "
                     f"{hidden} not ({'; '.join(why)}): --all shows them")
    for note in res.notes:
        lines.append(f"note: {note}")
    for k, s in enumerate(shown, 1):
        if s.continuum:
            flag = ("  SINGULAR: these inputs leave a finite motion (a continuum of configurations"
                    + (f"; {s.merged} solver results lie on it, one is shown)" if s.merged > 1 else ")"))
        elif s.singular:
            flag = "  SINGULAR (passive joints not determined: limit position or singularity" + (
                f"; a double root, reached {s.merged} ways)" if s.merged > 1 else ")")
        elif s.simple and s.sigma_min < DEFAULT.singular:
            flag = (f"  ill-conditioned (condition number {1.0 / max(s.sigma_min, 1e-300):.3g}): a simple root, "
                    "the passive joints are determined")
        else:
            flag = ""
        sets = f", {s.angle_sets} joint-angle sets" if s.angle_sets and len({x.angle_sets for x in res.solutions}) > 1 else ""
        lines.append(f"\nsolution {k}: residual {s.residual:.2e}, {s.iterations} iterations, "
                     f"sigma_min {s.sigma_min:.3g}{sets}{flag}")
        for lab in s.labels:
            lines.append(f"  not reached by moving: {lab}")
        lines.append(table(*solution_rows(res, s, degrees, units)))
        note = slide_note(res, s)
        if note:
            lines.append(note)
        if s.coupled:
            lines.append("coupled (mimic) joints: " + ", ".join(
                f"{n} = {v:.9g}" + (f" ({np.degrees(v):.6g} deg)" if n in res.angular_coupled else "")
                for n, v in s.coupled.items()))
        if s.link_angles and not s.links:
            lines.append("link angles (absolute, in the plane from the ground's x axis): " + ", ".join(
                f"{n} {np.degrees(a):.6g} deg" for n, a in s.link_angles.items()))
        if s.links and any("angle" in m or "omega" in m for m in s.links.values()):
            lines.append(links_table(s.links, units))
        if s.points:
            lines.append(points_table(s.points, units))
        if s.linkage:
            lines.append(linkage_construction_text(s.linkage))
        if s.leg_lengths:
            lines.append("leg lengths (between the joint centres each prismatic joint connects): " + ", ".join(
                f"{n} {v:.9g} m" for n, v in s.leg_lengths.items()))
        if s.output_pose is not None:
            p = s.output_pose
            lines.append(f"output '{res.output}' position {_fmt_vec(p[:3, 3], 0)} m, roll pitch yaw "
                         f"{_fmt_vec(np.degrees(s.output_rpy), 0)} deg")
            lines.append("  rotation " + " | ".join(_fmt_vec(r, 0) for r in p[:3, :3]))
        if s.output_twist is not None:
            lines.append(f"  twist (v, w) {_fmt_vec(s.output_twist, 0)}")
            lines.append(f"  acceleration (a, alpha) {_fmt_vec(s.output_acceleration, 0)}")
    return "\n".join(lines)


def sweep_rows(n: int, rows: str | None=None) -> list:
    """The steps a sweep's tables show: ``rows`` None -> about 11 evenly spaced (the last included),
    "all" -> every step, a number -> about that many."""
    if rows == "all":
        return list(range(n))
    want = 11 if rows is None else max(int(rows), 2)
    if n <= want:
        return list(range(n))
    idx = sorted(set(np.linspace(0, n - 1, want).round().astype(int).tolist()))
    return idx


def sweep_text(res: SweepResult, info: LinkageInfo | None = None, mus: list | None = None, rows: str | None=None, degrees: bool = False, linear_names: list=()) -> str:
    """The sweep's summary and a table of joint values (``rows``: see sweep_rows; ``degrees``: the
    input and the angles in deg, the coordinates in ``linear_names`` staying in m)."""
    angular = res.unit == "rad"
    linear = set(linear_names or ())
    lines = [f"sweep of {res.input} from {value_text(res.input, res.requested[0], angular)} to "
             f"{value_text(res.input, res.requested[1], angular)} in {res.requested[2]} steps"
             + (", through limit positions (--turn)" if res.turn else "") + f": {len(res.values)} configurations"]
    for lim in res.limits:
        lines.append(f"limit position at {res.input} = {value_text(res.input, lim.input, angular)} "
                     f"(relative sigma {lim.sigma:.2g})" + ("; the motion turns back there" if res.turn else ""))
    if res.circuit_closed:
        lines.append("the motion came back to its starting configuration: the whole circuit is traced")
    if res.stopped_at is not None:
        lines.append(f"stopped at {res.input} = {value_text(res.input, res.stopped_at, angular)}: {res.stop_reason}")
    if res.skipped:
        lo, hi = min(res.skipped), max(res.skipped)
        lines.append(f"not solved at {len(res.skipped)} input value{'s' if len(res.skipped) > 1 else ''} the motion "
                     f"passed ({value_text(res.input, lo, angular)} .. {value_text(res.input, hi, angular)}): "
                     "they are left out of the tables, and the sweep is not complete")
    if info is not None:
        lines.append(f"{info.kind}: " + ", ".join(f"{k} {v:.6g} m" for k, v in info.lengths.items()))
        lines.append(f"  {info.grashof}")
        if info.input_range:
            lo, hi = info.input_range
            lines.append(f"  input range: {lo:.6g} .. {hi:.6g} rad ({np.degrees(lo):.4g} .. {np.degrees(hi):.4g} deg)")
        else:
            lines.append("  input range: full turn")
        if info.limit_inputs:
            lines.append("  output limit positions at input = " + ", ".join(
                f"{x:.6g} rad ({np.degrees(x):.4g} deg)" for x in info.limit_inputs))
        tr = info.transmission
        if tr is not None:
            at = ", ".join(f"{np.degrees(x):.6g} deg" if degrees else f"{x:.6g} rad" for x in tr.low_at + tr.high_at)
            dead = (f"; {tr.dead_points} dead point{'s' if tr.dead_points != 1 else ''} (mu = 0 or 180 deg)"
                    if tr.dead_points else "; no dead point")
            lines.append(f"  transmission angle over the input's whole motion (located in closed form): "
                         f"{np.degrees(tr.low):.6g} .. {np.degrees(tr.high):.6g} deg (at input {at}); largest "
                         f"|90 deg - mu| {np.degrees(tr.deviation):.6g} deg{dead}")
        if mus:
            dev = np.abs(np.degrees(np.asarray(mus)) - 90)
            k = int(np.argmax(dev))
            lines.append(f"  transmission angle along this sweep: {np.degrees(min(mus)):.4g} .. {np.degrees(max(mus)):.4g} deg; "
                         f"worst {np.degrees(mus[k]):.4g} deg at input "
                         + (f"{np.degrees(res.values[k]):.6g} deg" if degrees else f"{res.values[k]:.6g} {res.unit}"))
    shown = sweep_rows(len(res.values), rows)
    n = len(res.values)
    x = np.degrees(res.values) if degrees else np.asarray(res.values)
    cols = [column_text([np.degrees(res.joints[k][j]) if degrees and name not in linear else res.joints[k][j]
                         for k in shown], absolute=1e-9) for j, name in enumerate(res.names)]
    body = [[f"{x[k]:.6g}"] + [c[i] for c in cols] for i, k in enumerate(shown)]
    lines.append("")
    lines.append(f"joint values at {len(shown)} of the {n} configurations"
                 + ("" if len(shown) == n else " (--rows all shows every one, --rows N about N)")
                 + (": angles in deg" if degrees else ""))
    lines.append(table([f"input [{'deg' if degrees else res.unit}]"] + list(res.names), body))
    return "\n".join(lines)


# ------------------------------------------------------------------ results as dictionaries
def linkage_dict(info: LinkageInfo) -> dict:
    d = {"kind": info.kind, "lengths": info.lengths, "grashof": info.grashof, "input_joint": info.input_joint,
         "input_range": list(info.input_range) if info.input_range else None,
         "limit_inputs": list(info.limit_inputs), "transmission_angle": info.transmission_angle}
    tr = info.transmission
    if tr is not None:  # over the input's whole motion, located in closed form (analysis.motion.transmission)
        d["transmission_range"] = {"min": tr.low, "max": tr.high, "min_at": list(tr.low_at), "max_at": list(tr.high_at),
                                   "deviation": tr.deviation, "turns": tr.turns, "dead_points": tr.dead_points,
                                   "dead_at": list(tr.dead_at), "how": "located in closed form"}
    return d


def sweep_singularity_dict(s: SweepSingularity, mech: Mechanism | None=None) -> dict:
    d = {"kind": s.kind, "input": s.input, "sigma": s.sigma, "limit": s.limit}
    if mech is not None:
        d["joints"] = mech.joint_values(s.q)
    return d


def sweep_dict(res: SweepResult, mech: Mechanism | None=None) -> dict:
    return {
        "input": res.input, "input_unit": res.unit,
        "from": res.requested[0], "to": res.requested[1], "steps": res.requested[2],
        "completed": res.completed, "skipped": list(res.skipped),
        "stopped_at": res.stopped_at, "stop_reason": res.stop_reason,
        "turn": res.turn, "circuit_closed": res.circuit_closed,
        "method": res.method, "notes": list(res.notes),
        "singularities": [sweep_singularity_dict(s, mech) for s in res.limits],
        "coordinates": list(res.names),
        "values": res.values.tolist(),
        "joints": res.joints.tolist(),
        "rates": res.rates.tolist(),
        "accelerations": res.accelerations.tolist(),
        **({"coupled_joints": {k: v.tolist() for k, v in res.coupled.items()}} if res.coupled else {}),
    }


def sweep_columns(res: SweepResult, motion=None) -> tuple:
    """(header, columns): the input, every joint value, rate and acceleration, the coupled joints; with
    ``motion`` (analysis.motion.links.MotionAlong) the loop joints, each link's absolute angle (planar) and
    each named point's x, y, z [m].  Columns are float arrays, one value per step (the step number
    is not among them)."""
    coupled = res.coupled or {}
    head = [res.input + "_input"] + list(res.names) + [f"d_{n}" for n in res.names] + [
        f"dd_{n}" for n in res.names] + list(coupled)
    n = len(res.values)
    cols = [np.asarray(res.values, float)]
    for M in (res.joints, res.rates, res.accelerations):
        M = np.asarray(M, float).reshape(n, -1)
        cols += [M[:, i] for i in range(M.shape[1])]
    cols += [np.asarray(v, float) for v in coupled.values()]
    if motion is not None:
        for name, v in motion.loop_joints.items():
            head += [f"{name} (loop)", f"d_{name} (loop)", f"dd_{name} (loop)"]
            cols += [np.asarray(x, float) for x in (v, motion.loop_rates[name], motion.loop_accelerations[name])]
        for name, m in motion.links.items():
            if "angle" in m:
                head += [f"{name} angle", f"{name} omega", f"{name} alpha"]
                cols += [np.asarray(m[k], float) for k in ("angle", "omega", "alpha")]
        for name, p in motion.points.items():
            P = np.asarray(p["position"], float)
            head += [f"{name} {ax}" for ax in "xyz"]
            cols += [P[:, i] for i in range(3)]
    return head, cols


def sweep_csv(res: SweepResult, motion=None, first_step: int = 0, header: bool = True) -> str:
    """One row per step (see :func:`sweep_columns`), numbered from ``first_step``, every value with 12
    significant digits; ``header`` False: the rows alone (a chunk of a streamed sweep)."""
    head, cols = sweep_columns(res, motion)
    top = csv_text(["step"] + head, []) if header else ""
    if not len(res.values):
        return top
    return top + csv_rows(cols, first_step)  # the text of "%d,%.12g,...\n" % row, built in numpy


def scan_dict(res: ScanResult) -> dict:
    k = res.worst
    a = np.abs(res.values)
    return {
        "output": res.output, "joints": list(res.joints), "samples": res.samples, "seed": res.seed,
        "measure": res.measure, "length": res.length if res.measure == "sigma_ratio" else None,
        "point": res.point, "threshold": res.threshold,
        "min": float(res.values[k]), "min_configuration": dict(zip(res.joints, map(float, res.theta[k]))),
        "max": float(res.values[int(np.argmax(a))]),
        "percentiles": {p: float(np.percentile(a, float(p))) for p in ("1", "5", "50")},
        "singular_fraction": res.singular_fraction(),
    }


def scan_csv(res: ScanResult) -> str:
    rows = np.column_stack([res.theta, res.values])
    return csv_text([*res.joints, res.measure], ([f"{x:.12g}" for x in row] for row in rows))


def map_dict(res: SingularityMap) -> dict:
    """A map as JSON: cells off the mapped branch are null in log10_sigma_min and false in
    ``reached``; ``notes`` says where the continuation stopped; ``seams`` lists the neighbouring
    cells [[j, i, j2, i2], ...] (row j: ys[j], column i: xs[i]) on different sheets of the mode."""
    reached = res.reached if res.reached is not None else np.isfinite(res.log_sigma)
    seams = res.seams.tolist() if res.seams is not None else []
    return {"x": res.x_name, "y": res.y_name, "xs": res.xs, "ys": res.ys,
            "log10_sigma_min": res.log_sigma, "kind": res.kind, "reached": reached,
            "off_branch": int(reached.size - reached.sum()), "seams": seams, "notes": list(res.notes)}


def map_csv(res: SingularityMap) -> str:
    rows = ([f"{x:.12g}", f"{y:.12g}", f"{res.log_sigma[j, i]:.6g}" if np.isfinite(res.log_sigma[j, i]) else "",
             res.kind[j, i]] for j, y in enumerate(res.ys) for i, x in enumerate(res.xs))
    return csv_text([res.x_name, res.y_name, "log10_sigma_min", "kind"], rows)


_DICTS = {MobilityResult: mobility_dict, PositionResult: position_dict, SingularityReport: singularity_dict,
          SweepResult: sweep_dict, SweepSingularity: sweep_singularity_dict, ScanResult: scan_dict,
          LinkageInfo: linkage_dict, Screw: screw_dict, SingularityMap: map_dict, Topology: topology_dict}


def to_dict(result) -> dict:
    """What ``--json`` prints for a result of screwkin's analyses, as plain Python (numbers, strings,
    lists, dictionaries) by the one rule of present/jsonout.py: an infinite number as "inf" or "-inf",
    a value that does not exist (NaN) as None."""
    for cls, fn in _DICTS.items():
        if isinstance(result, cls):
            return to_jsonable(fn(result))
    raise TypeError(f"no dictionary form for {type(result).__name__}")


# ------------------------------------------------------------------ the joint vocabulary
def joint_types_dict(types: tuple) -> list:
    """``info --joint-types --json``: one object per kinematic pair screwkin knows."""
    return [{"name": t.name, "symbol": t.symbol, "dof": t.dof, "motion": t.motion, "pair": t.pair,
             "contact": t.contact, "type": t.type, "written": t.written} for t in types]


def joint_types_text(types) -> str:
    """``info --joint-types``: the table of kinematic pairs."""
    rows = [(t.name, t.symbol, t.dof, t.pair, t.contact, t.motion) for t in types]
    return ("Joint types screwkin knows (DOF of the relative motion; the higher pairs' in their plane):\n"
            + table(["joint", "symbol", "DOF", "pair", "contact", "motion"], rows)
            + "\n\n" + table(["joint", "written in a file as (docs/format.md)"], [(t.name, t.written) for t in types]))
