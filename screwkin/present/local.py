"""The local analysis (analysis.local) and the redundant constraints (analysis.redundancy) as JSON-ready
dictionaries and text lines, for mobility, singularities, statics, sweep and draw."""

from __future__ import annotations

from ..analysis.local import LocalAnalysis, words
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.course.figures import SingularConfiguration
    from screwkin.analysis.motion.crossing import ChangePoint
    from screwkin.analysis.redundancy import Redundancy

__all__ = ["change_point_dict", "change_point_lines", "local_dict", "local_lines", "redundancy_dict", "redundancy_lines",
           "redundant_wrenches", "singularity_kind_text", "types_lines"]

_KIND = {
    "actuator": "actuator singularity (det of the passive Jacobian = 0)",
    "serial": "serial singularity",
    "constraint": "constraint singularity (the loops lose a constraint)",
}


def types_lines(types) -> list:
    """The singularity types that meet (analysis.singular.named_types) as text lines."""
    if not types:
        return ["singularity types: none (no singularity here)"]
    return ["singularity types here:"] + [f"  {v}: {n} -- {w}" for v, n, w in types]


def local_dict(la: LocalAnalysis, configuration: dict | None = None) -> dict:
    """``local``: {rank_drop, infinitesimal_mobility, finite_mobility, kind, order, branches: [{tangent,
    mobility}]} (the contract), with how it was decided beside."""
    d = {
        "rank_drop": la.rank_drop,
        "infinitesimal_mobility": la.infinitesimal_mobility,
        "finite_mobility": la.finite_mobility,
        "kind": la.kind,
        "order": la.order,
        "branches": [{"tangent": b.tangent, "mobility": b.mobility, "infinitesimal_mobility_nearby": b.nearby,
                      "tangent_space": list(b.tangent_space), "linear": b.linear, "order": b.order,
                      "confirmed": b.confirmed, "step": b.step, "deviation": b.deviation, "residual": b.residual}
                     for b in la.branches],
        "infinitesimal_mobility_inputs_held": la.inputs_held,
        "inputs": list(la.inputs),
        "rank": la.rank,
        "generic_rank": la.generic_rank,
        "coordinates": la.coordinates,
        "checked_order": la.checked_order,
        "certain": la.certain,
        "decided_by": la.decided_by,
        "words": words(la),
        "algebra": la.algebra,
        "redundant_rows": la.redundant_rows,
        "identically_zero_rows": la.identically_zero,
        "sigma": la.sigma,
        "notes": list(la.notes),
    }
    if configuration is not None:
        d["configuration"] = configuration
    return d


def local_lines(la: LocalAnalysis, where: str, explain: bool = True) -> list:
    """Text lines: what the mechanism can do at ``where``; with ``explain`` (--explain, report) the ranks, how
    it was decided and the notes too (the branches met are always listed: they are part of the answer)."""
    held = "" if la.inputs_held is None else f", {la.inputs_held} with the inputs held"
    lines = [f"at {where}: {words(la)}"]
    if explain:
        lines += [f"  rank of K {la.rank}" + (f" (generic {la.generic_rank}, drop {la.rank_drop})"
                                              if la.generic_rank is not None else "")
                  + f"; infinitesimal mobility {la.infinitesimal_mobility}{held}; finite mobility "
                  + ("undecided" if la.finite_mobility is None else str(la.finite_mobility)),
                  f"  how: {la.decided_by}"]
    for b in la.branches:
        if b.confirmed:
            lines.append(f"  branch of mobility {b.mobility}: closed again at a step of {b.step:g} along it "
                         f"(residual {b.residual:.1e}, {b.deviation:.1e} from the tangent's first-order prediction; "
                         f"infinitesimal mobility there {b.nearby})")
    for n in la.notes if explain else ():
        lines.append(f"  note: {n}")
    return lines


def redundant_wrenches(r: Redundancy) -> list:
    """``redundant_wrenches``: a basis of the statically indeterminate wrenches, each {joint: (fx, fy, fz, mx,
    my, mz)} about the world origin in the ground frame, with the rows of K it combines.  When every
    vector of the left null space lies in one joint's rows, the joints' own (canonical) bases are used."""
    if sum(j.count for j in r.joints) == r.count and all(j.wrenches for j in r.joints):
        return [{"joint": j.joint, "wrench": list(w), "at": list(j.at),
                 "named": j.named[k] if k < len(j.named) else None}
                for j in r.joints for k, w in enumerate(j.wrenches)]
    return [{"wrenches": {n: (list(w) if isinstance(w, tuple) else w) for n, w in b.items()}, "rows": rows}
            for b, rows in zip(r.basis, r.rows)]


