"""``screwkin export``: the mechanism written as MJCF (MuJoCo) or URDF with ``<loop_joint>``,
at an assembled configuration, so that its loops are closed in the file (MuJoCo's equalities
take their second point from qpos0)."""

from __future__ import annotations

import os

from ..errors import UsageError, quote
from ..files.exporter import write_mjcf, write_placed_urdf
from ..model.placed import check_closed, placed
from ..present.report import to_jsonable
from ..present.outfile import write_output
from ._common import add_configuration_options, configuration, emit, with_mode

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "export"
NEEDS_MECHANISM = True


def add_parser(sub, common, scaled):
    sp = sub.add_parser(NAME, help="write the mechanism as MJCF (MuJoCo) or URDF, assembled (loops closed in the file)")
    common(sp)
    sp.add_argument("--mjcf", metavar="OUT.xml", help="write MJCF here: loops as <equality> connect/weld")
    sp.add_argument("--urdf", metavar="OUT.urdf", help="write URDF here: loops as <loop_joint>")
    add_configuration_options(sp)


def run(mech, args) -> int:
    if not args.mjcf and not args.urdf:
        raise UsageError("export needs --mjcf OUT.xml or --urdf OUT.urdf (or both)")
    q = configuration(mech, args)
    residual = check_closed(mech, q, 1e3 * mech.tolerances.closure)
    values = {k: float(v) for k, v in mech.joint_values(q).items()}
    comment = (f"Written by screwkin export from {os.path.basename(mech.path)} at an assembled configuration "
               f"(loop residual {residual:.1e}): the file's zero configuration is that one, so each joint's value "
               "here is its value there minus: " + ", ".join(f"{k} {v:.9g}" for k, v in values.items()))
    written, notes = [], []
    for fmt, out in (("MJCF", args.mjcf), ("URDF", args.urdf)):
        if not out:
            continue
        pm = placed(mech, q, fmt, comment=comment)
        notes += [n for n in pm.notes if n not in notes]
        if fmt == "MJCF":
            write_output(out, write_mjcf(pm))
            for c in pm.cuts:
                if c.type in ("revolute", "continuous"):
                    notes.append(f"loop joint {quote(c.name)} (revolute): two <connect>s {pm.length:.3g} m apart on "
                                 "its axis (MJCF has no hinge equality; one of their 6 rows is redundant)")
                elif c.type not in ("spherical", "fixed"):
                    notes.append(f"loop joint {quote(c.name)} ({c.type}): a massless body {quote(c.name + '~F1')} "
                                 "carrying its motion, welded to the second link (MJCF has no such equality)")
            light = [b.name for b in pm.bodies if b.joint is not None and b.joint.type != "fixed" and b.mass <= 0]
            if light:
                notes.append(f"{len(light)} moving bodies without mass ({', '.join(quote(n, 30) for n in light[:3])}"
                             f"{', ...' if len(light) > 3 else ''}) get 1e-6 kg, which MuJoCo needs")
        else:
            write_output(out, write_placed_urdf(pm, mech.spec.root))
        written.append({"format": fmt, "path": str(out), "bodies": len(pm.bodies), "loop_joints": len(pm.cuts)})

    def data():
        return to_jsonable(with_mode(args, {"file": mech.path, "written": written, "configuration": values,
                                            "residual": residual, "notes": notes}))

    def text():
        lines = [f"wrote {w['path']} ({w['format']}): {w['bodies']} bodies, {w['loop_joints']} loop joints, at the "
                 f"assembled configuration (residual {residual:.1e})" for w in written]
        lines.append("joint values there (the written file's zero): "
                     + ", ".join(f"{k} = {v:.6g}" for k, v in values.items()))
        lines += [f"note: {n}" for n in notes]
        lines.append("note: visual geometry is not written; inertias are Pinocchio's (links fixed together merged)")
        return "\n".join(lines)

    return emit(args, data, text)
