"""Workspaces (screwkin.analysis.design.workspace) as text, JSON-ready dictionaries, CSV, pictures
(slices with matplotlib) and a meshcat point cloud."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin

from ..analysis.design.workspace import WorkspaceResult
from ..tolerances import DEFAULT
from .plots import pyplot
from .tables import table
from .tables import csv_text
from .outfile import write_figure, write_output

__all__ = ["workspace_dict", "workspace_text", "workspace_csv", "workspace_png", "workspace_figure", "workspace_cloud", "AXIS_NAMES"]

AXIS_NAMES = ("x", "y", "z")


def _measure_unit(dim: int) -> str:
    return "m^3" if dim == 3 else "m^2"


def axis_labels(r: WorkspaceResult) -> list:
    """Names of the grid axes: x, y, z when they are world axes, else u, v (in-plane)."""
    out = []
    for k, a in enumerate(r.axes):
        i = int(np.argmax(np.abs(a)))
        out.append(AXIS_NAMES[i] if abs(a[i]) > 1 - DEFAULT.zero else "uv"[k])
    return out


def workspace_dict(r: WorkspaceResult) -> dict:
    d = {
        "file": r.path, "output": r.output, "point": r.point, "method": r.method, "dimension": r.dimension,
        "volume": r.volume, "volume_unit": _measure_unit(r.dimension), "volume_cells": r.volume_cells,
        "free_volume": r.free_volume, "free_fraction": r.free_volume / r.volume if r.volume > 0 else None,
        "conditioning_min": r.conditioning_min, "conditioning_mean": r.conditioning_mean,
        "threshold": r.threshold, "characteristic_length": r.length, "inputs": list(r.inputs),
        "resolution": r.resolution, "axes": r.axes, "axis_names": axis_labels(r), "origin": r.origin,
        "bounds": r.bounds, "points": int(len(r.index)), "free_points": int(r.free.sum()),
        "boundary_points": int(len(r.boundary)), "free_boundary_points": int(len(r.free_boundary)),
        "solves": r.solves, "samples": r.samples, "truncated": r.truncated, "notes": list(r.notes),
        "orientation": None if r.orientation is None else r.orientation,
        "orientation_rpy": None if r.orientation is None else pin.rpy.matrixToRpy(r.orientation),
    }
    if len(r.index):
        worst = int(np.argmin(r.measures["conditioning"]))
        d["worst_conditioned_point"] = r.positions[worst]
    return d


def workspace_text(r: WorkspaceResult) -> str:
    dim, unit = r.dimension, _measure_unit(r.dimension)
    names = axis_labels(r)
    if r.method == "grid":
        what = (f"origin of '{r.output}' (any orientation)" if r.point else
                f"'{r.output}' at the constant orientation roll pitch yaw "
                + " ".join(f"{np.degrees(a):.4g}" for a in pin.rpy.matrixToRpy(r.orientation)) + " deg")
        how = (f"inverse kinematics on a {dim}-D grid of {r.resolution:.4g} m from the output's position in the "
               f"assembled configuration: {len(r.index)} points reached, {r.solves} configurations solved")
    else:
        what = f"origin of '{r.output}' (any orientation)"
        how = f"{r.samples} random joint configurations counted in cells of {r.resolution:.4g} m"
    lines = [f"Workspace of the {what}", f"  {r.path}", f"  method: {how}"]
    if dim == 2:
        plane = np.cross(r.axes[0], r.axes[1])
        lines.append("  in the plane through (" + ", ".join(f"{x:.4g}" for x in r.origin) + ") with normal ("
                     + ", ".join(f"{x:.4g}" for x in plane) + ")")
    rows = [[n, f"{lo:.6g}", f"{hi:.6g}", f"{hi - lo:.6g}"] for n, (lo, hi) in zip(names, r.bounds)]
    lines += ["", table(["axis", "from [m]", "to [m]", "extent [m]"], rows), ""]
    frac = r.free_volume / r.volume if r.volume > 0 else 0.0
    measure = ("the scan measure (smallest over largest singular value of the point's Jacobian; best of each cell)"
               if r.method == "sampling" else
               "smallest relative singular values of the passive constraint columns (actuator) and of the output's "
               "motion (serial)")
    size = "area" if r.dimension == 2 else "volume"  # (the JSON keys say volume for both, with volume_unit)
    rows = [
        [f"{size} [{unit}]", f"{r.volume:.6g}",
         "runs along the last axis extended to the boundary by bisection" if r.method == "grid" else "cells hit"],
        [f"{size}, grid cells [{unit}]", f"{r.volume_cells:.6g}", "points reached x cell size"],
        [f"singularity-free {size} [{unit}]", f"{r.free_volume:.6g}",
         f"{100 * frac:.1f} % of the {size}: measures >= {r.threshold:g}"],
        ["conditioning, worst (free part)", _value_text(r.conditioning_min), "1/condition number of the input -> output map"],
        ["conditioning, mean (free part)", _value_text(r.conditioning_mean), f"lengths divided by L = {r.length:.6g} m"],
    ]
    lines += [table(["quantity", "value", "how"], rows), "", f"  singular measures: {measure}",
              f"  inputs: {', '.join(r.inputs)}"]
    if len(r.boundary):
        lines.append(f"  boundary located at {len(r.boundary)} points (bisection to {r.resolution / 128:.2g} m), "
                     f"the threshold crossed at {len(r.free_boundary)}")
    if r.truncated:
        timed = any("time limit" in n for n in r.notes)
        lines.append("  warning: " + ("the time limit cut the workspace: the volumes are of the part reached"
                                      if timed else "the bounds cut the workspace: the volumes are of the part "
                                                    "within them"))
    lines += [f"  note: {n}" for n in r.notes]
    return "\n".join(lines)


def _value_text(x) -> str:
    return "-" if x is None else f"{x:.4g}"


def workspace_csv(r: WorkspaceResult, path: str, joint_columns: list | None = None) -> None:
    """One row per reached point (cell): world position, grid index, measures, free; with
    ``joint_columns`` ((name, q index) pairs) the joint values of the grid's solutions."""
    joint_columns = list(joint_columns or []) if r.configurations is not None else []
    head = (["x", "y", "z"] + [f"i_{n}" for n in axis_labels(r)] + ["actuator", "serial", "conditioning", "free"]
            + [n for n, _ in joint_columns])
    rows = []
    for k in range(len(r.index)):
        row = [f"{x:.9g}" for x in r.positions[k]] + [int(i) for i in r.index[k]]
        row += [f"{r.measures[m][k]:.6g}" for m in ("actuator", "serial", "conditioning")] + [int(r.free[k])]
        row += [f"{r.configurations[k, iq]:.9g}" for _, iq in joint_columns]
        rows.append(row)
    write_output(path, csv_text(head, rows))


