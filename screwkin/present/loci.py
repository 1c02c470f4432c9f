"""The traced singular loci of ``map --loci`` as JSON, text and a picture (issue 44).

Coordinates in the plane are written in the units the user typed for --x and --y."""

from __future__ import annotations

import numpy as np

from ..model.state import KinematicState
from ..units import in_unit
from .outfile import write_figure
from .plots import pyplot
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.singularities.loci import Loci
    from screwkin.analysis.singularities.regions import Regions
    from collections.abc import Sequence

__all__ = ["connections_dict", "connections_lines", "loci_dict", "loci_lines", "loci_png"]

_COLOURS = {"actuator": "tab:red", "serial": "tab:blue", "constraint": "tab:purple"}


def _xy(p: Sequence[float], xu: str, yu: str) -> list:
    return [float(in_unit(p[0], xu)), float(in_unit(p[1], yu))]


def loci_dict(loci: Loci, regions: Regions, x_unit: str, y_unit: str, loops=None, mech: Mechanism | None = None) -> dict:
    """The keys ``map --loci --json`` adds: loci [{kind, points, closed, sigma_max}], cusps, nodes,
    regions [{sample, modes, certain, how}], complete, cusps_complete, how, loci_notes; with --connect, connections
    [{cusp, start, radius, modes, joined, turn, sigma_min, path: [{inputs, joints}]}] (modes: the indices
    of the start's solutions, 0-based) and connections_tried."""
    out = {
        "loci": [{"kind": lc.kind, "points": [_xy(p, x_unit, y_unit) for p in lc.points], "closed": lc.closed,
                  "sigma_max": lc.residual} for lc in loci.loci],
        "cusps": [_xy(p, x_unit, y_unit) for p, _ in loci.cusps],
        "cusp_kinds": [k for _, k in loci.cusps],
        "nodes": [_xy(p, x_unit, y_unit) for p, _ in loci.nodes],
        "node_kinds": [k for _, k in loci.nodes],
        "complete": loci.complete,
        "cusps_complete": loci.cusps_complete,
        "loci_kinds": list(loci.traced),
        "how": loci.how,
        "loci_notes": list(loci.notes),
    }
    if regions is not None:
        out["regions"] = [{"sample": _xy(r.sample, x_unit, y_unit), "modes": r.modes, "certain": r.certain,
                           "how": r.how, "nodes": r.nodes} for r in regions.regions]
        out["regions_how"] = regions.resolution
        out["loci_notes"] += list(regions.notes)
    if loops is not None:
        found, tried = loops
        out["connections"] = [
            {"cusp": _xy(c.cusp, x_unit, y_unit), "start": _xy(c.start, x_unit, y_unit),
             "radius": _xy(c.radius, x_unit, y_unit), "modes": list(c.modes), "joined": c.loop.joined,
             "turn": "counter-clockwise" if c.turn > 0 else "clockwise", "sigma_min": c.loop.sigma_min,
             "path": [{"inputs": _xy(p, x_unit, y_unit), "joints": mech.joint_values(q)}
                      for p, q in zip(c.loop.inputs[::20], c.loop.q[::20])]}
            for c in found]
        out["connections_tried"] = tried
    return out


def loci_lines(loci: Loci, regions: Regions, x_name: str, y_name: str, x_unit: str, y_unit: str, loops=None,
               modes: str = "assembly modes") -> list:
    """Text lines: each curve, the cusps, nodes and regions (``modes``: what they count), and how they were found."""
    def pt(p: Sequence[float]) -> str:
        a, b = _xy(p, x_unit, y_unit)
        return f"({x_name} = {a:.9g} {x_unit}, {y_name} = {b:.9g} {y_unit})"

    lines = []
    kinds = sorted({lc.kind for lc in loci.loci})
    for kind in kinds:
        curves = [lc for lc in loci.loci if lc.kind == kind]
        lines.append(f"{kind} singular loci: {len(curves)} curve{'s' if len(curves) != 1 else ''} traced, "
                     f"{sum(len(c.points) for c in curves)} points, each on the singular condition "
                     f"(relative sigma_min at most {max(c.residual for c in curves):.1e})")
        for c in curves:
            lines.append(f"  {'closed curve' if c.closed else 'curve'} of {len(c.points)} points from "
                         f"{pt(c.points[0])} to {pt(c.points[-1])}")
    if not loci.loci:
        lines.append(f"no {' or '.join(loci.traced)} singular locus found in the box" if loci.traced else
                     "no singular locus traced (see below)")
    for p, kind in loci.cusps:
        lines.append(f"cusp ({kind}: three {modes} meet) at {pt(p)}")
    for p, kind in loci.nodes:
        lines.append(f"node ({kind} loci cross) at {pt(p)}")
    if regions is not None:
        for r in regions.regions:
            count = "not counted" if r.modes is None else f"{r.modes} {modes} ({r.how})"
            lines.append(f"region of {r.nodes} grid points, sample {pt(r.sample)}: {count}")
        lines.append(regions.resolution)
        lines += list(regions.notes)
    if loops is not None:
        found, tried = loops
        for c in found:
            lines.append(f"mode {c.modes[0] + 1} -> mode {c.modes[1] + 1 if c.modes[1] is not None else '?'} without a "
                         f"singularity: once round the cusp at {pt(c.cusp)}, "
                         f"{'counter-clockwise' if c.turn > 0 else 'clockwise'} from {pt(c.start)} "
                         f"(smallest actuator measure {c.loop.sigma_min:.2g})")
        lines.append(f"{len(found)} of {tried} loops round the cusps change the assembly mode without a singularity")
    lines.append(f"complete: {'yes' if loci.complete else 'not claimed'}; cusps complete: "
                 f"{'yes' if loci.cusps_complete else 'not claimed'}; {loci.how}")
    lines += list(loci.notes)
    return lines


