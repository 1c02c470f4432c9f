"""A planar mechanism's decomposition into its swept input and class-II dyads (Assur groups
of two links and three joints), from the topology alone: which links the held inputs weld
together (groups), then, from the ground, the swept input joint and dyads whose two outer
joints sit on groups already placed.  The geometry is read by screwkin.analysis.motion.dyads.
"""

from __future__ import annotations

from dataclasses import dataclass

from .topology import UnionFind
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["DyadPlan", "plan"]

_RJOINTS = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned",
            "JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned")
_PJOINTS = ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned")


@dataclass(frozen=True)
class _Pair:
    name: str
    kind: str  # "R" | "P"
    groups: tuple  # (group of link 1, group of link 2)
    tree: int | None  # the tree joint's index in the model, None for a cut joint


@dataclass(frozen=True)
class DyadPlan:
    """How a planar mechanism decomposes with its inputs held (topology only; the geometry is
    read at q0 by screwkin.analysis.motion.dyads): the group (links welded by held inputs and fixed loop
    joints) of every body, the
    swept input joint and the dyads in solving order as (kind, A, B, C) pair indices."""

    groups: tuple  # group of every body (model joint index)
    pairs: tuple  # _Pair
    swept: int  # index in pairs of the swept input joint
    dyads: tuple  # ("RRR" | "RRP" | "PRR" | "RPR", a, b, c): pair indices; a on the first link, c on the second
    order: tuple  # per op: the groups it places: (known, placed) for the input, (g1, g2) for a dyad


def _pairs(mech: Mechanism):
    """The tree and cut joints as (name, kind, body1, body2, tree index), or a reason they are not R/P."""
    model, out = mech.model, []
    for j in range(1, model.njoints):
        short = model.joints[j].shortname()
        kind = "R" if short in _RJOINTS else "P" if short in _PJOINTS else None
        if kind is None:
            return f"joint {model.names[j]} is a {short}, not a revolute or prismatic joint"
        out.append((model.names[j], kind, model.parents[j], j, j))
    for c in mech.cuts:
        if c.pair is not None or c.type not in ("revolute", "continuous", "prismatic", "fixed"):
            return f"loop joint {c.name} is a {c.pair or c.type} joint"
        kind = {"prismatic": "P", "fixed": "W"}.get(c.type, "R")  # W: a weld, the two links are one
        out.append((c.name, kind, model.frames[c.frame1].parentJoint, model.frames[c.frame2].parentJoint, None))
    return out


def plan(mech: Mechanism, inputs: list, name: str) -> DyadPlan | str:
    """The DyadPlan of ``mech`` swept along input ``name`` with the other ``inputs`` held, or a
    string saying why it does not decompose into the input and RRR/RRP/PRR/RPR dyads."""
    if mech.couplings or mech.extra_rows:
        return "coupled joints or higher pairs"
    found = _pairs(mech)
    if isinstance(found, str):
        return found
    nb = mech.model.njoints
    bodies = UnionFind(range(nb))
    held = set(inputs) - {name}
    welds = [(b1, b2) for pname, kind, b1, b2, tree in found if kind == "W" or (tree is not None and pname in held)]
    for b1, b2 in welds:
        bodies.join(b2, b1)  # b1's group under b2's representative
    groups = tuple(bodies.find(b) for b in range(nb))
    pairs, swept = [], None
    for pname, kind, b1, b2, tree in found:
        if kind == "W" or (tree is not None and pname in held):
            continue
        g = (groups[b1], groups[b2])
        if g[0] == g[1]:
            return f"joint {pname} joins two links the held inputs weld together"
        if pname == name:
            swept = len(pairs)
        pairs.append(_Pair(pname, kind, g, tree))
    if swept is None:
        return f"the input {name} is not a tree joint"
    known = {groups[0]}
    used = set()
    order, dyads = [], []
    todo = set(groups) - known
    while todo:
        sp = pairs[swept]
        if swept not in used and (sp.groups[0] in known) != (sp.groups[1] in known):
            k, u = sp.groups if sp.groups[0] in known else sp.groups[::-1]
            used.add(swept)
            known.add(u)
            todo.discard(u)
            order.append((k, u))
            continue
        step = None
        for ib, b in enumerate(pairs):
            if ib in used or ib == swept or b.groups[0] in known or b.groups[1] in known:
                continue
            g1, g2 = b.groups
            outer = []
            for g in (g1, g2):
                outer.append([i for i, p in enumerate(pairs) if i not in used and i != ib and i != swept
                              and g in p.groups and (set(p.groups) - {g}) <= known])
            for ia in outer[0]:
                for ic in outer[1]:
                    if ia != ic:
                        kinds = pairs[ia].kind + b.kind + pairs[ic].kind
                        if kinds in ("RRR", "RRP", "PRR", "RPR"):
                            step = (kinds, ia, ib, ic, g1, g2)
                            break
                if step:
                    break
            if step:
                break
        if step is None:
            return "the links left do not form a class-II dyad (RRR, RRP, PRR or RPR) on placed links"
        kinds, ia, ib, ic, g1, g2 = step
        used.update((ia, ib, ic))
        known.update((g1, g2))
        todo -= {g1, g2}
        dyads.append((kinds, ia, ib, ic))
        order.append((g1, g2))
    if swept not in used:
        return f"the input {name} moves no link"
    if len(used) != len(pairs):
        return "more joints than the dyads use (an overconstrained or a spatial loop)"
    return DyadPlan(groups, tuple(pairs), swept, tuple(dyads), tuple(order))