def workspace_figure(r: WorkspaceResult, title: str | None = None):
    """The figure of :func:`workspace_png` (matplotlib, not yet saved): the conditioning over the
    plane itself (2-D), or three slices through the grid point nearest the workspace's centroid
    (3-D: the platform of a Stewart platform), each slice in mm on equal axes, the colour scale over
    the values reached (its range in the colour bar's label), the located boundary in black, where
    the measures cross the threshold in red; one legend for all the panels, below them."""
    plt = pyplot("--png")
    from matplotlib.lines import Line2D

    names = axis_labels(r)
    h = r.resolution
    cond = r.measures["conditioning"]
    mm = 1000.0
    if r.dimension == 2:
        fig, ax = plt.subplots(figsize=(7.5, 7), layout="constrained")
        panels = [(ax, 0, 1, np.ones(len(r.index), bool), None)]
    else:
        fig, axs = plt.subplots(1, 3, figsize=(16, 6.2), layout="constrained")
        c = np.round(np.mean(r.index, axis=0)).astype(int)
        panels = [(ax, a, b, r.index[:, n] == c[n], (n, c[n])) for ax, (a, b, n) in zip(axs, ((0, 1, 2), (0, 2, 1),
                                                                                              (1, 2, 0)))]
    coords = r.coordinates
    finite = cond[np.isfinite(cond)]
    lo = float(finite.min()) if finite.size else 0.0
    hi = max(float(finite.max()) if finite.size else 1.0, lo + 1e-12)
    mesh = None
    legend = {}
    for ax, a, b, sel, cut in panels:
        if not sel.any():
            ax.set_axis_off()
            continue
        ia, ib = r.index[sel, a], r.index[sel, b]
        grid = np.full((ib.max() - ib.min() + 1, ia.max() - ia.min() + 1), np.nan)
        grid[ib - ib.min(), ia - ia.min()] = cond[sel]
        ca, cb = coords[sel, a], coords[sel, b]
        extent = tuple(mm * v for v in (ca.min() - h / 2, ca.min() + (grid.shape[1] - 0.5) * h, cb.min() - h / 2,
                                        cb.min() + (grid.shape[0] - 0.5) * h))
        mesh = ax.imshow(grid, origin="lower", extent=extent, cmap="viridis", vmin=lo, vmax=hi,
                         interpolation="nearest")
        notfree = sel & ~r.free
        if notfree.any():
            ax.plot(mm * coords[notfree, a], mm * coords[notfree, b], "x", color="0.5", ms=4)
            legend[f"measure < {r.threshold:g}"] = Line2D([], [], marker="x", color="0.5", linestyle="")
        for pts, color, label in ((r.boundary, "k", "boundary (located)"),
                                  (r.free_boundary, "r", f"threshold {r.threshold:g} crossed")):
            if len(pts):
                P = pts @ r.axes.T
                near = np.ones(len(P), bool) if cut is None else np.abs(P[:, cut[0]] - (r.axes[cut[0]] @ r.origin
                                                                                          + cut[1] * h)) < h / 2
                if near.any():
                    ax.plot(mm * P[near, a], mm * P[near, b], ".", color=color, ms=4)
                    legend[label] = Line2D([], [], marker=".", color=color, linestyle="", ms=6)
        pad = 0.6 * h * mm
        ax.set_xlim(extent[0] - pad, extent[1] + pad)
        ax.set_ylim(extent[2] - pad, extent[3] + pad)
        ax.set_xlabel(f"{names[a]} [mm]", fontsize=11)
        ax.set_ylabel(f"{names[b]} [mm]", fontsize=11)
        ax.set_aspect("equal")
        ax.grid(True, color="0.85", linewidth=0.5)
        ax.set_axisbelow(True)
        ax.tick_params(labelsize=9)
        if cut is not None:
            at = mm * (r.axes[cut[0]] @ r.origin + cut[1] * h)
            ax.set_title(f"slice {names[cut[0]]} = {at:.1f} mm", fontsize=11)
    if mesh is not None:
        fig.colorbar(mesh, ax=[p[0] for p in panels], shrink=0.85,
                     label=f"conditioning (1 / condition number): {lo:.3g} to {hi:.3g}")
    if legend:
        fig.legend(list(legend.values()), list(legend), loc="outside lower center", ncol=len(legend), fontsize=10)
    what = ("a point, orientation free" if r.point else "position at fixed orientation"
            if r.dimension == 3 and r.orientation is not None else "pose")
    fig.suptitle(title or (f"{Path(str(r.path)).stem}: workspace of '{r.output}' ({what})\n{r.volume:.4g} "
                           f"{_measure_unit(r.dimension)}, singularity-free {r.free_volume:.4g} {_measure_unit(r.dimension)}, "
                           f"grid step {mm * h:.3g} mm"), fontsize=12)
    return fig


