"""A sweep in chunks: the same motion as ``sweep``, computed a chunk of grid values at a time.

Large sweeps (a million steps written to a file) would hold every configuration, rate and
acceleration in memory; ``sweep_chunks`` yields them a chunk at a time instead, so that the
caller writes each chunk and lets it go (bounded memory).  Each chunk is one ``sweep`` over
its part of the grid, started from the previous chunk's last configuration (``q_start``, its
angles moved back by the whole turns sweep wraps a start by): the
closed form (analysis.motion.dyads) reads its branch off that configuration, so the branch
continues; the tracker (and its batched predictor) continues from it likewise.  The first row of
every chunk after the first is the previous chunk's last one and is dropped.

Limit positions: without ``turn`` the motion stops at one, as ``sweep`` does (the chunk that met
it is the last).  ``turn`` (the input running back) is not chunked: ``sweep`` does it in memory.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...errors import UsageError
from .sweep import SweepResult, sweep
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any
    from screwkin.model.mechanism import Mechanism

__all__ = ["sweep_chunks", "DEFAULT_CHUNK"]

DEFAULT_CHUNK = 20_000  # grid values a chunk: a few MB of arrays on a four-bar


def _drop_first(res: SweepResult) -> SweepResult:
    coupled = {k: v[1:] for k, v in res.coupled.items()} if res.coupled else res.coupled
    return replace(res, values=res.values[1:], q=res.q[1:], joints=res.joints[1:], rates=res.rates[1:],
                   accelerations=res.accelerations[1:], coupled=coupled)


def _keep_turns(mech: Mechanism, res: SweepResult, q_prev: np.ndarray) -> SweepResult:
    """The piece's one-coordinate angles moved by the whole turns its start was wrapped by (sweep
    starts from an angle in (-pi, pi]), so that q runs on continuously from the previous piece."""
    single, *_ = mech._value_layout()
    cols = np.array([i for _, i, w in single if w], int)
    if not len(cols) or not len(res.q):
        return res
    turns = np.round((q_prev[cols] - res.q[0, cols]) / (2 * np.pi))
    if not np.any(turns):
        return res
    Q = np.array(res.q, float)
    Q[:, cols] += 2 * np.pi * turns
    return replace(res, q=Q)


def sweep_chunks(solver, name: str, start: float, stop: float, steps: int, fixed: dict | None = None,
                 near: dict | None = None, rate: float = 1.0, chunk: int = DEFAULT_CHUNK, q_start=None, **options: Any):
    """Yield ``sweep(solver, name, start, stop, steps, ...)``'s motion as SweepResults of at most
    ``chunk`` (+1 for the first) consecutive steps each, in the order of the motion (see the module
    docstring).  ``q_start``: the configuration of the mode to follow (as sweep's).  ``options``: sweep's other
    keyword arguments (closed_form, batch, ...), not turn.
    Each piece's ``requested`` is its own part of the grid; the last piece's stopped_at and
    stop_reason are the motion's."""
    if options.get("turn"):
        raise UsageError("a sweep through limit positions (turn) is not computed in chunks")
    if chunk < 1:
        raise UsageError("a chunk needs at least 1 step")
    h = (stop - start) / steps if steps else 0.0
    j, q, prior = 0, None, None
    while True:
        j1 = min(steps, j + chunk)
        a = start + j * h
        b = stop if j1 == steps else start + j1 * h
        res = sweep(solver, name, a, b, max(j1 - j, 1), fixed=fixed, near=near if q is None else None,
                    rate=rate, q_start=q_start if q is None else q, prior=prior, **options)
        piece = res if q is None else _drop_first(_keep_turns(solver.mech, res, q))
        yield piece
        if res.stopped_at is not None or j1 >= steps or not len(res.q):
            return
        q, j = np.array(piece.q[-1] if len(piece.q) else res.q[-1]), j1
        prior = (float(res.values[-2]), np.array(res.q[-2])) if len(res.values) > 1 else None
