"""Statics results (screwkin.analysis.forces.statics) as text and JSON-ready dictionaries."""

from __future__ import annotations

import numpy as np

from ..analysis.forces.statics import Leg, StaticsResult
from .screws import screw_dict
from .tables import table
from .tables import shown_text
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.screws import Screw

__all__ = ["statics_dict", "statics_text", "NO_SOLUTION"]

#: JSON "solution" where the inputs cannot hold the load
NO_SOLUTION = ("none: no equilibrium; efforts, reactions, constraint_forces and amplification are a least-squares "
               "fit that leaves least_squares_residual unbalanced, not a solution")


def _screw_text(s: Screw) -> str:
    pitch = f"pitch {s.pitch:.4g} m" if np.isfinite(s.pitch) else "pitch inf (a couple)"
    point = "" if s.point is None else " through (" + ", ".join(f"{x:.4g}" for x in s.point) + ")"
    return "axis (" + ", ".join(f"{x:.4g}" for x in s.direction) + ")" + point + ", " + pitch


def leg_dict(leg: Leg) -> dict:
    return {"joints": list(leg.joints), "actuated": list(leg.actuated), "twists": leg.twists,
            "constraint_wrenches": [{"wrench": list(w), "screw": screw_dict(s)}
                                    for w, s in zip(leg.constraint_wrenches, leg.constraint_screws)],
            "transmission_wrenches": [{"wrench": list(w), "screw": screw_dict(s)}
                                      for w, s in zip(leg.transmission_wrenches, leg.transmission_screws)]}


def statics_dict(r: StaticsResult, legs: tuple | None=None) -> dict:
    d = {"inputs": list(r.inputs), "efforts": r.efforts, "units": r.units, "wrench": list(r.wrench),
         "output": r.output, "gravity": r.gravity, "equilibrium": r.equilibrium, "unbalanced": r.unbalanced,
         "reactions": [{"joint": x.joint, "kind": x.kind, "wrench": list(x.wrench), "determinate": x.determinate}
                       for x in r.reactions],
         "indeterminate": r.indeterminate, "singular": r.singular, "sigma_actuator": r.sigma_actuator,
         "amplification": r.amplification, "characteristic_length": r.length,
         "constraint_forces": [{"row": k, "value": v} for k, v in r.constraint_forces],
         "actuator_efforts": dict(r.actuator_efforts), "coupled_efforts": dict(r.coupled_efforts),
         "transmissions": [t.text() for t in r.transmissions], "springs": dict(r.springs), "notes": list(r.notes),
         # no equilibrium: efforts, reactions, constraint_forces and amplification are a least-squares fit, no solution
         "least_squares_residual": None if r.equilibrium else r.unbalanced,
         "solution": "equilibrium" if r.equilibrium else NO_SOLUTION}
    if legs is not None:
        d["legs"] = [leg_dict(leg) for leg in legs]
    return d


def statics_text(r: StaticsResult, legs=None) -> str:
    load = []
    if r.output is not None and any(r.wrench):
        f, m = r.wrench[:3], r.wrench[3:]
        load.append(f"wrench on '{r.output}' at its frame's origin: force ({', '.join(shown_text(x) for x in f)}) N, "
                    f"moment ({', '.join(shown_text(x) for x in m)}) N m (world axes)")
    if r.gravity:
        load.append("the links' weights (Pinocchio's gravity, from the inertials)")
    lines = ["load: " + ("; ".join(load) if load else "none")]
    if not r.equilibrium:
        lines.append(f"NO EQUILIBRIUM: the inputs ({', '.join(r.inputs) or 'none'}) cannot hold this load "
                     f"(unbalanced generalized force {r.unbalanced:.3g})")
        lines.append("no actuator efforts and no joint reactions hold it: those of a least-squares fit are not shown "
                     "(--json has them, with \"solution\" and \"least_squares_residual\" saying they are a fit)")
    if r.inputs and r.equilibrium:
        lines.append("")
        lines.append(table(["actuator", "effort"], [
            (n, "indeterminate (redundant actuation)" if r.efforts[n] is None else f"{shown_text(r.efforts[n])} {r.units[n]}")
            for n in r.inputs]))
        for t in r.transmissions:
            e = r.actuator_efforts.get(t.actuator)
            lines.append(f"actuator {t.actuator!r}: {shown_text(e)} (the effort on {t.joint} / {t.scale * t.gear:g}: "
                         f"{t.text()})")
        for name, e in r.coupled_efforts.items():
            lines.append(f"coupled joint {name!r}: {shown_text(e)} {r.units[name]} "
                         "(what its coupling exerts along it)")
        if r.singular:
            lines.append(f"near an actuator singularity (relative sigma {r.sigma_actuator:.2g}): the efforts grow "
                         f"without bound as the mechanism approaches it; amplification {r.amplification:.3g}")
        elif r.amplification is not None:
            lines.append(f"amplification |efforts| / |load| = {r.amplification:.3g} (lengths made dimensionless by "
                         f"L = {r.length:.4g} m; actuator sigma {r.sigma_actuator:.3g})")
    rows = [(x.joint, x.kind, *(shown_text(v, 5) for v in x.wrench)) for x in r.reactions]
    if r.equilibrium:
        lines.append("")
        lines.append("joint reactions: what the parent side exerts on the child side, at each joint's origin, world axes")
        lines.append(table(["joint", "kind", "fx [N]", "fy", "fz", "mx [N m]", "my", "mz"], rows))
    if r.indeterminate and r.equilibrium:
        lines.append(f"'?': not determined by statics ({r.indeterminate} redundant constraint or actuator "
                     "direction(s): an overconstrained linkage, or a planar one's out-of-plane components)")
    for name, f in r.springs.items():
        lines.append(f"spring of {name!r}: {shown_text(f)} {r.units[name]} along the joint (-stiffness (x - springref))")
    for k, leg in enumerate(legs or (), 1):
        lines.append("")
        lines.append(f"leg {k}: joints {', '.join(leg.joints)}; actuated {', '.join(leg.actuated) or 'none'}; "
                     f"the leg alone lets the platform move in {leg.twists} direction(s)")
        for s in leg.constraint_screws:
            lines.append(f"  constraint wrench: {_screw_text(s)}")
        for s in leg.transmission_screws:
            lines.append(f"  transmission wrench: {_screw_text(s)}")
    lines += [f"note: {n}" for n in r.notes]
    return "\n".join(lines)
