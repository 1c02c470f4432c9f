"""The global search of constrained synthesis: scipy's differential evolution over a bounded box
of a four-bar's dimensions, one run per discrete choice (assembly branch, crank direction, root of
a Burmester curve), each seeded from the user's seed and its index so that the result is the same
for a seed whatever runs it; then the exact local refinement (least squares) of the best distinct
members of each final population.  Runs are independent: ``mapper`` (a map over Dask workers, or
the builtin map in this process) spreads them.

Why differential evolution: the error of a four-bar against points or poses has many local minima
(branches, coupler curves folding through the points in another order), its dimensions are few
(4 to 10) and bounded (the pivot box, the length range), and it needs no derivatives; the
vectorized objective evaluates a whole population in one numpy pass.  Constraints enter as
penalties (zero where met: analysis.design.synthesis.constraints) so that the search can cross
infeasible regions; the refinement keeps them as residuals, and every design reported says
whether it meets them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.design.synthesis.constraints import Constraints
    from collections.abc import Callable

__all__ = ["box_text", "Search", "SearchReport", "evolve", "distinct_best", "task_seed"]

#: Differential evolution's settings: population (times the dimensions: 15, scipy's default, missed the
#: exact path through 12 points of a coupler curve that 25 to 30 finds), generations, tolerance.
POPSIZE = 30
GENERATIONS = 200
TOLERANCE = 1e-6


@dataclass(frozen=True)
class Search:
    """How to search: ``seed`` (every run's seed derives from it), ``best`` designs to list,
    ``generations`` at most per run, ``mapper`` (map(function, tasks); None: in this process) and
    ``where`` it runs (said in the report)."""

    seed: int = 0
    best: int = 5
    generations: int = GENERATIONS
    popsize: int = POPSIZE
    mapper: object = None
    where: str = "in this process"


@dataclass(frozen=True)
class SearchReport:
    """How a global search went, for the report."""

    method: str
    runs: int
    evaluations: int
    seconds: float
    where: str
    seed: int
    candidates: tuple = ()  # the designs listed (analysis.design.synthesis.designs.Candidate), best first
    box: str = ""  # where the search looked, as chosen (box_text): what the constraints left to the search


def box_text(constraints: Constraints, pivots: tuple | None=None, lengths: tuple | None = None) -> str:
    """Where a search looks, in words: the fixed pivots' box ((low, high) corners [m]) and the links'
    lengths ((low, high) [m]), each said to be the search's own choice where ``constraints`` (a
    Constraints) does not give it (--bounds, --lengths)."""
    parts = []
    if pivots is not None:
        (x0, y0), (x1, y1) = pivots
        parts.append(f"fixed pivots in x {x0:.4g} .. {x1:.4g} m, y {y0:.4g} .. {y1:.4g} m"
                     + ("" if constraints.bounds is not None else " (chosen around the task: --bounds sets it)"))
    if lengths is not None:
        parts.append(f"links {lengths[0]:.4g} .. {lengths[1]:.4g} m"
                     + ("" if constraints.lengths is not None else " (chosen from the task's size: --lengths sets it)"))
    return "; ".join(parts)


def task_seed(seed: int, index: int) -> int:
    """The seed of run ``index`` of a search seeded ``seed`` (independent streams, the same for a seed)."""
    return int(np.random.SeedSequence([int(seed), int(index)]).generate_state(1)[0])


def evolve(cost: Callable[[np.ndarray], np.ndarray], lower: np.ndarray, upper: np.ndarray, seed: int, generations: int = GENERATIONS, popsize: int = POPSIZE) -> tuple:
    """Differential evolution (scipy, best1bin, Latin-hypercube start, deferred updating) of the
    vectorized ``cost`` (X (n, d) -> (n,)) over the box [lower, upper]: (population (m, d), costs (m,),
    evaluations)."""
    from scipy.optimize import differential_evolution

    def f(x: np.ndarray):  # scipy gives the population as (d, n)
        return cost(np.asarray(x, float).T)

    res = differential_evolution(f, list(zip(lower, upper)), strategy="best1bin", maxiter=generations,
                                 popsize=popsize, tol=TOLERANCE, mutation=(0.5, 1.0), recombination=0.7,
                                 seed=seed, polish=False, init="latinhypercube", updating="deferred",
                                 vectorized=True)
    return np.asarray(res.population), np.asarray(res.population_energies), int(res.nfev)


def distinct_best(population: np.ndarray, costs: np.ndarray, lower: np.ndarray, upper: np.ndarray, count: int, apart: float = 0.05) -> list:
    """Indices of up to ``count`` of the best members, each at least ``apart`` (of the box's size, in
    every dimension's scale) from those taken before."""
    span = np.maximum(np.asarray(upper, float) - np.asarray(lower, float), 1e-300)
    order = np.argsort(costs)
    taken = []
    for k in order:
        if not np.isfinite(costs[k]):
            break
        if all(np.max(np.abs(population[k] - population[j]) / span) > apart for j in taken):
            taken.append(int(k))
        if len(taken) >= count:
            break
    return taken


def run_all(search: Search, function: Callable[..., object], tasks: list) -> tuple:
    """(the tasks' results in order, seconds): ``function`` mapped over ``tasks`` by the search's mapper."""
    t0 = time.perf_counter()
    mapper = search.mapper or map
    out = list(mapper(function, tasks))
    return out, time.perf_counter() - t0
