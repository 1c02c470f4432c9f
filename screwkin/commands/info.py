"""screwkin info: the topology table (links, joints, loops), or with --joint-types the joint vocabulary."""

from __future__ import annotations

from ..errors import ScrewkinError, UsageError
from ..model.joint_types import JOINT_TYPES
from ..present.report import joint_types_dict, joint_types_text
from ..present.mobility import topology_dict, topology_text
from ._common import emit
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "info"
NEEDS_MECHANISM = "optional"  # --joint-types needs no FILE


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser(NAME, help="topology table: links, joints, loops (--joint-types: the joint vocabulary)")
    common(sp, optional_file=True)
    sp.add_argument("--joint-types", action="store_true",
                    help="list every joint type screwkin knows (DOF, motion, pair, contact); needs no FILE")


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    if args.joint_types:
        return emit(args, lambda: {"joint_types": joint_types_dict(JOINT_TYPES)}, lambda: joint_types_text(JOINT_TYPES))
    if mech is None:
        raise UsageError("info needs a FILE (or --joint-types)")
    try:
        q = mech.assemble().q
        note = None
    except ScrewkinError as exc:
        q = mech.neutral()
        note = f"not assembled ({exc}); geometry read at the file's configuration"
    topo = mech.topology(q)

    def data():
        d = topology_dict(topo)
        d.update({"file": mech.path, "actuated": mech.actuated, "cut_joints": [c.name for c in mech.cuts],
                  "coordinates": mech.nv, "assembled": note is None})
        return d

    def text() -> str:
        lines = [topology_text(topo, f"Topology of {mech.path}"), f"actuated: {', '.join(mech.actuated) or 'none declared'}"]
        return "\n".join(lines + ([f"note: {note}"] if note else []))

    return emit(args, data, text)
