"""Singularity maps over two inputs: log10 of the smallest relative singular value on a grid.

The grid is walked row by row by continuation (each point starts from its
neighbour's solution), so one assembly mode is mapped; points whose loops
cannot be closed are NaN.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import AssemblyError, UsageError
from .singular import Generic, measures

__all__ = ["SingularityMap", "singularity_map"]


@dataclass(frozen=True)
class SingularityMap:
    x_name: str
    y_name: str
    xs: np.ndarray
    ys: np.ndarray
    log_sigma: np.ndarray  # (len(ys), len(xs)): log10 of the smallest relative singular value
    kind: np.ndarray  # (len(ys), len(xs)) object array: which singularity the minimum belongs to
    q: np.ndarray  # (len(ys), len(xs), nq) configurations (NaN where not assembled)

    def csv(self) -> str:
        lines = [f"{self.x_name},{self.y_name},log10_sigma_min,kind"]
        for j, y in enumerate(self.ys):
            for i, x in enumerate(self.xs):
                lines.append(f"{x:.12g},{y:.12g},{self.log_sigma[j, i]:.6g},{self.kind[j, i]}")
        return "\n".join(lines) + "\n"

    def png(self, path: str):
        try:
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            raise UsageError("--png needs matplotlib: pip install matplotlib") from None
        fig, ax = plt.subplots(figsize=(7, 5.5))
        X, Y = np.meshgrid(self.xs, self.ys)
        mesh = ax.pcolormesh(X, Y, self.log_sigma, shading="auto", cmap="viridis")
        fig.colorbar(mesh, ax=ax, label="log10 smallest relative singular value")
        finite = self.log_sigma[np.isfinite(self.log_sigma)]
        if finite.size and finite.min() < -2:
            ax.contour(X, Y, self.log_sigma, levels=[-2.0], colors="white", linewidths=1.2)
            ax.plot([], [], color="white", label="singular (sigma < 1e-2)")
            ax.legend(loc="upper right", facecolor="0.3", labelcolor="white")
        ax.set_xlabel(f"{self.x_name} [rad or m]")
        ax.set_ylabel(f"{self.y_name} [rad or m]")
        fig.tight_layout()
        fig.savefig(path, dpi=100)
        plt.close(fig)


def singularity_map(solver, x_name, xs, y_name, ys, fixed=None, output=None, point: bool = False) -> SingularityMap:
    mech = solver.mech
    fixed = dict(fixed or {})
    for n in (x_name, y_name):
        if n not in solver.inputs:
            raise UsageError(f"{mech.path}: '{n}' is not an input ({', '.join(solver.inputs)})")
    q_row = solver.solve({x_name: xs[0], y_name: ys[0], **fixed}).solutions[0].q
    g = Generic(mech, solver.inputs, output, point, configurations=solver.generic().configurations)
    logs = np.full((len(ys), len(xs)), np.nan)
    kinds = np.full((len(ys), len(xs)), "", dtype=object)
    qs = np.full((len(ys), len(xs), mech.nq), np.nan)
    for j, y in enumerate(ys):
        q = q_row
        for i, x in enumerate(xs):
            try:
                q = mech.closure.solve(solver.set_inputs(q, {x_name: x, y_name: y, **fixed}), frozen=solver.frozen).q
            except AssemblyError:
                continue
            if i == 0:
                q_row = q
            qs[j, i] = q
            m = measures(mech, q, g)
            kind = min(m, key=m.get)
            logs[j, i] = np.log10(max(m[kind], 1e-16))
            kinds[j, i] = kind
    return SingularityMap(x_name, y_name, np.asarray(xs), np.asarray(ys), logs, kinds, qs)
