"""``screwkin export``: the mechanism written as MJCF (MuJoCo) or URDF with ``<loop_joint>``,
at an assembled configuration, so that its loops are closed in the file (MuJoCo's equalities
take their second point from qpos0)."""

from __future__ import annotations

import os

from ..errors import UsageError, quote
from ..files.exporter import DEFAULT_DENSITY, ROD_RATIO, helper_names, mujoco_refuses, write_mjcf, write_placed_urdf
from ..files.mjcf_rows import redundant_rows
from ..model.placed import check_closed, placed
from ..present.outfile import write_output
from ._common import emit
from ._configuration import add_configuration_options, configuration, with_mode
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "export"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable[..., None], scaled: Callable[..., None]) -> None:
    sp = sub.add_parser(NAME, help="write the mechanism as MJCF (MuJoCo) or URDF, assembled (loops closed in the file)")
    common(sp)
    sp.add_argument("--mjcf", metavar="OUT.xml", help="write MJCF here: loops as <equality> connect/weld")
    sp.add_argument("--urdf", metavar="OUT.urdf", help="write URDF here: loops as <loop_joint>")
    add_configuration_options(sp)


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    if not args.mjcf and not args.urdf:
        raise UsageError("export needs --mjcf OUT.xml or --urdf OUT.urdf (or both)")
    q = configuration(mech, args)
    residual = check_closed(mech, q, 1e3 * mech.tolerances.closure)
    values = {k: float(v) for k, v in mech.joint_values(q).items()}
    comment = (f"Written by screwkin export from {os.path.basename(mech.path)} at an assembled configuration "
               f"(loop residual {residual:.1e}): the file's zero configuration is that one, so each joint's value "
               "here is its value there minus: " + ", ".join(f"{k} {v:.9g}" for k, v in values.items()))
    written, notes, texts, compounds, redundant = [], [], [], [], None
    for fmt, out in (("MJCF", args.mjcf), ("URDF", args.urdf)):  # both made before either is written
        if not out:
            continue
        pm = placed(mech, q, fmt, comment=comment)
        notes += [n for n in pm.notes if n not in notes]
        if fmt == "MJCF":
            texts.append((out, write_mjcf(pm)))
            names = helper_names(pm)
            for c in pm.cuts:
                if c.type in ("revolute", "continuous"):
                    notes.append(f"loop joint {quote(c.name)} (revolute): <connect>s {quote(c.name)} and "
                                 f"{quote(names['axis', c.name])} {pm.length:.3g} m apart on its axis (MJCF has no "
                                 "hinge equality; a hinge on a small body welded to the link drifts more in MuJoCo; "
                                 "screwkin reads the pair back as one revolute loop joint)")
                elif c.type not in ("spherical", "fixed"):
                    notes.append(f"loop joint {quote(c.name)} ({c.type}): a body {quote(names['F1', c.name])} "
                                 "carrying its motion, welded to the second link (MJCF has no such equality)")
            notes += _compound_notes(pm)
            line, redundant = _redundant_note(texts[-1][1])
            notes += [line] if line else []
            compounds += [{"type": c.type, "joint": c.name if c.type == "spherical" else None,
                           "members": list(c.members), "links_left_out": list(c.links), "body": c.body,
                           "axes": [list(a) for a in c.axes], "values": list(c.values)} for c in pm.compounds]
            light = [b.name for b in pm.bodies if b.joint is not None and b.joint.type != "fixed" and b.mass <= 0]
            light += [names["F1", c.name] for c in pm.cuts if ("F1", c.name) in names and c.type not in
                      ("spherical", "fixed", "revolute", "continuous")]
            if light:
                notes.append(f"{len(light)} moving bodies without mass ({', '.join(quote(n, 30) for n in light[:3])}"
                             f"{', ...' if len(light) > 3 else ''}) get a solid of {DEFAULT_DENSITY:g} kg/m^3 (MuJoCo's "
                             f"default density): a rod from the body's origin to its farthest joint, radius "
                             f"{ROD_RATIO:g} of its length (a sphere of radius {ROD_RATIO * pm.length:.3g} m where no "
                             "other joint is on it): MuJoCo needs a mass on every moving body")
            odd = [b.name for b in pm.bodies if b.joint is not None and b.joint.type != "fixed"
                   and mujoco_refuses(b.mass, b.inertia)]
            if odd:
                notes.append(f"{len(odd)} bodies ({', '.join(quote(n, 30) for n in odd[:3])}{', ...' if len(odd) > 3 else ''})"
                             " have a mass with an inertia MuJoCo refuses (not positive, or A + B < C): their mass is "
                             "written with the inertia of the solid above, scaled to it")
        else:
            texts.append((out, write_placed_urdf(pm, mech.spec.root)))
            for what, key in (("armature", "armature"), ("spring", "stiffness")):
                rotors = [b.joint.name for b in pm.bodies if b.joint is not None and dict(b.joint.dynamics).get(key)]
                if rotors:
                    notes.append(f"the {what} of {len(rotors)} joints ({', '.join(quote(n, 30) for n in rotors[:3])}"
                                 f"{', ...' if len(rotors) > 3 else ''}) has no URDF form: not written (damping and "
                                 "frictionloss are, as <dynamics damping friction>)")
        written.append({"format": fmt, "path": str(out), "bodies": len(pm.bodies), "loop_joints": len(pm.cuts)})
    for out, body in texts:
        write_output(out, body)

    def data():
        return with_mode(args, {"file": mech.path, "written": written, "configuration": values,
                                "residual": residual, "notes": notes, "compounds": compounds,
                                "redundant_rows": redundant})

    def text() -> str:
        lines = [f"wrote {w['path']} ({w['format']}): {w['bodies']} bodies, {w['loop_joints']} loop joints, at the "
                 f"assembled configuration (residual {residual:.1e})" for w in written]
        lines.append("joint values there (the written file's zero): "
                     + ", ".join(f"{k} = {v:.6g}" for k, v in values.items()))
        lines += [f"note: {n}" for n in notes]
        lines.append("note: visual geometry is not written; inertias are Pinocchio's (links fixed together merged)")
        return "\n".join(lines)

    return emit(args, data, text)