def redundancy_dict(r: Redundancy) -> dict:
    d = {"redundant_wrenches": redundant_wrenches(r),
         "redundant_joints": [{"joint": j.joint, "what": j.what, "rows": j.rows, "redundant_rows": j.count,
                               "wrenches": [list(w) for w in j.wrenches], "at": list(j.at), "named": list(j.named),
                               "words": j.words, "why": j.why} for j in r.joints],
         "redundant_rows_qr": list(r.qr_redundant_rows)}
    if r.suggestion is not None:
        s = r.suggestion
        d["exactly_constrained_by"] = {"changes": [{"joint": n, "type": t, "words": w} for n, t, w in s.changes],
                                       "words": s.words, "mobility": s.mobility, "overconstraint": s.overconstraint,
                                       "checked": s.checked}
    return d


_WHY = {"planar": "the loop is planar", "spherical": "the loop is spherical",
        "planar and overconstrained": "the loop is planar, and overconstrained in its plane",
        "spherical and overconstrained": "the loop is spherical, and overconstrained on its sphere",
        "overconstrained": "the linkage is overconstrained"}


def redundancy_lines(r: Redundancy, title: str = "redundant constraints", explain: bool = True) -> list:
    """Text lines naming each joint's redundant wrenches, the rows a QR names, and the suggestion; without
    ``explain`` one line: how many, at which joints and why (--explain names them and the way out)."""
    if not r.count:
        return []
    def who(j):
        return f"{j.what} '{j.joint}'" if j.what in ("connect", "weld", "coupling") else j.joint

    if not explain:
        where = "; ".join(f"{j.count} at {who(j)} ({_WHY.get(j.why, j.why)})" for j in r.joints)
        return [f"{title}: {r.count}" + (f", {where}" if where else "") + " (--explain names them"
                + (" and how to remove them)" if r.suggestion is not None else ")")]
    lines = [f"{title} ({r.count}, the statically indeterminate wrenches):"]
    for j in r.joints:
        lines.append(f"  {who(j)}: {j.words} -- {_WHY.get(j.why, j.why)}")
    if r.qr_redundant_rows:
        lines.append("  rows a pivoted QR of K^T puts last (as Chrono removes them): " + ", ".join(r.qr_redundant_rows))
    s = r.suggestion
    if s is not None:
        if s.changes:
            lines.append(f"  exactly constrained if you {s.words}: checked, the changed model has mobility {s.mobility} "
                         f"and overconstraint {s.overconstraint} ({s.checked})")
        else:
            lines.append(f"  to make it exactly constrained: {s.words}")
    return lines


def _branch_text(la, k: int) -> str:
    if k is None:
        return "no branch found"
    b = la.branches[k]
    return f"branch {k + 1} (" + ", ".join(f"{n} {v:.4g}" for n, v in b.tangent.items() if v) + ")"


def change_point_dict(cp: ChangePoint, mech: Mechanism | None = None) -> dict:
    """A constraint singularity met along a motion (analysis.motion.crossing.ChangePoint)."""
    d = {"input": cp.input, "sigma": cp.sigma, "local": local_dict(cp.local),
         "came_on_branch": None if cp.came is None else cp.came + 1,
         "continues_on_branch": None if cp.goes is None else cp.goes + 1,
         "located_here": cp.located}
    if mech is not None:
        d["joints"] = mech.joint_values(cp.q)
    return d


def change_point_lines(cp, where: str) -> list:
    """What a constraint singularity met along a motion is, and which branch the motion takes there."""
    lines = [f"  at {where}: {words(cp.local)}"]
    if cp.local.branches and (cp.came is not None or cp.goes is not None):
        lines.append(f"    the motion comes in on {_branch_text(cp.local, cp.came)} and continues on "
                     f"{_branch_text(cp.local, cp.goes)}")
    return lines


def singularity_kind_text(s: SingularConfiguration) -> str:
    """What a singular configuration met along the input is, in words (a drawing's subtitle, a
    report's table): its kind, a limit position, the change point analysed (analysis.local)."""
    if getattr(s, "point", None) is not None:  # a constraint singularity, analysed (analysis.local)
        return "; ".join(line.strip() for line in change_point_lines(s.point, "it"))[len("at it: "):]
    if s.kind == "actuator" and s.limit:
        return "limit position of the input: actuator singularity (det of the passive Jacobian = 0)"
    if s.kind == "serial":
        return (f"serial singularity of '{s.output}': its limit position (a dead centre when driven from it)"
                if s.output else "serial singularity")
    return _KIND.get(s.kind, s.kind)
