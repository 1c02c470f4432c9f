"""A grasp analysis (screwkin.analysis.forces.grasp.GraspResult) as text and as a JSON-ready dictionary."""

from __future__ import annotations


import numpy as np

from ..analysis.forces.grasp import GraspResult
from ..analysis.screws import screw_of
from ..model.geometry import TINY
from ..tolerances import DEFAULT
from .jsonout import to_jsonable
from .tables import SHOWN_ZERO, shown_text, table
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.files.grasp import Contact

__all__ = ["grasp_dict", "grasp_text", "wrench_axis"]

#: Grasp maps wider than this many columns are left to --json in the text.
TEXT_COLUMNS = 16


def _vector_text(v) -> str:
    return "(" + ", ".join(shown_text(x) for x in v) + ")"


def _wrench_labels(planar: bool) -> list:
    return ["fx", "fy", "mz"] if planar else ["fx", "fy", "fz", "mx", "my", "mz"]


def pure_moment(w: np.ndarray, planar: bool) -> np.ndarray:
    """The wrench with a force below the motion tolerance (relative to the wrench) set to zero: a
    force of 3e-7 N beside a moment of 1 N m is round-off, and its line of action (through a point
    144 km away) is no answer: it is a pure moment."""
    w = np.array(w, float)
    k = 2 if planar else 3
    if np.linalg.norm(w[:k]) <= DEFAULT.motion * max(np.linalg.norm(w), TINY):
        w[:k] = 0.0
    return w


def wrench_axis(w: np.ndarray | list, planar: bool) -> dict:
    """The line of action of a wrench (force, moment): direction of the force, the point of the
    line nearest the origin, pitch = f . m / |f|^2 [m]; a pure moment (no force) has direction
    the moment's, no point and pitch inf.  Planar wrenches (fx, fy, mz) as spatial ones."""
    w = pure_moment(np.asarray(w, float), planar)
    f, m = (np.array([w[0], w[1], 0.0]), np.array([0.0, 0.0, w[2]])) if planar else (w[:3], w[3:])
    s = screw_of(np.concatenate([m, f]))  # a twist's (v, w) is a wrench's (m, f): the same axis
    return {"direction": list(s.direction), "point": list(s.point) if s.point is not None else None,
            "pitch": s.pitch}  # infinite for a couple: "inf" (present/jsonout.py)


def _contact_dict(c: Contact) -> dict:
    d = {"point": list(c.point), "normal": list(c.normal), "model": c.model, "mu": c.mu}
    if c.model == "soft_finger":
        d["mu_torsion"] = c.mu_torsion
    return d


def _certificate_dict(r: GraspResult) -> dict | None:
    c = r.certificate
    if c is None:
        return None
    if c.kind == "internal_force":
        return {"internal_force": c.internal_force, "residual": c.residual, "margin": c.margin, "cones": c.cones,
                "contact_forces": [{"contact": f.contact, "normal": f.normal, "tangential": list(f.tangential),
                                    "torsion": f.torsion, "force": list(f.force), "friction_ratio": f.friction_ratio,
                                    "torsion_ratio": f.torsion_ratio} for f in c.contact_forces]}
    return {"unresisted_wrench": pure_moment(c.unresisted_wrench, r.spec.planar).tolist(), "opposite_unresisted_too": c.both_signs,
            "axis": wrench_axis(c.unresisted_wrench, r.spec.planar), "margin": c.margin, "cones": c.cones}


def grasp_dict(r: GraspResult) -> dict:
    """What ``screwkin grasp --json`` prints, as plain Python (present/jsonout.py's rule: "inf" for an
    infinite number, None for a value that does not exist)."""
    q = r.quality
    return to_jsonable({
        "file": r.spec.path,
        "planar": r.spec.planar,
        "contacts": [_contact_dict(c) for c in r.spec.contacts],
        "wrench_components": _wrench_labels(r.spec.planar),
        "grasp_map": r.grasp_map,
        "grasp_map_columns": list(r.columns),
        "rank": r.rank,
        "internal_force_dimension": r.internal_force_dimension,
        "form_closure": r.form_closure,
        "force_closure": r.force_closure,
        "decided_by": r.how,
        "certificate": _certificate_dict(r),
        "quality": {"epsilon": q.epsilon, "epsilon_upper": q.epsilon_upper, "norm": q.norm,
                    "torque_scale": q.torque_scale, "torque_scale_source": r.length_source,
                    "origin": "the object frame's origin", "note": q.reason},
        "facets": r.facets,
        "facets_requested": r.facets_requested,
        "cone_error": r.cone_error,
        "exact_cones": r.exact_cones,
        "tolerance": r.tolerance,
        "notes": list(r.notes),
    })


def _yes(b: bool) -> str:
    return "undecided" if b is None else ("YES" if b else "no")


def _percent(x: float | None) -> str:
    return "-" if x is None else f"{100 * (0.0 if x < SHOWN_ZERO else x):.3g}%"