def _names(names: list, n: int = 3) -> str:
    return ", ".join(quote(x, 30) for x in names[:n]) + (", ..." if len(names) > n else "")


def _compound_notes(pm) -> list:
    """One line per kind of compound joint the MJCF export wrote as one body's joints."""
    out = []
    balls = [c for c in pm.compounds if c.type == "spherical"]
    if balls:
        one = len(balls) == 1
        out.append(f"{len(balls)} compound spherical joint{'' if one else 's'} (three concurrent revolutes through "
                   f"massless links: {_names([c.name for c in balls])}) {'is' if one else 'are'} one ball joint "
                   f"{'' if one else 'each, '}of that name, the massless links left out: a ball's quaternion Q = "
                   "R(a1, d1) R(a2, d2) R(a3, d3) about its members' axes a (--json: compounds) gives the members' "
                   "values, theirs here + d (screwkin.model.placed.ball_values)")
    for kind, what in (("universal", "two hinges"), ("cylindrical", "a hinge and a slide")):
        cs = [c for c in pm.compounds if c.type == kind]
        if cs:
            one = len(cs) == 1
            out.append(f"{len(cs)} compound {kind} joint{'' if one else 's'} ({_names([c.name for c in cs])}) "
                       f"{'is its' if one else 'are their'} {what} in one body, the massless links left out")
    return out


def _redundant_note(text: str) -> tuple:
    """(one note naming the redundant equality rows of the MJCF ``text`` from MuJoCo's efc_J at qpos0, or
    saying why they are not named; the RedundantRows as JSON, None without MuJoCo)."""
    try:
        written, rows = redundant_rows(text)
    except ImportError:
        return "the redundant equality rows are not named: MuJoCo is not installed (pip install mujoco)", None
    except Exception as exc:  # noqa: BLE001 - MuJoCo refusing the text is a bug of the writer: said, not hidden
        return f"the redundant equality rows are not named: MuJoCo refuses the written file ({exc})", None
    if not rows:
        return None, []
    n = sum(r.count for r in rows)
    shown = "; ".join(r.text() for r in rows[:6]) + ("; ... (--json: redundant_rows)" if len(rows) > 6 else "")
    return (f"{n} of MuJoCo's {written} equality rows {'is' if n == 1 else 'are'} redundant at the written zero "
            f"(the left null space of its efc_J there; rows taken in the file's order): {shown}",
            [r.as_dict() for r in rows])
