"""Pictures of results with matplotlib (optional: ``pip install -e '.[plot]'``)."""

from __future__ import annotations

import numpy as np

from ..errors import UsageError

__all__ = ["sweep_plot", "sweep_figure", "map_png"]


def _pyplot(option):
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


def sweep_figure(res, mus=None, singularities=(), title=None, linear=None):
    """The figure of :func:`sweep_plot` (matplotlib, not yet saved): three rows -- joint values,
    rates, accelerations -- against the input.  Angles are unwrapped along the motion and drawn
    in degrees on the left axis, lengths in mm on a right axis of their own (dashed); every
    curve has a legend entry; each located singularity (``SweepSingularity``: the sweep's limit
    positions and those of ``--singularities``) is a vertical line, with its kind in the legend.
    linear: mask of the coordinates that are lengths (``Mechanism.translational``; default: none).
    mus: the transmission angle at each step [rad], drawn in degrees with the joint angles."""
    plt = _pyplot("--plot")
    n = len(res.names)
    linear = np.zeros(n, bool) if linear is None or len(linear) != n else np.asarray(linear, bool)
    x_deg = res.unit == "rad"
    xr = np.unwrap(np.asarray(res.values, float)) if x_deg else np.asarray(res.values, float)
    x = np.degrees(xr) if x_deg else 1000.0 * xr
    x_unit = "deg" if x_deg else "mm"
    joints = np.array(res.joints, float)
    if joints.ndim == 2 and joints.shape[1] == n and len(joints):
        joints[:, ~linear] = np.unwrap(joints[:, ~linear], axis=0)
    scale = np.where(linear, 1000.0, 180.0 / np.pi)  # mm, deg
    rows = [("joint value", joints, "deg", "mm"),
            (f"rate (input rate {res.rate:g} {'rad' if x_deg else 'm'}/s)", np.asarray(res.rates), "deg/s", "mm/s"),
            ("acceleration", np.asarray(res.accelerations), "deg/s²", "mm/s²")]
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 9))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for r, (what, data, a_unit, l_unit) in enumerate(rows):
        ax = axes[r]
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
    fig.suptitle(title or f"sweep of {res.input}", fontsize=11)
    fig.tight_layout()
    return fig


def sweep_plot(res, path, mus=None, singularities=(), title=None, linear=None):
    """Joint values, rates and accelerations against the input (SweepResult), into a PNG
    (see :func:`sweep_figure` for what is drawn)."""
    plt = _pyplot("--plot")
    fig = sweep_figure(res, mus, singularities, title, linear)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def map_png(res, path: str):
    """A singularity map (SingularityMap) as a heat map with the singular curves."""
    plt = _pyplot("--png")
    fig, ax = plt.subplots(figsize=(7, 5.5))
    X, Y = np.meshgrid(res.xs, res.ys)
    mesh = ax.pcolormesh(X, Y, res.log_sigma, shading="auto", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="log10 smallest relative singular value")
    finite = res.log_sigma[np.isfinite(res.log_sigma)]
    if finite.size and finite.min() < -2:
        ax.contour(X, Y, res.log_sigma, levels=[-2.0], colors="white", linewidths=1.2)
        ax.plot([], [], color="white", label="singular (sigma < 1e-2)")
        ax.legend(loc="upper right", facecolor="0.3", labelcolor="white")
    ax.set_xlabel(f"{res.x_name} [rad or m]")
    ax.set_ylabel(f"{res.y_name} [rad or m]")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