def grasp_text(r: GraspResult) -> str:
    """The analysis as text: contacts, G, rank, closure with the certificate, quality, cones."""
    spec = r.spec
    rows = _wrench_labels(spec.planar)
    n = len(spec.contacts)
    lines = [f"grasp: {spec.path} -- {n} contact{'s' if n != 1 else ''}, "
             f"{'planar' if spec.planar else 'spatial'}; wrenches ({', '.join(rows)}) on the object, about the "
             "origin of its frame"]
    shown = spec.contacts[:50]
    lines.append(table(["contact", "model", "point [m]", "normal (into the object)", "mu", "mu_torsion [m]"], [
        (k, c.model, " ".join(shown_text(x) for x in (c.point[:2] if spec.planar else c.point)),
         " ".join(shown_text(x) for x in (c.normal[:2] if spec.planar else c.normal)),
         shown_text(c.mu) if c.model != "frictionless" else "-",
         shown_text(c.mu_torsion) if c.model == "soft_finger" else "-") for k, c in enumerate(shown, 1)]))
    if n > len(shown):
        lines.append(f"... and {n - len(shown)} more contacts (all in --json)")
    p, m = r.grasp_map.shape
    lines.append("")
    if m <= TEXT_COLUMNS:
        lines.append(f"grasp map G ({p} x {m}; force rows in N, moment rows in N m, per unit contact force [N] "
                     "or torsion [N m]):")
        body = [[lab] + [shown_text(x) for x in row] for lab, row in zip(rows, r.grasp_map)]
        lines += ["  " + x for x in table(["", *r.columns], body).splitlines()]
    else:
        lines.append(f"grasp map G: {p} x {m} (columns {r.columns[0]} ... {r.columns[-1]}; printed by --json)")
    lines.append(f"rank G = {r.rank} of {p}" + (" (full)" if r.rank == p else
                                                 f": wrenches outside a {r.rank}-dimensional space are resisted "
                                                 "by no contact force"))
    lines.append(f"internal forces (G f = 0): dim null(G) = {r.internal_force_dimension}")
    lines.append(f"form closure (every contact taken frictionless): {_yes(r.form_closure)}")
    lines.append(f"force closure: {_yes(r.force_closure)} -- {r.how}")
    lines += _certificate_lines(r)
    lines += _quality_lines(r)
    if r.exact_cones:
        lines.append("friction cones: exact (frictionless contacts, mu = 0 and planar cones are polyhedral); "
                     "cone error 0")
    else:
        lines.append(f"friction cones: {r.facets}-facet pyramids" + (
            f" (refined from --facets {r.facets_requested})" if r.facets != r.facets_requested else "")
            + f", cone error 1 - cos(pi/{r.facets}) = {r.cone_error:.3g} (the inscribed pyramid holds "
              f"friction {1 - r.cone_error:.4g} mu in every direction, the circumscribed one at most "
              f"{1 / (1 - r.cone_error):.4g} mu); the verdict is checked against the circular cones")
    lines.append(f"tolerance: certificates clear their bounds by {r.tolerance:g} (wrenches with moments / L)")
    for note in r.notes:
        lines.append(f"note: {note}")
    return "\n".join(lines)


def _certificate_lines(r: GraspResult) -> list:
    c = r.certificate
    if c is None:
        return []
    if c.kind == "internal_force":
        out = [f"  certificate: an internal force strictly inside every cone (found with the {c.cones} cones), "
               f"|G f| = {c.residual:.2g}, total normal force 1 N:"]
        spatial = not r.spec.planar
        shown = c.contact_forces[:50]
        body = []
        for cf in shown:
            body.append((cf.contact, shown_text(cf.normal), " ".join(shown_text(x) for x in cf.tangential) or "-",
                         shown_text(cf.torsion) if cf.torsion is not None else "-", _percent(cf.friction_ratio),
                         _percent(cf.torsion_ratio)))
        heads = ["contact", "normal [N]", "tangential [N]" + (" (t1 t2)" if spatial else " (t)"),
                 "torsion [N m]", "friction used", "torsion used"]
        out += ["    " + x for x in table(heads, body).splitlines()]
        if len(c.contact_forces) > len(shown):
            out.append(f"    ... and {len(c.contact_forces) - len(shown)} more contacts (all in --json)")
        return out
    w = pure_moment(c.unresisted_wrench, r.spec.planar)
    k = 2 if r.spec.planar else 3
    ax = wrench_axis(w, r.spec.planar)
    where = (f"a pure moment about {_vector_text(ax['direction'])}" if ax["point"] is None else
             f"line of action along {_vector_text(ax['direction'])} through {_vector_text(ax['point'])}, pitch "
             f"{shown_text(ax['pitch'])} m")
    return [f"  certificate: a wrench on the object that no contact forces inside the cones balance "
            f"(found with the {c.cones} cones):",
            f"    force {_vector_text(w[:k])} N, moment {_vector_text(w[k:])} N m ({where})",
            "    " + ("nor its opposite: it lies outside the span of G" if c.both_signs else
                      "every contact wrench has a component along it, none against it")]


def _quality_lines(r: GraspResult) -> list:
    q = r.quality
    scale = f"moments divided by L = {q.torque_scale:.4g} m ({r.length_source})"
    what = ("Ferrari-Canny, L1: the hull of the primitive wrenches of unit normal force, i.e. sum of normal "
            f"forces <= 1; {scale}; about the object frame's origin")
    if q.epsilon is None:
        return [f"quality: epsilon not computed ({q.reason}); {what}"]
    out = [f"quality: epsilon = {q.epsilon:.6g} ({what})"]
    if not r.exact_cones:
        out.append(f"  for the circular cones epsilon lies between {q.epsilon:.6g} (inscribed pyramids) and "
                   f"{q.epsilon_upper:.6g} (circumscribed)")
    elif q.epsilon_upper is not None and q.epsilon_upper > q.epsilon:
        out.append(f"  bounds only: epsilon lies between {q.epsilon:.6g} and {q.epsilon_upper:.6g}")
    if q.reason:
        out.append(f"  ({q.reason})")
    return out
