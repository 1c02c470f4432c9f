"""A mechanism's topology and mobility as text tables and JSON-ready dictionaries: the links and
joints, the counts with their formulas (Kutzbach, Gruebler), the screw-theory rows (coordinates,
constraint rank, idle and effective DOFs) and the output's motion.
"""

from __future__ import annotations

from ..model.six_bar import INVERSIONS
from .local import local_dict, local_lines, redundancy_dict, redundancy_lines
from .tables import table
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.mobility import MobilityResult
    from screwkin.model.topology import Topology
    from screwkin.model.topology import Joint

__all__ = ["topology_dict", "mobility_dict", "JOINT_COLUMNS", "joint_rows", "topology_text", "count_rows",
           "screw_theory_rows", "mobility_text"]


def _joint_dict(j: Joint) -> dict:
    return {
        "name": j.name,
        "type": j.type,
        "dof": j.dof,
        "links": list(j.links),
        "motion": j.motion,
        "contact": j.contact,
        "pair": j.pair,
        "cut": j.cut,
        "members": list(j.members),
    }


def topology_dict(topo: Topology) -> dict:
    return {
        "links": topo.n_links,
        "link_names": list(topo.links),
        "ground": topo.ground,
        "joints": [_joint_dict(j) for j in topo.joints],
        "loops": topo.loops,
        "motion_space": topo.motion_space,
        "motion_space_detail": topo.motion_space_detail,
        "six_bar": topo.six_bar,  # "Watt I" ... "Stephenson III" (model.six_bar), None for other mechanisms
        "massless_links_in_compound_joints": list(topo.dummy_links),
        "welds": list(topo.welds),
        "couplings": [{"joint": c.joint, "mimics": c.mimics, "multiplier": c.multiplier, "offset": c.offset}
                      for c in topo.couplings],
    }


def mobility_dict(r: MobilityResult) -> dict:
    t = r.topology
    out = None
    if r.output is not None:
        o = r.output
        out = {
            "link": o.link,
            "dimension": o.dimension,
            "translations": o.translations,
            "rotations": o.rotations,
            "label": o.label,
            "center": list(o.center) if o.center is not None else None,
            "twists": [list(map(float, tw)) for tw in o.twists],
        }
    d = topology_dict(t)
    d.update({
        "file": r.path,
        "kutzbach": t.kutzbach,
        "gruebler": t.gruebler,
        "J1": t.full_joints,
        "J2": t.half_joints,
        "spherical_count": t.spherical_count,
        "coordinates": r.coordinates,
        "constraint_rows": r.constraint_rows,
        "constraint_rank": r.rank,
        "mobility": r.mobility,
        "overconstraint": r.overconstraint,
        "idle_dofs": r.idle_dofs,
        "idle_links": [{"link": i.link, "dofs": i.dofs} for i in r.idle],
        "effective_mobility": r.effective_mobility,
        "effective_dofs": r.effective_dofs,
        "actuated": list(r.actuated),
        "actuation_source": r.actuation_source,
        "transmissions": [{"input": t.name, "actuator": t.actuator, "kind": t.kind, "terms": [list(x) for x in t.terms],
                           "joint": t.joint, "scale": t.scale, "offset": t.offset, "gear": t.gear}
                          for t in r.transmissions],
        "free_with_inputs_locked": r.free_with_inputs_locked,
        "classification": r.classification,
        "notes": list(r.notes),
        "output_motion": r.output.label if r.output is not None else None,
        "output": out,
        "redundant_constraints": r.redundant_constraints,
        "assembly": {"residual": r.residual, "iterations": r.iterations, "configurations_sampled": r.samples,
                     "start": r.assembly_start, "starts": r.starts, "configuration": r.configuration},
        "generic_mobility": r.generic_mobility,
    })
    if r.local is not None:
        d["local"] = local_dict(r.local)
        d["local"]["where"] = r.local_where
    if r.redundant is not None:
        d.update(redundancy_dict(r.redundant))
    return d


#: The columns of :func:`joint_rows`
JOINT_COLUMNS = ("joint", "type", "dof", "motion", "pair (contact)", "links", "loop")


def joint_rows(topo: Topology, limit: int = 48) -> list:
    """One row per joint of a Topology (columns JOINT_COLUMNS); names longer than ``limit`` shortened."""
    return [(j.name if len(j.name) <= limit else j.name[:limit - 3] + "...", j.type, j.dof, j.motion,
             f"{j.pair} ({j.contact})", f"{j.links[0]} - {j.links[1]}", "cut" if j.cut else "") for j in topo.joints]


def topology_text(topo: Topology, title: str) -> str:
    lines = [title, "", table(list(JOINT_COLUMNS), joint_rows(topo)), ""]
    lines.append(f"links N = {topo.n_links} (ground: {topo.ground})   joints J = {topo.n_joints}   "
                 f"loops L = J - N + 1 = {topo.loops}   sum f = {topo.sum_dof}"
                 + (f"   couplings C = {len(topo.couplings)}" if topo.couplings else ""))
    if topo.textbook_planar:
        lines.append(f"full joints J1 = {topo.full_joints} (one DOF: lower pairs, rolling)   "
                     f"half joints J2 = {topo.half_joints} (two DOF: sliding contacts)")
    for c in topo.couplings:
        lines.append(f"coupling (mimic): {c.joint} = {c.multiplier:g} x {c.mimics} + {c.offset:g}: "
                     f"{c.joint} is no degree of freedom of its own")
    if topo.welds:
        lines.append(f"loops closed by welds (fixed cut joints, each joining two URDF links into one link): "
                     f"{', '.join(topo.welds)}")
    if topo.dummy_links:
        lines.append(f"massless links inside compound joints (not counted): {len(topo.dummy_links)}")
    lines.append(f"motion space: {topo.motion_space} ({topo.motion_space_detail})")
    if topo.six_bar:
        lines.append(f"six-bar: {topo.six_bar}: {INVERSIONS[topo.six_bar]} ('{topo.ground}')")
    return "\n".join(lines)


