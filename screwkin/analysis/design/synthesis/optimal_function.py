"""Constrained, optimal function generation: the four-bars whose rocker angle follows f(x) through
the precision points (3 to 200: least squares beyond 3) while the crank turns through the input range,
that meet the constraints (analysis.design.synthesis.constraints), best first.

The unknowns are the crank a, coupler b and rocker c (the ground d = ``--ground``; with ``--lengths``
the ground too, within the range: function generation does not change with the linkage's size); with
``--bounds`` the ground line (along x: the angles are measured from the x axis) is centred in the box,
which must hold both pivots.  Freudenstein's crank and rocker may point away from their angles
(negative a or c in function.py): one run per branch and per sign of each.  The cost is the root mean square of the structural error at the
precision points (rad: psi generated on the run's branch, circle intersection, minus psi asked), the
constraints' penalties, and 1 % of the transmission angle's worst deviation from 90 deg over the input
range (the whole turn when the crank turns fully).  One run per branch; the refinement is least
squares on the structural errors with the penalty as one more residual.  The design is then
function.py's (Freudenstein's coefficients from the lengths: K1 = d / c, K2 = d / a,
K3 = (a^2 - b^2 + c^2 + d^2) / 2ac).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ....model.geometry import circle_circle, wrap_angle
from .constraints import grashof_type, motion_mu
from .designs import Candidate, FunctionResult, SynthesisError
from .function import function_result, function_task
from .optimal import MARGIN, PENALTY, PREFER, REFINED, refined, rank_key
from .search import SearchReport, box_text, distinct_best, evolve, run_all, task_seed
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.design.synthesis.constraints import Constraints
    from screwkin.analysis.design.synthesis.search import Search

__all__ = ["optimal_function"]


def _unknowns(task: dict, constraints: Constraints) -> tuple:
    """(names of the unknowns, lower, upper): a, b, c (and d with --lengths, B0's x, y with --bounds)."""
    d = task["ground"]
    lo, hi = constraints.lengths if constraints.lengths is not None else (0.05 * d, 10 * d)
    names, lower, upper = ["a", "b", "c"], [lo] * 3, [hi] * 3
    if constraints.lengths is not None:
        names.append("d")
        lower.append(lo)
        upper.append(hi)
    return names, np.array(lower, float), np.array(upper, float)


def _parts(X: np.ndarray, names: list[str], task: dict, bounds: tuple | None=None) -> tuple:
    """a, b, c, d (m,) and B0 (m, 2): at the origin, or, with ``bounds``, the ground line centred in the box."""
    get = {n: X[:, k] for k, n in enumerate(names)}
    d = get.get("d", np.full(len(X), task["ground"]))
    if bounds is None:
        B0 = np.zeros((len(X), 2))
    else:
        (x0, y0), (x1, y1) = bounds
        B0 = np.stack([x0 + (x1 - x0 - d) / 2, np.full(len(X), (y0 + y1) / 2)], -1)
    return get["a"], get["b"], get["c"], d, B0


def _errors(X: np.ndarray, names: list[str], task: dict, signs: tuple, constraints: Constraints, equal: float, phi: np.ndarray, psi: np.ndarray) -> tuple:
    """(structural errors (m, n) [rad], penalties (m,), mu (lo, hi)) of designs X at the angles phi, psi;
    ``signs`` (branch, crank's, rocker's): Freudenstein's signed crank and rocker (a link pointing the
    other way from its angle, as function.py's negative a or c)."""
    sigma, sa, sc = signs
    a, b, c, d, B0 = _parts(X, names, task, constraints.bounds)
    A = np.stack([d[:, None] + sa * a[:, None] * np.cos(phi)[None], sa * a[:, None] * np.sin(phi)[None]], -1)
    B, h2 = circle_circle(A, b[:, None], np.zeros(2), c[:, None], sigma)  # B0 at the origin
    err = wrap_angle(np.arctan2(B[..., 1], B[..., 0]) + (math.pi if sc < 0 else 0.0) - psi[None], upper=True)
    apart = np.maximum(-h2, 0).sum(axis=1) / d ** 2
    g = d
    phi0 = task["p0"] - (math.pi if sa > 0 else 0.0)  # the crank from the ground line A0 -> B0 (along -x)
    mu_lo, mu_hi = motion_mu(g, a, b, c, phi0, task["p1"] - task["p0"], equal)
    A0 = B0 + np.stack([d, np.zeros_like(d)], -1)
    pen = constraints.penalty(A0, B0, g, a, b, c, mu_lo, mu_hi, task["ground"]) + apart
    return err, pen, (mu_lo, mu_hi)


def _function_run(job: tuple) -> tuple:
    """One run (picklable: what a Dask worker computes): differential evolution on the precision points,
    then least squares from its best distinct members.  Returns ([(x, signs)], generations)."""
    task, names, constraints, signs, seed, generations, popsize, equal = job
    _, lower, upper = _unknowns(task, constraints)
    phi, psi = task["phi"], task["psi"]

    def cost(X: np.ndarray) -> np.ndarray:
        err, pen, (lo, hi) = _errors(X, names, task, signs, constraints, equal, phi, psi)
        dev = np.where(np.isnan(lo), math.pi / 2, np.maximum(math.pi / 2 - lo, hi - math.pi / 2))
        c = np.sqrt((err ** 2).mean(axis=1)) + PENALTY * pen + PREFER * dev / (math.pi / 2)
        return np.where(np.isfinite(c), c, 1e3)

    pop, costs, nfev = evolve(cost, lower, upper, seed, generations, popsize)
    tight = constraints.tightened(MARGIN * task["ground"], MARGIN)
    out = []
    def residuals(X: np.ndarray, weight: float) -> np.ndarray:
        err, pen, _ = _errors(X, names, task, signs, tight, equal, phi, psi)
        return np.concatenate([err, weight * pen[:, None]], axis=1)

    for k in distinct_best(pop, costs, lower, upper, REFINED):
        out.append((refined(residuals, pop[k], lower, upper, task["ground"]), signs))
    return out, nfev


def optimal_function(text: str, x_range: tuple[float, float], input_range: tuple[float, float], output_range: tuple[float, float], points: int, spacing: str, ground: float, constraints: Constraints, search: Search,
                     equal: float = 1e-9) -> FunctionResult:
    """The best function generators that meet ``constraints`` (module docstring): the FunctionResult of
    the best, its ``search`` report listing the best few."""
    task = function_task(text, x_range, input_range, output_range, points, spacing, ground)
    constraints.check()
    names, lower, upper = _unknowns(task, constraints)
    runs = [(s, sa, sc) for s in (1.0, -1.0) for sa in (1.0, -1.0) for sc in (1.0, -1.0)]
    jobs = [(task, names, constraints, r, task_seed(search.seed, k), search.generations, search.popsize, equal)
            for k, r in enumerate(runs)]
    results, seconds = run_all(search, _function_run, jobs)
    cands = []
    for found, _ in results:
        for x, signs in found:
            sigma, sa, sc = signs
            a, b, c, d, B0 = (float(v[0]) if np.ndim(v) == 1 else v[0]
                              for v in _parts(x[None], names, task, constraints.bounds))
            K = (d / (sc * c), d / (sa * a), (a * a - b * b + c * c + d * d) / (2 * sa * a * sc * c))
            try:
                res = function_result(task, K, d, sigma, tuple(map(float, B0)))
            except SynthesisError:
                continue
            err, _, (lo, hi) = _errors(x[None], names, task, signs, constraints, equal, task["phi"], task["psi"])
            mu = (float(lo[0]), float(hi[0])) if np.isfinite(lo[0]) else None
            fb = res.design.fourbar
            unmet = tuple(constraints.unmet(fb.A0, fb.B0, d, a, b, c, mu, equal, 1e-9 * max(d, 1.0)))
            cand = Candidate(res.design, float(np.abs(err).max()), float(np.sqrt(np.mean(err ** 2))), mu,
                             grashof_type(d, a, b, c, equal)[0], tuple(res.defects), unmet,
                             f"branch {'+' if sigma > 0 else '-'}, crank {'+' if sa > 0 else '-'}, rocker "
                             f"{'+' if sc > 0 else '-'}")
            cands.append((cand, res))
    if not cands:
        raise SynthesisError("synthesize function", "the search found no four-bar that assembles at the precision "
                                                     "points")
    cands.sort(key=lambda c: rank_key(c[0], 1e-9))
    evaluations = sum(r[1] for r in results)
    report = SearchReport(f"the crank, coupler and rocker{' and the ground' if 'd' in names else ''}"
                          f"{' (the ground line centred in the bounds)' if constraints.bounds else ''} searched: differential "
                          f"evolution (scipy, best1bin), then least squares from the best {REFINED} distinct members "
                          "of each run", len(runs), evaluations, seconds, search.where, search.seed,
                          tuple(c[0] for c in cands[:search.best]), box_text(constraints, lengths=(lower[0], upper[0])))
    return replace(cands[0][1], search=report)
