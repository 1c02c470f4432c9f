"""Screws as text and JSON: the product-of-exponentials chains (screwkin screws), each loop as the
product of exponentials of all its joints, and single screws (axis, point, pitch)."""

from __future__ import annotations

import numpy as np

from ..analysis.screws import Screw, planar_form, screw_of
from .tables import fmt_vec as _fmt_vec
from .tables import table

__all__ = ["gram_symbolic_dict", "gram_symbolic_text", "screw_dict", "screws_dict", "screws_text", "loops_dict", "loops_text"]


def screw_dict(s: Screw) -> dict:
    return {"twist": list(s.twist), "direction": list(s.direction),
            "point": list(s.point) if s.point is not None else None,
            "pitch": s.pitch}  # infinite for a translation: "inf" (present/jsonout.py)


def screws_dict(structure: list | tuple, normal: tuple | None=None) -> list:
    out = []
    for st in structure:
        ch = st["chain"]
        joints = []
        for k, name in enumerate(ch.joints):
            d = {"joint": name, "xi0": screw_dict(screw_of(ch.xi0[:, k])), "theta": float(st["theta"][k]),
                 "xi": screw_dict(screw_of(st["space_jacobian"][:, k]))}
            if normal is not None:
                d["xi0_planar"] = planar_form(ch.xi0[:, k], normal).tolist()
                d["xi_planar"] = planar_form(st["space_jacobian"][:, k], normal).tolist()
            joints.append(d)
        out.append({"chain": ch.name, "joints": joints, "g0": ch.g0.tolist(), "g": st["g"].tolist(),
                    "space_jacobian": st["space_jacobian"].tolist(), "body_jacobian": st["body_jacobian"].tolist()})
    return out


def loops_dict(loops: list, normal: tuple | None=None) -> list:
    """analysis.screws.LoopScrews as JSON: each loop's joints in order with sign and twist."""
    out = []
    for lp in loops:
        joints = []
        for k, name in enumerate(lp.joints):
            d = {"joint": name, "sign": lp.signs[k], "cut": name == lp.cut, "xi0": screw_dict(screw_of(lp.xi0[:, k]))}
            if normal is not None:
                d["xi0_planar"] = planar_form(lp.xi0[:, k], normal).tolist()
            joints.append(d)
        out.append({"cut": lp.cut, "joints": joints, "closed_at_reference": lp.closed_at_reference})
    return out


def loops_text(loops: list, normal: tuple | None=None) -> str:
    """Each loop as the product of exponentials of all its joints, the cut joint included, = I."""
    lines = []
    for lp in loops:
        terms = " ".join(f"exp({'-' if sg < 0 else ''}[xi_{n}] th_{n})" for n, sg in zip(lp.joints, lp.signs))
        lines.append(f"loop closed at cut joint {lp.cut}:  {terms} = I")
        rows = []
        for k, name in enumerate(lp.joints):
            row = [name + (" (cut)" if name == lp.cut else ""), "+" if lp.signs[k] > 0 else "-",
                   _fmt_vec(lp.xi0[:, k], 8)]
            if normal is not None:
                row.append(_fmt_vec(planar_form(lp.xi0[:, k], normal), 8))
            rows.append(row)
        lines.append(table(["joint", "sign", "xi (v, w) at reference"] + (["(vx, vy, w)"] if normal is not None
                                                                          else []), rows))
        if not lp.closed_at_reference:
            lines.append("(the file is drawn with this loop open: the product is the identity only once the twists "
                         "are taken at an assembled configuration)")
        lines.append("")
    return "\n".join(lines)


def screws_text(structure: list, normal: tuple | None=None) -> str:
    lines = []
    for st in structure:
        ch = st["chain"]
        lines.append(f"chain to {ch.name}:  g(q) = " + " ".join(
            f"exp([xi{k + 1}] th{k + 1})" for k in range(len(ch.joints))) + " g(0)")
        rows = []
        for k, name in enumerate(ch.joints):
            s0 = screw_of(ch.xi0[:, k])
            pitch = "inf" if not np.isfinite(s0.pitch) else f"{s0.pitch:.3g}"
            point = "-" if s0.point is None else _fmt_vec(s0.point, 0)
            row = [f"xi{k + 1}", name, _fmt_vec(ch.xi0[:, k], 8), _fmt_vec(s0.direction, 0), point, pitch,
                   f"{st['theta'][k]:.6g}", _fmt_vec(st["space_jacobian"][:, k], 8)]
            if normal is not None:
                row.append(_fmt_vec(planar_form(ch.xi0[:, k], normal), 8))
            rows.append(row)
        headers = ["", "joint", "xi (v, w) at reference", "axis", "point", "pitch", "theta", "xi' (v, w) now"]
        if normal is not None:
            headers.append("(vx, vy, w)")
        lines.append(table(headers, rows))
        lines.append("g(0) = " + " | ".join(_fmt_vec(r, 0) for r in ch.g0[:3]))
        lines.append("")
    return "\n".join(lines)


def gram_symbolic_dict(loops) -> list:
    return [{"joints": list(lp.joints), "cofactors": lp.cofactors, "zero_when": {k: list(v) for k, v in
                                                                               lp.zero_when.items()},
             "note": lp.note} for lp in loops]


def gram_symbolic_text(loops) -> str:
    """Each loop's Gram cofactors in symbols and where they vanish (the joint is stationary)."""
    lines = ["Gram cofactors in symbols (the symbols of screwkin equations; C = 0: the joint is stationary)"]
    for lp in loops:
        lines.append(f"loop {' - '.join(lp.joints)}" + (f": {lp.note}" if lp.note else ""))
        for name, expr in lp.cofactors.items():
            where = "; ".join(lp.zero_when[name])
            lines.append(f"  C_{name} = {expr}   ({'0 where ' + where if where else 'never 0'})")
    return "\n".join(lines)
