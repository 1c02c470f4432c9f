"""Pictures of results with matplotlib (optional: ``pip install -e '.[plot]'``)."""

from __future__ import annotations

import numpy as np

from ..errors import UsageError

__all__ = ["sweep_plot", "map_png"]


def _pyplot(option):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise UsageError(f"{option} needs matplotlib: pip install matplotlib") from None
    return plt


def sweep_plot(res, path, mus=None):
    """Joint values, rates and accelerations against the input (SweepResult), into a PNG;
    mus: the transmission angle at each step [rad], drawn on a second axis."""
    plt = _pyplot("--plot")
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 8))
    for k, name in enumerate(res.names):
        axes[0].plot(res.values, res.joints[:, k], label=name)
        axes[1].plot(res.values, res.rates[:, k], label=name)
        axes[2].plot(res.values, res.accelerations[:, k], label=name)
    axes[0].set_ylabel("joint value [rad, m]")
    axes[1].set_ylabel(f"rate [1/s] (input rate {res.rate:g})")
    axes[2].set_ylabel("acceleration")
    axes[2].set_xlabel(f"{res.input} [rad or m]")
    axes[0].legend(fontsize=7)
    if mus is not None:
        ax = axes[0].twinx()
        ax.plot(res.values, np.degrees(mus), "k--", label="transmission angle")
        ax.set_ylabel("transmission angle [deg]")
    fig.tight_layout()
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
