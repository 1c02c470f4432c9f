"""Pictures of results with matplotlib (optional: ``pip install -e '.[plot]'``)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import UsageError
from ..model.geometry import plane_basis
from ..tolerances import DEFAULT
from ..units import Quantity, in_unit, si_factor
from .tables import input_rate_words
from .outfile import write_figure
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.motion.links import MotionAlong
    from screwkin.analysis.motion.sweep import SweepResult
    from screwkin.analysis.singularities.maps import SingularityMap
    from screwkin.present.tables import RateUnits

__all__ = ["sweep_plot", "motion_figure", "sweep_figure", "map_png", "map_figure", "pyplot"]


def pyplot(option: str):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise UsageError(f"{option} needs matplotlib: pip install matplotlib") from None
    return plt


#: How the kinds of located singularities are named on a sweep plot
_KIND_LABEL = {"actuator": "actuator singularity", "serial": "serial singularity",
               "constraint": "constraint singularity"}


def _nearest_turn(angle, along):
    """The angle plus the whole turn that puts it nearest the (unwrapped) values ``along``."""
    if not len(along):
        return angle
    k = np.round((along - angle) / (2 * np.pi))
    cand = angle + 2 * np.pi * k
    return float(cand[np.argmin(np.abs(cand - along))])


def _rate_scales(units: RateUnits) -> list:
    """The rows' units and factors (SI value x factor = value shown) of a sweep figure: angles in deg and
    lengths in mm; rates and accelerations in ``units`` (tables.RateUnits: those typed with --rate, as the
    tables show them), or deg/s and mm/s (per s^2) when None."""
    if units is None:
        return [("deg", "mm"), ("deg/s", "mm/s"), ("deg/s²", "mm/s²")]
    return [("deg", "mm"), (units.rate(False), units.rate(True)),
            (units.acceleration(False), units.acceleration(True))]


def sweep_figure(res: SweepResult, mus: list | None=None, singularities: tuple | list=(), title: str | None = None, linear: np.ndarray | None=None, paths: dict | None = None, absolute: bool=False,
                 rate_words: str | None=None, units=None):
    """The figure of :func:`sweep_plot` (matplotlib, not yet saved): three rows -- joint values,
    rates, accelerations -- against the input.  Angles are unwrapped along the motion and drawn
    in degrees on the left axis, lengths in mm on a right axis of their own (dashed); every
    curve has a legend entry; each located singularity (``SweepSingularity``: the sweep's limit
    positions and those of ``--singularities``) is a vertical line, with its kind in the legend.
    linear: mask of the coordinates that are lengths (``Mechanism.translational``; default: none).
    mus: the transmission angle at each step [rad], drawn in degrees with the joint angles.
    rate_words: what the rates are for (tables.input_rate_words: "at crank 120 rpm"; default "per 1 rad/s
    of crank" from the sweep's rate), on the rate and acceleration axes and in the title.
    units: the units of the rates and accelerations (tables.RateUnits, those typed: --rate 120rpm draws rpm
    and rpm/s, as the tables show them); None: deg/s and mm/s, per s for the accelerations."""
    plt = pyplot("--plot")
    n = len(res.names)
    linear = np.zeros(n, bool) if linear is None or len(linear) != n else np.asarray(linear, bool)
    x_deg = res.unit == "rad"
    xr = np.unwrap(np.asarray(res.values, float)) if x_deg else np.asarray(res.values, float)
    x = np.degrees(xr) if x_deg else 1000.0 * xr
    x_unit = "deg" if x_deg else "mm"
    joints = np.array(res.joints, float)
    if joints.ndim == 2 and joints.shape[1] == n and len(joints):
        joints[:, ~linear] = np.unwrap(joints[:, ~linear], axis=0)
    first = "absolute angle, position" if absolute else "joint value"
    rates_what = "omega, rate" if absolute else "rate"
    rate_words = rate_words or input_rate_words(res.input, Quantity(res.rate), not x_deg)
    shown = [(a.replace("^2", "²"), b.replace("^2", "²")) for a, b in _rate_scales(units)]
    rows = [(first, joints, *shown[0]),
            (f"{rates_what} ({rate_words})", np.asarray(res.rates), *shown[1]),
            (f"{'alpha, acceleration' if absolute else 'acceleration'} ({rate_words})", np.asarray(res.accelerations),
             *shown[2])]
    if paths:
        fig = plt.figure(figsize=(8, 13))
        grid = fig.add_gridspec(4, 1, height_ratios=[1, 1, 1, 1.4])
        axes = [fig.add_subplot(grid[0])]
        axes += [fig.add_subplot(grid[k], sharex=axes[0]) for k in (1, 2)]
        path_ax = fig.add_subplot(grid[3])
        for k, (name, xy) in enumerate(paths.items()):
            path_ax.plot(1000 * xy[:, 0], 1000 * xy[:, 1], color=f"C{k}", label=f"{name} (path)")
            path_ax.plot(1000 * xy[0, 0], 1000 * xy[0, 1], "o", color=f"C{k}", markersize=4)
        path_ax.set_aspect("equal", adjustable="datalim")
        path_ax.set_xlabel("x [mm] (in the plane)")
        path_ax.set_ylabel("y [mm]")
        path_ax.legend(fontsize=7, loc="best")
        path_ax.set_title("point paths (a dot at the first step)", fontsize=9)
    else:
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 9))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for r, (what, data, a_unit, l_unit) in enumerate(rows):
        ax = axes[r]
        scale = np.where(linear, si_factor(l_unit), si_factor(a_unit))
        handles = []
        twin = ax.twinx() if linear.any() else None
        for k, name in enumerate(res.names):
            if data.ndim != 2 or data.shape[1] <= k:
                continue
            on = twin if linear[k] else ax
            (h,) = on.plot(x, data[:, k] * scale[k], color=colors[k % len(colors)], linestyle="--" if linear[k] else "-",
                           label=f"{name} [{l_unit if linear[k] else a_unit}]")
            handles.append(h)
        if r == 0 and mus is not None:
            (h,) = ax.plot(x, np.degrees(np.asarray(mus, float)), color="k", linestyle=":", linewidth=1.5,
                           label="transmission angle [deg]")
            handles.append(h)
        if not linear.all():
            ax.set_ylabel(f"{what} [{a_unit}]")
        if twin is not None:
            twin.set_ylabel(f"{what} [{l_unit}]" if linear.all() else f"{what.split(' (')[0]}, sliding [{l_unit}]")
        if linear.all():
            ax.set_yticks([])
        seen = set()
        for s in singularities:
            xs = float(np.degrees(_nearest_turn(s.input, xr)) if x_deg else 1000.0 * s.input)
            label = "limit position" if s.limit else _KIND_LABEL.get(s.kind, s.kind)
            h = ax.axvline(xs, color="crimson" if s.limit else "darkorange", linestyle="-." if s.limit else "--",
                           linewidth=1.0, label=label if label not in seen else None)
            if r == 0 and label not in seen:
                handles.append(h)
            seen.add(label)
        if r == 0 or len(handles) > 0:
            ax.legend(handles=handles, fontsize=7, loc="best", ncol=2 if len(handles) > 6 else 1)
    axes[2].set_xlabel(f"input {res.input} [{x_unit}]")
    fig.suptitle(title or f"sweep of {res.input}, {rate_words}", fontsize=11)
    fig.tight_layout()
    return fig


def absolute_series(res: SweepResult, motion: MotionAlong, linear: np.ndarray | None=None) -> tuple | None:
    """The sweep's curves in absolute quantities (issue 24): for a planar mechanism each link that
    turns (its vector-loop angle, omega, alpha about the plane's normal) and each slider coordinate
    (prismatic tree or loop joint: position, rate, acceleration); ``res`` with those as its
    ``names``/``joints``/``rates``/``accelerations``, and their length mask.  None when there are no
    absolute angles (a spatial mechanism): the joints are drawn then."""
    links = {n: m for n, m in (motion.links if motion is not None else {}).items() if "angle" in m}
    if not links:
        return None
    names, values, rates, accs, lengths = [], [], [], [], []
    for name, m in links.items():
        angle = np.unwrap(np.asarray(m["angle"], float))
        if np.ptp(angle) < DEFAULT.equal and np.ptp(np.asarray(m["omega"], float)) < DEFAULT.equal:
            continue  # a link that does not turn (a slider block): its position is the slider's coordinate
        names.append(f"{name} (angle)")
        values.append(angle), rates.append(np.asarray(m["omega"])), accs.append(np.asarray(m["alpha"]))
        lengths.append(False)
    mask = np.zeros(len(res.names), bool) if linear is None or len(linear) != len(res.names) else np.asarray(linear)
    for k in np.flatnonzero(mask):
        names.append(res.names[k])
        values.append(res.joints[:, k]), rates.append(res.rates[:, k]), accs.append(res.accelerations[:, k])
        lengths.append(True)
    for name, v in motion.loop_joints.items():
        if name not in motion.angular_loop:
            names.append(f"{name} (loop)")
            values.append(v), rates.append(motion.loop_rates[name]), accs.append(motion.loop_accelerations[name])
            lengths.append(True)
    stack = lambda cols: np.stack(cols, axis=1) if cols else np.zeros((len(res.values), 0))  # noqa: E731
    return replace(res, names=tuple(names), joints=stack(values), rates=stack(rates),
                   accelerations=stack(accs)), np.array(lengths, bool)


def motion_figure(res: SweepResult, mus: list | None=None, singularities: list=(), title: str | None = None, linear: np.ndarray | None=None, motion: MotionAlong | None = None, normal=None,
                  rate_words: str | None=None, units=None):
    """The figure of a sweep (matplotlib, not yet saved; see :func:`sweep_figure` for what is drawn): for
    a planar mechanism with ``motion`` (analysis.motion.links.MotionAlong) the links' absolute angle,
    omega and alpha and the sliders' coordinates, else the joint values; the named points' paths in a
    fourth panel (in the plane of ``normal``, default the motion's).  ``sweep --plot`` and ``report``."""
    absolute = absolute_series(res, motion, linear)
    if absolute is not None:
        res, linear = absolute
    paths = {}
    if motion is not None and motion.points:
        normal = normal if normal is not None else motion.normal
        e1, e2, _ = plane_basis(normal if normal is not None else (0.0, 0.0, 1.0))
        paths = {n: np.asarray(p["position"]) @ np.stack([e1, e2], axis=1) for n, p in motion.points.items()}
    return sweep_figure(res, mus, singularities, title, linear, paths=paths, absolute=absolute is not None,
                        rate_words=rate_words, units=units)


def sweep_plot(res: SweepResult, path: str, mus: list | None=None, singularities: list=(), title: str | None = None, linear: np.ndarray | None=None, motion: MotionAlong | None=None, normal=None,
               rate_words: str | None=None, units=None) -> None:
    """A sweep into a PNG: :func:`motion_figure`, saved."""
    plt = pyplot("--plot")
    fig = motion_figure(res, mus, singularities, title, linear, motion, normal, rate_words, units)
    try:
        write_figure(fig, path, dpi=100)
    finally:
        plt.close(fig)


def _axis_values(values: np.ndarray, unit: str):
    """SI values in ``unit`` (a unit of screwkin.units as typed, any case: 'deg', 'MM'; bare: SI)."""
    return in_unit(np.asarray(values, float), unit) if unit else np.asarray(values, float)


def map_figure(res: SingularityMap, x_unit: str = "rad", y_unit: str = "rad", title: str | None = None):
    """The figure of :func:`map_png` (matplotlib, not yet saved): log10 of the smallest relative
    singular value over the two inputs, with the axes in ``x_unit`` and ``y_unit`` (the units the
    user typed: 'deg', 'mm', ...; SI values are divided by the unit's factor), the curve
    sigma = 1e-2, and the cells the continuation did not reach on the mapped assembly mode
    (``res.reached`` False) blank and hatched, with a legend entry of their own -- no colour is
    drawn across the jump between two modes."""
    plt = pyplot("--png")
    from matplotlib.patches import Patch, Rectangle

    fig, ax = plt.subplots(figsize=(7, 5.5))
    xs, ys = _axis_values(res.xs, x_unit), _axis_values(res.ys, y_unit)
    X, Y = np.meshgrid(xs, ys)
    reached = np.isfinite(res.log_sigma) if res.reached is None else np.asarray(res.reached, bool)
    shown = np.ma.masked_where(~reached | ~np.isfinite(res.log_sigma), res.log_sigma)
    hx0 = abs(xs[1] - xs[0]) / 2 if len(xs) > 1 else 0.5
    hy0 = abs(ys[1] - ys[0]) / 2 if len(ys) > 1 else 0.5
    ax.add_patch(Rectangle((xs.min() - hx0, ys.min() - hy0), np.ptp(xs) + 2 * hx0, np.ptp(ys) + 2 * hy0,
                           facecolor="0.92", edgecolor="0.6", hatch="//", linewidth=0.0, zorder=0))
    mesh = ax.pcolormesh(X, Y, shown, shading="nearest", cmap="viridis", zorder=1)
    fig.colorbar(mesh, ax=ax, label="log10 smallest relative singular value")
    handles = []
    if (~reached).any():
        handles.append(Patch(facecolor="0.92", edgecolor="0.6", hatch="//", label="not reached on this assembly mode"))
    seams = res.seams
    if seams is not None and len(seams):
        from matplotlib.collections import LineCollection

        hx = np.diff(xs).mean() / 2 if len(xs) > 1 else 0.5
        hy = np.diff(ys).mean() / 2 if len(ys) > 1 else 0.5
        segs = []
        for j, i, j2, i2 in seams:
            xm, ym = (xs[i] + xs[i2]) / 2, (ys[j] + ys[j2]) / 2
            segs.append([(xm, ym - hy), (xm, ym + hy)] if i2 != i else [(xm - hx, ym), (xm + hx, ym)])
        ax.add_collection(LineCollection(segs, colors="red", linewidths=2.0))
        handles.append(Patch(facecolor="red", edgecolor="red", label="seam: neighbours on different sheets"))
    finite = shown.compressed()
    if finite.size and finite.min() < -2 < finite.max():
        ax.contour(X, Y, shown, levels=[-2.0], colors="white", linewidths=1.2)
        handles.append(Patch(facecolor="0.3", edgecolor="white", label="singular (sigma < 1e-2): white curve"))
    if handles:
        ax.legend(handles=handles, loc="upper right", fontsize=8, framealpha=0.9)
    ax.set_xlabel(f"{res.x_name} [{x_unit}]")
    ax.set_ylabel(f"{res.y_name} [{y_unit}]")
    ax.set_title(title or f"singularity map over {res.x_name} and {res.y_name}", fontsize=10)
    fig.tight_layout()
    return fig


def map_png(res: SingularityMap, path: str, x_unit: str = "rad", y_unit: str = "rad", title: str | None = None) -> None:
    """A singularity map (SingularityMap) as a heat map with the singular curves (see :func:`map_figure`)."""
    plt = pyplot("--png")
    fig = map_figure(res, x_unit, y_unit, title)
    ax = fig.axes[0]
    try:
        write_figure(fig, path, dpi=100, metadata={"Title": ax.get_title(),
                                                   "Description": f"x: {ax.get_xlabel()}; y: {ax.get_ylabel()}"})
    finally:
        plt.close(fig)
