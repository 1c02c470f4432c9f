"""Singularity maps over two inputs: log10 of the smallest relative singular value on a grid.

The grid is walked row by row by continuation (each point starts from its
neighbour's solution), so one assembly mode is mapped; points whose loops
cannot be closed are NaN.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import AssemblyError, UsageError
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