def loci_png(loci: Loci, regions: Regions, path: str, xs: np.ndarray, ys: np.ndarray, x_name: str, y_name: str, x_unit: str, y_unit: str, title: str | None = None) -> None:
    """Loci by kind, cusps and nodes, regions shaded by their number of assembly modes."""
    plt = pyplot("--png")
    fig, ax = plt.subplots(figsize=(7, 6))
    try:
        X, Y = in_unit(np.asarray(xs), x_unit), in_unit(np.asarray(ys), y_unit)
        if regions is not None and regions.regions:
            counts = np.full(regions.labels.shape, np.nan)
            for k, r in enumerate(regions.regions):
                if r.modes is not None:
                    counts[regions.labels == k + 1] = r.modes
            if np.isfinite(counts).any():
                top = int(np.nanmax(counts))
                mesh = ax.pcolormesh(X, Y, counts, cmap="Greys", vmin=0, vmax=max(top, 1) * 1.6, shading="nearest")
                fig.colorbar(mesh, ax=ax, label="real assembly modes")
            for r in regions.regions:
                if r.modes is not None:
                    a, b = _xy(r.sample, x_unit, y_unit)
                    ax.annotate(str(r.modes), (a, b), ha="center", va="center", fontsize=8)
        shown = set()
        for lc in loci.loci:
            P = np.array([_xy(p, x_unit, y_unit) for p in lc.points])
            label = None if lc.kind in shown else f"{lc.kind} singularity"
            shown.add(lc.kind)
            style = {"color": _COLOURS.get(lc.kind, "k"), "label": label}
            if len(P) == 1:
                ax.plot(P[:, 0], P[:, 1], "o", ms=4, **style)
            else:
                ax.plot(P[:, 0], P[:, 1], "-", lw=1.4, **style)
        if loci.cusps:
            C = np.array([_xy(p, x_unit, y_unit) for p, _ in loci.cusps])
            ax.plot(C[:, 0], C[:, 1], "*", ms=11, color="gold", mec="k", label="cusp")
        if loci.nodes:
            N = np.array([_xy(p, x_unit, y_unit) for p, _ in loci.nodes])
            ax.plot(N[:, 0], N[:, 1], "s", ms=5, mfc="none", mec="k", label="node")
        ax.set_xlim(X.min(), X.max())
        ax.set_ylim(Y.min(), Y.max())
        ax.set_xlabel(f"{x_name} [{x_unit}]")
        ax.set_ylabel(f"{y_name} [{y_unit}]")
        ax.set_title(title or f"singular loci over {x_name} and {y_name}")
        if shown or loci.cusps:
            ax.legend(loc="best", fontsize=8)
        write_figure(fig, path, dpi=100, metadata={"Title": ax.get_title()})
    finally:
        plt.close(fig)


def connections_dict(conns, mech: Mechanism, output_frame: int | None = None) -> dict:
    """The keys ``solve``/``ik --all --connect --json`` add: connections [{modes: [i, j] (numbered as the
    listing, from 1), joined, proved, why, plane, sigma_min, path: [{joints, output_pose (with an output)}]}],
    det_signs (each mode's, null where no argument), connections_how, connections_notes."""
    out = []
    for c in conns.connections:
        path = []
        for q in (c.path if c.path is not None else []):
            point = {"joints": mech.joint_values(q)}
            if output_frame is not None:
                point["output_pose"] = KinematicState(mech, q).frame_pose(output_frame).tolist()
            path.append(point)
        out.append({"modes": [c.modes[0] + 1, c.modes[1] + 1], "joined": c.joined, "proved": c.proved,
                    "why": c.why, "plane": list(c.plane) if c.plane else None, "sigma_min": c.sigma_min,
                    "path": path})
    return {"connections": out, "det_signs": list(conns.signs), "connections_how": conns.how,
            "connections_notes": list(conns.notes)}


def connections_lines(conns, what: str = "modes") -> list:
    """Text: one line per pair, then how and the notes."""
    lines = [f"{what} {c.modes[0] + 1} and {c.modes[1] + 1}: "
             + (c.why if c.joined or c.why.startswith("unknown") else f"not joined: {c.why}")
             for c in conns.connections]
    if not conns.connections and conns.signs:
        lines.append(f"no pair of {what} to compare: {len(conns.signs)} listed")
    return lines + [f"connections: {conns.how}"] + list(conns.notes)