def workspace_png(r: WorkspaceResult, path: str) -> None:
    """The conditioning over the workspace, in slices (see :func:`workspace_figure`)."""
    plt = pyplot("--png")
    fig = workspace_figure(r)
    try:
        write_figure(fig, path, dpi=100, metadata={"Title": fig._suptitle.get_text()})
    finally:
        plt.close(fig)


def workspace_cloud(r: WorkspaceResult, viewer, size=None) -> None:
    """The reached points as a meshcat point cloud, coloured by conditioning (viridis-like
    ramp from dark blue to yellow), points below the threshold grey."""
    import meshcat.geometry as g

    cond = r.measures["conditioning"]
    top = max(float(cond.max()), 1e-12) if len(cond) else 1.0
    t = np.clip(cond / top, 0, 1)[:, None]
    dark, light = np.array([0.27, 0.0, 0.33]), np.array([0.99, 0.91, 0.14])
    colors = (1 - t) * dark + t * light
    colors[~r.free] = 0.6
    points = g.PointCloud(position=r.positions.T.astype(np.float32), color=colors.T.astype(np.float32),
                          size=float(size or r.resolution * 0.6))
    viewer["screwkin/workspace/points"].set_object(points)
    if len(r.boundary):
        viewer["screwkin/workspace/boundary"].set_object(g.PointCloud(
            position=r.boundary.T.astype(np.float32), color=np.zeros((3, len(r.boundary)), np.float32),
            size=float(size or r.resolution * 0.3)))
