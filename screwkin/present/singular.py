"""A singularity report (analysis.singular.SingularityReport) as text and as a JSON-ready
dictionary: the singularities present, the stationary joints, the loops' Gram cofactors, the condition
numbers and the singular directions."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ..analysis.singular import SingularityReport
from .screws import screw_dict
from .tables import fmt_vec as _fmt_vec
from .tables import table

__all__ = ["singularity_dict", "singularity_text"]


def singularity_text(rep: SingularityReport) -> str:
    """singularities' text: which singularities are present, the stationary joints, each loop's Gram
    cofactors, the condition numbers and the singular directions as screws."""
    def yes(b: bool) -> str:
        return "YES" if b else "no"

    out = f"   output: {rep.output}" + (" (its origin as a point)" if rep.point else "") if rep.output else ""
    lines = [f"inputs: {', '.join(rep.inputs) or 'none declared'}" + out,
             f"(measures of dimensionless matrices: lengths divided by the characteristic length "
             f"L = {rep.length:.4g} m)",
             table(["singularity", "present", "relative sigma_min"], [
                 ("serial / inverse-kinematic (output loses a direction)", yes(rep.serial),
                  f"{rep.sigmas['serial']:.3g}" if rep.output else "- (no --output)"),
                 ("actuator / direct-kinematic (moves with inputs locked)", yes(rep.actuator),
                  f"{rep.sigmas['actuator']:.3g}"),
                 ("constraint (rank of K drops)", yes(rep.constraint), f"{rep.sigmas['constraint']:.3g}"),
             ])]
    lines.append(f"stationary joints (rate forced to zero by the loops): {', '.join(rep.stationary_joints) or 'none'}")
    gram = tuple(getattr(rep, "gram", ()))
    free = [g for g in gram if not g.cofactors and g.nullity > 1]  # adj(G) = 0: said once, for all such loops
    if len(free) > 1:
        lines.append(f"\nloops closed by {', '.join(f'{g.loop} ({len(g.joints)} joint twists, loop mobility {g.nullity})' for g in free)}: "
                     f"Gram matrix G = S^T S of each loop's joint twists (dimensionless, L = {rep.length:.4g} m)")
        lines.append("  cofactors: each loop has more than one freedom of its own, so adj(G) = 0 and every cofactor "
                     "vanishes identically (the cofactors tell the stationary joints of a loop with one freedom)")
    for g in gram:
        if len(free) > 1 and g in free:
            continue
        lines.append(f"\nloop closed by {g.loop}: Gram matrix G = S^T S of its {len(g.joints)} joint twists "
                     f"(dimensionless, L = {rep.length:.4g} m)" + (f", loop mobility {g.nullity}" if g.nullity >= 0 else ""))
        if not g.cofactors:
            lines.append(f"  cofactors: {g.note}")
            continue
        lines.append(table(["joint", "cofactor C_ii", "C_ii / sum C_jj (= v_i^2)", "stationary"],
                           [(n, f"{g.cofactors[n]:.6g}", f"{g.relative[n]:.6g}", "YES (C_ii = 0)" if n in g.zero else
                             "no") for n in g.joints]))
    lines += _condition_lines(rep)
    for t in rep.singular_twists:
        lines.append(f"\n{t.kind} singular direction:")
        if t.joint_rates:
            lines.append("  joints moving: " + ", ".join(f"{n} {v:+.4g}" for n, v in t.joint_rates.items()))
        if t.screw is not None and np.linalg.norm(t.screw.direction) > 0:
            s = t.screw
            pitch = f"{s.pitch:.4g} m/rad" if np.isfinite(s.pitch) else "inf (a translation)"
            lines.append(f"  screw: axis direction {_fmt_vec(s.direction, 0)}, through "
                         f"{_fmt_vec(s.point, 0) if s.point is not None else '-'}, pitch {pitch}")
        elif t.twist is not None:  # never a zero twist written as a screw
            lines.append(f"  the output '{rep.output}' does not move in it (a zero twist: no screw)")
    return "\n".join(lines)


def _condition_meaning(rep: SingularityReport) -> str | None:
    """What ``rep.condition`` is the condition number of (it is not the input -> output map's)."""
    if rep.condition is None:
        return None
    if rep.manipulability is not None:
        return ("J_o V: the output's twist over an orthonormal basis of the mechanism's joint-rate motions "
                "(not over the input rates)")
    return "K_p: the loops' Jacobian in the passive joints (how well the inputs fix them)"


def _condition_lines(rep: SingularityReport) -> list[str]:
    """The two condition numbers, each saying what it is of: the input -> output map's first (Merlet's, what a
    parallel robot's user means), then the one of J_o V or K_p."""
    io = getattr(rep, "condition_input_output", None)
    note = getattr(rep, "input_output_note", None)
    value = f"{io:.4g}" if io is not None else "-"
    if io is None:
        lines = [f"condition number of the input -> output map (Merlet's): - ({note})"]
    else:
        lines = [f"condition number of the input -> output map (Merlet's): {value}"
                 + (f" ({note})" if note else "")
                 + f"  (of J: the input rates -> {rep.output}'s twist (v/L, w) at its origin, = of J^-1; "
                   f"L = {rep.length:.4g} m)"]
    if rep.condition is not None:
        lines.append(f"condition number {rep.condition:.4g}" + (
            f", manipulability {rep.manipulability:.4g}" if rep.manipulability is not None else "")
            + f" (L = {rep.length:.4g} m) of {_condition_meaning(rep)}")
    return lines


def _gram_dict(loops: Iterable) -> dict:
    """gram_loops: every loop's cofactors; gram_cofactors, gram_zero, gram_loop: those of the first
    loop with one freedom of its own (the single loop of a one-loop mechanism)."""
    first = next((g for g in loops if g.cofactors), None)
    return {"gram_loops": [{"loop": g.loop, "joints": list(g.joints), "nullity": g.nullity, "cofactors": g.cofactors,
                            "relative": g.relative, "zero": list(g.zero), "note": g.note} for g in loops],
            "gram_loop": first.loop if first else None,
            "gram_cofactors": dict(first.cofactors) if first else {},
            "gram_zero": list(first.zero) if first else []}


def singularity_dict(rep: SingularityReport) -> dict:
    """singularities --json's object."""
    return {
        "serial": rep.serial, "actuator": rep.actuator, "constraint": rep.constraint,
        "stationary_joints": list(rep.stationary_joints), "sigma_min": rep.sigma_min,
        "sigmas": rep.sigmas, "condition": rep.condition, "manipulability": rep.manipulability,
        "condition_of": _condition_meaning(rep),
        "condition_input_output": getattr(rep, "condition_input_output", None),
        "condition_input_output_note": getattr(rep, "input_output_note", None),
        "characteristic_length": rep.length, "inputs": list(rep.inputs), "output": rep.output,
        "point": rep.point,
        **_gram_dict(getattr(rep, "gram", ())),
        "singular_twists": [{"kind": t.kind, "joint_rates": t.joint_rates,
                             "twist": list(t.twist) if t.twist is not None else None,
                             "screw": screw_dict(t.screw) if t.screw is not None else None}
                            for t in rep.singular_twists],
    }
