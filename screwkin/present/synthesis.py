"""Synthesis results as JSON-ready dictionaries and readable text.

Every kind has the same core (the contract of issue 14): ``kind``, ``file``, ``links`` (link
name -> dimensions), ``pivots``, ``precision`` (each precision position or point with
``reached`` and ``residual``), ``grashof``, ``transmission_angle_range`` [deg], ``defects``
(strings, empty when none) and ``valid``; each kind adds its own keys beside them.  Numbers
stay SI (m, rad) in the results; keys ending in ``_deg`` and the text give degrees.
Function generation's precision entries add ``as_typed``: x, phi, psi asked and psi reached in the
angles of --input-range/--output-range (``target``/``value`` keep the file's rocker-frame angle).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from ..analysis.design.synthesis.designs import ChainsResult, Check, FunctionResult, MotionResult, PathResult
from ..analysis.design.synthesis.chains import guides_of
from ..model.geometry import wrap_angle
from ..analysis.design.synthesis.fourbar import PIVOT_JOINTS, tool_local
from .jsonout import to_jsonable
from .tables import shown_text, table
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.design.synthesis.designs import Candidate
    from screwkin.analysis.design.synthesis.designs import Design
    from screwkin.analysis.design.synthesis.designs import Dyad
    from screwkin.analysis.design.synthesis.designs import Target
    from collections.abc import Sequence

__all__ = ["synthesis_dict", "synthesis_text", "chains_dict", "chains_text"]


def _deg(x: float | None) -> float | None:
    """Degrees; None where there is no value (None, or NaN: the linkage does not assemble there)."""
    return None if x is None or x != x else math.degrees(x)


def _pt(p: tuple) -> list:
    return [float(p[0]), float(p[1])]


def _target_dict(t: Target) -> dict:
    if t.kind == "pose":
        return {"x": t.value[0], "y": t.value[1], "theta_deg": _deg(t.value[2])}
    if t.kind == "point":
        return {"x": t.value[0], "y": t.value[1]}
    return {"psi_deg": _deg(t.value[0])}


def _value_dict(kind: str, v: tuple) -> dict | None:
    if not v:
        return None
    if kind == "pose":
        return {"x": v[0], "y": v[1], "theta_deg": _deg(v[2])}
    if kind == "point":
        return {"x": v[0], "y": v[1]}
    return {"psi_deg": _deg(v[0])}


def _core(kind: str, design: Design, check: Check, file: str) -> dict:
    fb = design.fourbar
    L = fb.lengths
    links = {"ground": {"length": L["ground"]}, "crank": {"length": L["crank"]},
             "coupler": {"length": L["coupler"]}, "rocker": {"length": L["rocker"]}}
    if fb.tool is not None:
        u, v, gamma = tool_local(fb)
        what = "frame" if kind == "motion" else "point"
        links["coupler"][what] = {"x": u, "y": v, **({"angle_deg": _deg(gamma)} if kind == "motion" else {})}
    precision = []
    for p in check.precision:
        d = {"label": p.target.label, "target": _target_dict(p.target), "input_deg": _deg(p.target.input),
             "reached": p.reached, "residual": p.residual, "value": _value_dict(p.target.kind, p.value),
             "error": p.error, "closed_form_error": p.closed_form_error}
        if p.target.kind == "pose":
            d["angle_error_deg"] = _deg(p.angle_error)
        if p.target.kind == "angle":
            d["error_deg"] = _deg(p.error)
        precision.append(d)
    mu = check.transmission_range
    finite = [p.error for p in check.precision if math.isfinite(p.error)]
    point = None
    if fb.tool is not None:  # the guided frame's origin, or the tracer, as --point takes it: on the coupler link
        u, v, _ = tool_local(fb)
        point = f"{'P' if kind == 'path' else 'F'}={'coupler'}:{u!r},{v!r},0"
    return {
        "input": design.input_joint,
        "point": point,
        "max_error": max(finite) if finite and len(finite) == len(check.precision) else None,
        "kind": kind,
        "file": str(file),
        "links": links,
        "pivots": {"A0": _pt(fb.A0), "B0": _pt(fb.B0), "A": _pt(fb.A), "B": _pt(fb.B)},
        # the same pivots by the file's joint and the letter `draw` gives it (one lettering for text and drawing)
        "pivot_joints": {role: {"joint": joint, "letter": check.letters.get(joint)} for role, joint in PIVOT_JOINTS.items()},
        "precision": precision,
        "grashof": check.grashof,
        "transmission_angle_range": [math.degrees(mu[0]), math.degrees(mu[1])] if mu else None,
        # the same range by a name that says what it is over (a design of search.designs has its own, over the
        # whole motion: transmission_angle_range_over_motion)
        "transmission_angle_range_between_positions": [math.degrees(mu[0]), math.degrees(mu[1])] if mu else None,
        "defects": list(check.defects),
        "valid": check.valid,
        "check": {"assembled_iterations": check.assembled_iterations, "tolerance": check.tolerance,
                  "direction": {1: "counterclockwise", -1: "clockwise", 0: None}[check.direction],
                  "travel_deg": [_deg(t) for t in check.travel]},
    }


def _candidate_dict(k: int, c: Candidate) -> dict:
    fb = c.design.fourbar
    u, v, _ = tool_local(fb) if fb.tool is not None else (None, None, None)
    mu = [_deg(c.transmission[0]), _deg(c.transmission[1])] if c.transmission else None
    # transmission_angle_range as it always was here, and by the name that tells it from the written design's
    # (the top level's, between the precision positions): over a whole turn where the crank turns, else its travel
    return {"rank": k + 1, "max_error": c.error, "rms_error": c.rms, "error_unit": "rad" if c.design.kind == "function"
            else "m", "transmission_angle_range": mu, "transmission_angle_range_over_motion": mu, "grashof": c.grashof, "defects": list(c.defects), "unmet": list(c.unmet),
            "meets_constraints": c.feasible, "lengths": fb.lengths,
            "pivots": {"A0": _pt(fb.A0), "B0": _pt(fb.B0), "A": _pt(fb.A), "B": _pt(fb.B)},
            "point": None if u is None else [u, v], "run": c.run}


def _search_dict(report, constraints: list) -> dict:
    return {"method": report.method, "runs": report.runs, "evaluations": report.evaluations,
            "seconds": report.seconds, "where": report.where, "seed": report.seed, "constraints": constraints,
            "searched_within": report.box, "designs": [_candidate_dict(k, c) for k, c in enumerate(report.candidates)]}


def _dyad_dict(k: int, d: Dyad) -> dict:
    return {"index": k, "fixed": _pt(d.fixed), "moving": _pt(d.moving), "moving_local": _pt(d.local),
            "length": d.length}


def synthesis_dict(result, check: Check, file: str, constraints: Sequence[str]=()) -> dict:
    """The JSON object of a motion, function or path result and its check (``constraints``: the
    constrained search's, in words)."""
    design = result.design
    out = _core(design.kind, design, check, file)
    if getattr(result, "search", None) is not None:
        out["search"] = _search_dict(result.search, list(constraints))
    if isinstance(result, MotionResult):
        out.update({
            "method": result.method,
            "poses": [{"x": p[0], "y": p[1], "theta_deg": _deg(p[2])} for p in result.poses],
            "candidates": [_dyad_dict(k, d) for k, d in enumerate(result.candidates)],
            "pick": list(result.pick),
            "poles": [{"positions": [i + 1, j + 1], "point": _pt(P)} for i, j, P in result.poles],
        })
    elif isinstance(result, FunctionResult):
        out.update({
            "function": result.function, "x_range": list(result.x_range),
            "input_range_deg": [_deg(x) for x in result.input_range],
            "output_range_deg": [_deg(x) for x in result.output_range],
            "spacing": result.spacing, "least_squares": result.least_squares,
            "precision_x": list(result.x), "phi_deg": [_deg(x) for x in result.phi],
            "psi_deg": [_deg(x) for x in result.psi], "K": list(result.K),
            "structural_error_deg": {"max": _deg(result.max_structural_error),
                                     "at_precision_points": [_deg(e) for e in result.error_at_points]},
        })
        for entry, typed in zip(out["precision"], _as_typed(result, check)):
            entry["as_typed"] = typed
    elif isinstance(result, PathResult):
        out.update({
            "points": [list(p) for p in result.points],
            "timing_deg": None if result.timing is None else [_deg(t) for t in result.timing],
            "crank_angles_deg": [_deg(t) for t in result.crank_angles],
            "errors": list(result.errors), "starts": result.starts, "converged": result.converged,
            "tolerance": result.tolerance,
        })
    return to_jsonable(out)


def _as_typed(result: FunctionResult, check: Check) -> list:
    """Each precision point of function generation in the angles of --input-range and
    --output-range as typed [deg]: the crank's phi, the rocker's psi asked and the psi the file
    gives there (None where it does not assemble).  The file's own angles differ: the crank
    joint counts from the first precision point, the rocker's frame may point from B0 away from B."""
    out = []
    for p, x, phi, psi in zip(check.precision, result.x, result.phi, result.psi):
        got = None
        if p.value and math.isfinite(p.error):
            got = math.degrees(psi + float(wrap_angle(p.value[0] - p.target.value[0], upper=True)))
        out.append({"x": x, "phi_deg": math.degrees(phi), "psi_deg": math.degrees(psi), "psi_reached_deg": got})
    return out


#: Display cut-off of synthesis numbers: below this in magnitude they are written as 0 (the closed
#: forms are exact to round-off, tighter than tables.SHOWN_ZERO).
SYNTHESIS_ZERO = 1e-15


def _shown_number(x: float, digits: int = 6) -> str:
    """tables.shown_text with synthesis' own round-off (SYNTHESIS_ZERO)."""
    return shown_text(x, digits, SYNTHESIS_ZERO)


def _search_lines(result, constraints: Sequence[str]) -> list:
    """The constrained search: how, what it had to meet, and its best designs (closed form), best first."""
    report = result.search
    out = [f"constrained search: {report.method}; {report.runs} run{'s' if report.runs != 1 else ''} "
           f"({report.where}), seed {report.seed}, {report.seconds:.2f} s"]
    out += [f"  constraint: {c}" for c in constraints] or ["  constraints: none"]
    if report.box:
        out.append(f"  searched within: {report.box}")
    unit = "deg" if result.design.kind == "function" else "m"
    rows = []
    for k, c in enumerate(report.candidates):
        err = math.degrees(c.error) if unit == "deg" else c.error
        mu = f"{math.degrees(c.transmission[0]):.4g} .. {math.degrees(c.transmission[1]):.4g}" if c.transmission else "-"
        L = c.design.fourbar.lengths
        rows.append([k + 1, f"{err:.3g}", mu, c.grashof, "; ".join(c.defects) or "none",
                     "yes" if c.feasible else "no: " + "; ".join(c.unmet),
                     " ".join(f"{L[n]:.4g}" for n in ("ground", "crank", "coupler", "rocker"))])
    out.append(f"the best {len(rows)} design{'s' if len(rows) != 1 else ''} (judged in closed form, the transmission "
               "angle over a whole turn where the crank turns fully, else over its travel; the first is written and "
               "checked below):")
    out.append("  " + table(["#", f"max error [{unit}]", "transmission [deg]", "Grashof", "defects",
                             "meets constraints", "ground crank coupler rocker [m]"], rows).replace("\n", "\n  "))
    if not report.candidates[0].feasible:
        out.append("NO design found meets every constraint: the nearest is written (see what it misses)")
    return out


def _method_lines(result: MotionResult | FunctionResult | PathResult) -> list[str]:
    """How the design was synthesized: the dyads chosen, the function's precision points, the path's fit."""
    out = []
    if isinstance(result, MotionResult):
        out.append(f"method: {result.method}")
        if len(result.candidates) > 2 or result.ranked:
            rows = [[k, f"({_shown_number(c.fixed[0])}, {_shown_number(c.fixed[1])})", f"({_shown_number(c.moving[0])}, {_shown_number(c.moving[1])})",
                     _shown_number(c.length)] for k, c in enumerate(result.candidates)]
            out.append(f"candidate dyads ({len(rows)}; --pick CRANK,ROCKER chooses two):")
            out.append("  " + table(["#", "fixed pivot (centre point) [m]", "moving pivot (circle point) [m]",
                                     "length [m]"], rows).replace("\n", "\n  "))
        out.append(f"chosen: crank = candidate {result.pick[0]}, rocker = candidate {result.pick[1]}")
    elif isinstance(result, FunctionResult):
        out.append(f"y = {result.function} on x in [{_shown_number(result.x_range[0])}, {_shown_number(result.x_range[1])}]; crank "
                   f"phi {_shown_number(math.degrees(result.input_range[0]))} .. {_shown_number(math.degrees(result.input_range[1]))} "
                   f"deg, rocker psi {_shown_number(math.degrees(result.output_range[0]))} .. "
                   f"{_shown_number(math.degrees(result.output_range[1]))} deg")
        how = "least squares" if result.least_squares else "exact (3 x 3 linear solve)"
        out.append(f"{len(result.x)} precision points ({result.spacing} spacing), {how}: "
                   f"K1 = {result.K[0]:.9g}, K2 = {result.K[1]:.9g}, K3 = {result.K[2]:.9g}")
        where = "over the range" if np.all(np.isfinite(result.structural_error)) else \
            "where the linkage assembles"
        out.append(f"structural error (the output's miss between the precision points): largest "
                   f"{_shown_number(math.degrees(result.max_structural_error), 4)} deg {where}; at the precision points " + ", ".join(f"{math.degrees(e):.2g}" if math.isfinite(e) else "(none)"
                                                          for e in result.error_at_points)
                   + " deg")
    elif isinstance(result, PathResult):
        timing = "crank angles prescribed (--timing)" if result.timing is not None else "crank angles free"
        if result.search is None:
            out.append(f"{len(result.points)} points, {timing}; least squares from {result.starts} starts, "
                       f"{result.converged} reached every point within {_shown_number(result.tolerance, 3)} m")
        else:
            out.append(f"{len(result.points)} points, {timing}; {result.converged} of the designs refined reach every "
                       f"point within {_shown_number(result.tolerance, 3)} m")
    return out


def _linkage_lines(d: dict) -> list[str]:
    """The linkage written: its links, coupler frame or point, joints (lettered as draw letters them), Grashof
    class and transmission angle (``d``: synthesis_dict's)."""
    out = []
    links = d["links"]
    out.append("links [m]: " + ", ".join(f"{n} {_shown_number(v['length'])}" for n, v in links.items()))
    named = {role: (v["letter"] or role) for role, v in d["pivot_joints"].items()}  # draw's letters
    if "frame" in links["coupler"] or "point" in links["coupler"]:
        t = links["coupler"].get("frame") or links["coupler"].get("point")
        extra = f", {_shown_number(t['angle_deg'])} deg" if "angle_deg" in t else ""
        out.append(f"coupler {'frame' if 'frame' in links['coupler'] else 'point'} in the coupler's frame (origin "
                   f"{named['A']}, x along {named['A']}{named['B']}): ({_shown_number(t['x'])}, {_shown_number(t['y'])}) m{extra}")
    pv = d["pivots"]
    order = sorted(pv, key=lambda role: named[role])
    out.append("joints [m] (at the first position; lettered as draw letters them): " + ", ".join(
        f"{named[r]} {d['pivot_joints'][r]['joint']} ({_shown_number(pv[r][0])}, {_shown_number(pv[r][1])})" for r in order))
    out.append(f"Grashof: {d['grashof'] or 'not identified'}")
    mu = d["transmission_angle_range"]
    out.append("transmission angle from the first position to the farthest (screwkin's sweep): "
               + (f"{mu[0]:.4g} .. {mu[1]:.4g} deg" if mu else "not measured")
               + (f" (crank turning {d['check']['direction']})" if d["check"]["direction"] else ""))
    return out


def _precision_rows(result: MotionResult | FunctionResult | PathResult, check: Check) -> list[list]:
    """The check's table: each precision position, its target, whether it is reached, its errors and travel."""
    rows = []
    typed = _as_typed(result, check) if isinstance(result, FunctionResult) else [None] * len(check.precision)
    for p, travel, as_typed in zip(check.precision, list(check.travel) + [None] * len(check.precision), typed):
        t = p.target
        if as_typed is not None:  # function generation: the angles as typed, not the file's
            want = f"phi {_shown_number(as_typed['phi_deg'])} deg -> psi {_shown_number(as_typed['psi_deg'])} deg"
            err = f"{math.degrees(p.error):.2g} deg"
        elif t.kind == "pose":
            want = f"({_shown_number(t.value[0])}, {_shown_number(t.value[1])}, {_shown_number(math.degrees(t.value[2]))} deg)"
            err = f"{p.error:.2g} m, {math.degrees(p.angle_error):.2g} deg"
        elif t.kind == "point":
            want = f"({_shown_number(t.value[0])}, {_shown_number(t.value[1])})"
            err = f"{p.error:.2g} m"
        else:
            want = f"psi {_shown_number(math.degrees(t.value[0]))} deg"
            err = f"{math.degrees(p.error):.2g} deg"
        if not math.isfinite(p.error):
            err = "not assembled"
        rows.append([t.label, f"{_shown_number(math.degrees(t.input))}", want, "yes" if p.reached else "NO", err,
                     f"{p.residual:.2g}", f"{p.closed_form_error:.2g}" if math.isfinite(p.closed_form_error) else "-",
                     "-" if travel is None else _shown_number(math.degrees(travel), 5)])
    return rows


def synthesis_text(result: MotionResult | FunctionResult | PathResult, check: Check, file: str,
                   constraints: Iterable = ()) -> str:
    """A readable report of a motion, function or path result and its check."""
    d = synthesis_dict(result, check, file, constraints)
    title = {"motion": "Motion generation (rigid-body guidance)", "function": "Function generation (Freudenstein)",
             "path": "Path generation"}[result.design.kind]
    out = [f"{title}: wrote {file}"]
    out += _method_lines(result)
    if getattr(result, "search", None) is not None:
        out += _search_lines(result, constraints)
    out += _linkage_lines(d)
    out.append("")
    out.append(f"checked with screwkin on {file} (loaded, solved at each precision position, followed by sweep):")
    out.append(f"  drawn closed: {'yes' if check.assembled_iterations == 0 else 'no'} (assembly Newton iterations "
               f"{check.assembled_iterations})")
    rows = _precision_rows(result, check)
    # "reached" is at the position itself, within the check's tolerance (the header says it): a function
    # generator's structural error between the positions is another number, on its own line above
    within = f"{check.tolerance:.0e} rad" if isinstance(result, FunctionResult) else (
        f"{check.tolerance:.0e} m" + (" and rad" if any(p.target.kind == "pose" for p in check.precision) else ""))
    out.append("  " + table(["position", "crank [deg]", "target", f"reached (within {within})", "error", "residual",
                             "vs closed form [m]", "travel [deg]"], rows).replace("\n", "\n  "))
    if isinstance(result, FunctionResult):
        out.append(f"  targets in the angles typed (--input-range, --output-range); the file's crank_joint "
                   f"counts from the first precision point: crank = phi - {_shown_number(math.degrees(result.phi[0]))} deg")
    if check.defects:
        out.append("DEFECTS:")
        out += [f"  - {x}" for x in check.defects]
        out.append("not valid: the linkage does not do what was asked as written (see the defects)")
    elif all(p.reached for p in check.precision):
        between = (f"; between them the output is off by up to "
                   f"{_shown_number(math.degrees(result.max_structural_error), 4)} deg (the structural error)"
                   if isinstance(result, FunctionResult) else "")
        out.append(f"no defect: every precision position is reached (within {within}), on one branch, in the order "
                   f"given{between}")
    else:
        out.append("no defect: the positions are approximated (least squares), on one branch, in the order given")
    return "\n".join(out)


def chains_dict(result: ChainsResult, directory: str | None=None) -> dict:
    files = {(f.chain, f.ground): f for f in result.files}
    chains = []
    for c in result.chains:
        mechs = []
        names = c.inversion_names or (None,) * len(c.inversions)
        for g, orbit, name in zip(c.inversions, c.orbits, names):
            f = files.get((c.index, g))
            mechs.append({"ground": g, "inversion": name, "equivalent_grounds": list(orbit),
                          "file": f.file if f else None, "mobility": f.mobility if f else None,
                          "assembled_iterations": f.assembled_iterations if f else None,
                          "problem": f.problem if f else None})
        guides = guides_of(c.links, c.joints)
        chains.append({"index": c.index, "name": c.name, "links": c.links,
                       "joints": [{"links": [u, v], "type": k, **({"guide": guides[(u, v)]} if k == "P" else {})}
                                  for u, v, k in c.joints],
                       "joints_per_link": list(c.degrees), "automorphisms": c.automorphisms, "mechanisms": mechs})
    defects = [f"chain {f.chain}, chain link {f.ground} grounded: {f.problem}" for f in result.files if f.problem]
    return to_jsonable({
        "kind": "chains", "file": None if directory is None else str(directory), "links": {}, "pivots": {},
        "precision": [], "grashof": None, "transmission_angle_range": None,
        "transmission_angle_range_between_positions": None, "defects": defects,
        "valid": not defects,
        "chain_links": result.links, "dof": result.dof, "prismatic": result.prismatic, "joints": result.joints,
        "gruebler": f"3({result.links} - 1) - 2 x {result.joints} = {result.dof}",
        "count": len(result.chains), "mechanisms": sum(len(c.inversions) for c in result.chains),
        "chains": chains, "files": [f.file for f in result.files], "graphs_examined": result.candidates,
    })


def chains_text(result: ChainsResult, directory: str | None=None) -> str:
    d = chains_dict(result, directory)
    kinds = f", {result.prismatic} of them prismatic" if result.prismatic else ""
    out = [f"planar kinematic chains of {result.links} links and {result.dof} DOF: {result.joints} one-DOF joints"
           f"{kinds} (Gruebler {d['gruebler']}); 2-connected, no degenerate sub-chain",
           f"{d['count']} distinct chain{'s' if d['count'] != 1 else ''}, {d['mechanisms']} mechanism"
           f"{'s' if d['mechanisms'] != 1 else ''} (inversions: a ground link per class of links under the chain's "
           "automorphisms)"]
    for c in d["chains"]:
        joints = " ".join(f"{j['links'][0]}-{j['links'][1]}" + ("" if j["type"] == "R" else f"(P, guide {j['guide']})")
                          for j in c["joints"])
        out.append(f"  {c['index']:>3}. {c['name']}: joints {joints}; {c['automorphisms']} automorphism"
                   f"{'s' if c['automorphisms'] != 1 else ''}; grounds "
                   + ", ".join(str(m["ground"]) + (f" ({m['inversion']})" if m["inversion"] else "")
                               for m in c["mechanisms"]))
        for m in c["mechanisms"]:
            if m["file"]:
                status = f"mobility {m['mobility']}" + (f"  PROBLEM: {m['problem']}" if m["problem"] else ", drawn closed")
                name = f" ({m['inversion']})" if m["inversion"] else ""
                out.append(f"        chain link {m['ground']} grounded{name}: {m['file']} ({status})")
    if result.files:
        out.append(f"wrote {len(result.files)} file{'s' if len(result.files) != 1 else ''} to {directory}, each loaded and checked with screwkin "
                   "(drawn closed, mobility by the constraint rank)")
    if d["defects"]:
        out.append("DEFECTS:")
        out += [f"  - {x}" for x in d["defects"]]
    return "\n".join(out)