def count_rows(t: Topology) -> list:
    """(count, formula with the numbers put in, value) for a Topology: Kutzbach, and Gruebler (both
    ways the textbooks write it) or the spherical count where they apply."""
    c, cv = (" - C", f" - {len(t.couplings)}") if t.couplings else ("", "")
    counts = [("Kutzbach (spatial)", f"6(N-1-J) + sum f{c} = 6({t.n_links}-1-{t.n_joints}) + {t.sum_dof}{cv}",
               t.kutzbach)]
    if t.gruebler is not None:
        counts.append(("Gruebler (planar)", f"3(N-1-J) + sum f{c} = 3({t.n_links}-1-{t.n_joints}) + {t.sum_dof}{cv}",
                       t.gruebler))
        if t.textbook_planar:
            counts.append(("Gruebler, as the textbooks write it",
                           f"3(N-1) - 2 J1 - J2{c} = 3({t.n_links}-1) - 2*{t.full_joints} - {t.half_joints}{cv}",
                           3 * (t.n_links - 1) - 2 * t.full_joints - t.half_joints - len(t.couplings)))
    if t.spherical_count is not None:
        counts.append(("spherical", f"3(N-1-J) + sum f{c} = 3({t.n_links}-1-{t.n_joints}) + {t.sum_dof}{cv}",
                       t.spherical_count))
    return counts


def screw_theory_rows(r: MobilityResult) -> list:
    """(quantity, value) rows of the screw-theory mobility of a MobilityResult."""
    t = r.topology
    rows = [
        ("joint coordinates", r.coordinates),
        ("constraint rows (cut joints)", r.constraint_rows),
        ("rank of constraint Jacobian K", r.rank),
        *([("mobility M = coordinates - rank K", r.mobility),
           ("overconstraint, spatial (rows - rank = M - Kutzbach)", r.overconstraint)]
          if r.generic_mobility in (None, r.mobility) else
          [(f"mobility M (finite, at {r.local_where}: the local analysis)", r.mobility),
           ("generic mobility = coordinates - rank K", r.generic_mobility),
           ("overconstraint, spatial (rows - rank = generic mobility - Kutzbach)", r.overconstraint)]),
        *([(f"redundant constraints {'in the plane (M - Gruebler)' if t.motion_space == 'planar' else 'on the sphere (M - spherical count)'}",
            r.redundant_constraints)] if t.motion_space != "spatial" else []),
        ("idle DOFs", r.idle_dofs),
        ("effective mobility", r.effective_mobility),
        ("actuated joints", ", ".join(r.actuated) + (f"  [{r.actuation_source}]" if r.actuated else "") or "none declared"),
        ("DOFs the actuators control", r.effective_dofs if r.effective_dofs is not None else "-"),
    ]
    if r.output is not None:
        rows.append((f"output link '{r.output.link}' can do", r.output.label))
    return rows


def answer_line(r: MobilityResult) -> str:
    """The answer first: M (the effective mobility beside it when links idle), the actuated joints, what the
    output link can do, the classification."""
    idle = r.mobility - r.effective_mobility
    acts = ", ".join(r.actuated)
    return (f"M = {r.mobility}" + (f" ({r.effective_mobility} effective, {idle} idle)" if idle else "")
            + (f", actuated by {acts}" if acts else "")
            + (f"; output link '{r.output.link}' can do {r.output.label}" if r.output is not None else "")
            + f": {r.classification}")


def mobility_text(r: MobilityResult, explain: bool = True) -> str:
    """The text of ``mobility``: the answer first, then the topology, the counts and the screw-theory table;
    ``explain`` (--explain) adds how the local analysis decided, and names the redundant constraints with the
    exactly constrained alternative (one line says how many without it)."""
    t = r.topology
    lines = [answer_line(r), "", topology_text(t, f"Mobility of {r.path}"), ""]
    lines.append(table(["count", "formula", "value"], count_rows(t)))
    lines.append("")
    rows = screw_theory_rows(r)
    lines.append(table(["screw theory", "value"], rows))
    if r.idle:
        lines.append("links in idle motions: " + ", ".join(f"{i.link} ({i.dofs})" for i in r.idle))
    lines.append("")
    lines.append(f"classification: {r.classification}")
    for n in r.notes:
        lines.append(f"note: {n}")
    if r.local is not None:
        lines += local_lines(r.local, r.local_where, explain)
    if r.redundant is not None and r.redundant.count:
        lines += redundancy_lines(r.redundant, "redundant constraints at a configuration of the generic rank"
                                  if explain else "redundant constraints", explain)
    lines.append(f"(assembled from {r.assembly_start}: closure residual {r.residual:.2e} after {r.iterations} "
                 f"iterations; generic rank taken over {r.samples} assembled configurations)")
    return "\n".join(lines)
