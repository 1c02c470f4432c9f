"""Every assembly mode of a mechanism with polynomial loop closure, and how complete the set is.

For the inputs given, the closure of the passive joints (model.algebraic: cosines and sines of
revolute angles, prismatic lengths, quaternions) is solved over the complex numbers by monodromy,
certified by the trace test (analysis.motion.monodromy), then carried to the inputs by one parameter
homotopy.  Of the roots reached:
- a root that does not make every closure row vanish is a root of the random combination of rows
  only (spurious) and is dropped;
- a real root is an assembly mode: its configuration is polished by undamped Newton on Pinocchio's
  closure (model.newton.polish, the reference), then reported as solve reports every mode;
- the others are complex: no real assembly, counted.
Roots that differ only by the closure's sign symmetries (model.symmetry: a universal joint
flipped, the other Euler set of a spherical joint) are one placement of the links, so one mode;
roots with the same joint centres and output pose (PositionSolver.signature) are one mode too.  Of
each mode's joint-angle sets the one within the joint limits and nearest the reference
configuration is reported, and how many sets reach it.

``ModeCount`` says what was found and how completeness is known: certified (the trace test), or
why not -- closure not polynomial (rolling, gears, screws, cams, --set-angle rows, mimic joints),
a continuum, idle degrees of freedom, paths that failed, a trace test that did not close.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ...model import newton
from ...model.algebraic import PolynomialClosure, SquareSystem, algebraic_obstacle
from ...model.closure import Assembly
from ...model.symmetry import find_symmetries
from .monodromy import MonodromyOptions, all_roots, to_target

__all__ = ["ModeCount", "Certified", "Search", "certified_modes", "search", "join"]


@dataclass(frozen=True)
class ModeCount:
    """How many assembly modes there are for the inputs, and how that is known.

    found:       modes found, real and complex (distinct placements of the links);
    complete:    every mode is found (certified: ``certificate`` says how);
    method:      "monodromy" (homotopy continuation) or "random starts" (damped Newton);
    real:        modes with real joint values: the mechanism's assembly modes, reported;
    complex:     modes with complex joint values (no real assembly), None when not known;
    certificate: how completeness is known ("trace test"), None when it is not;
    reason:      why completeness is not certified ("" when it is);
    detail:      what the search did: paths tracked and failed, the trace test's value, the
                 symmetry group's size, roots at infinity and spurious ones, seconds."""

    found: int
    complete: bool
    method: str
    real: int
    complex: int | None
    certificate: str | None
    reason: str = ""
    detail: dict = field(default_factory=dict)


@dataclass
class Certified:
    """Real modes found (each (q, model.closure.Assembly, angle sets, simple)) and the count."""

    modes: list
    count: ModeCount


def obstacle(solver) -> str | None:
    """Why the certified search does not apply to this solver's mechanism and inputs, or None."""
    mech = solver.mech
    why = algebraic_obstacle(mech.model, mech.cuts, mech.closure.extra, mech.couplings)
    if why:
        return f"the loop closure is not polynomial: {why}"
    if not mech.cuts:
        return "no loops"
    if solver.free_dofs:
        return f"these inputs leave {solver.free_dofs} degree(s) of freedom free (a continuum)"
    if solver.idle_dofs:
        return (f"the mechanism has {solver.idle_dofs} idle degree(s) of freedom (links that spin without "
                "moving a joint centre): their positive-dimensional solution sets are not tracked")
    return None


def certified_modes(solver, values: dict, seed: int = 0, options: MonodromyOptions = MonodromyOptions()):
    """The assembly modes for the input ``values`` by homotopy continuation (see the module): a
    Certified, or the reason (a string) why the method does not apply."""
    why = obstacle(solver)
    if why:
        return why
    t0 = time.perf_counter()
    mech = solver.mech
    ref = solver.reference()
    q_in = solver.set_inputs(mech.neutral() if ref is None else ref, values)
    closure = PolynomialClosure(mech.model, mech.cuts, solver.frozen, mech.length, points=solver._points,
                                output=solver.output_frame)
    closure.set_inputs(q_in)
    if closure.m < closure.nt:
        return (f"the loops give {closure.m} independent equations for {closure.nt} unknowns "
                "(a continuum for every input)")
    rng = np.random.default_rng(seed)
    group = find_symmetries(closure, rng)
    system = SquareSystem(closure, rng)
    roots = all_roots(system, group, closure.random_points(rng, 1), rng, options)
    ends = to_target(system, roots, np.zeros(system.n), options)
    return _classify(solver, closure, system, group, roots, ends, q_in, ref, time.perf_counter() - t0)


def _classify(solver, closure, system, group, roots, ends, q_in, ref, seconds) -> Certified:
    """The real modes (polished, one angle set each) and the counts, from the target's endpoints."""
    mech, tol = solver.mech, solver.mech.tolerances
    finite = np.isin(ends.status, ("regular", "singular"))
    X = ends.X
    scale = 1.0 + np.abs(np.where(np.isfinite(X), X, 0)).max(axis=1)
    closes = np.zeros(len(X), bool)
    if finite.any():
        closes[finite] = system.closes(X[finite]) <= 1e-8 * scale[finite] ** 2
    real = closes & (np.abs(X.imag).max(axis=1) <= 1e-7 * scale)
    sizes = group.orbit_sizes(np.where(np.isfinite(X), X, 0), 1e-9)
    modes = []  # [signature, q, assembly, angle sets, simple]
    elements = group.elements()
    for i in np.flatnonzero(real):
        q, a = _best_twin(solver, closure, elements, X[i].real, q_in, ref)
        if a.residual > tol.closure:
            continue  # not polished onto Pinocchio's closure: left out (counted in the detail)
        sig = solver.signature(q)
        for mode in modes:
            if np.max(np.abs(mode[0] - sig)) < tol.geometry * max(mech.length, 1.0):
                mode[3] += int(sizes[i])
                mode[4] = mode[4] and ends.status[i] == "regular"
                break
        else:
            modes.append([sig, q, a, int(sizes[i]), ends.status[i] == "regular" and ends.cycles[i] == 1])
    # complex modes: distinct complex signatures of the roots that close and are not real
    cplx = np.flatnonzero(closes & ~real)
    sigs = closure.signature(X[cplx]) if cplx.size else np.zeros((0, 0))
    distinct = []
    for s in sigs:
        if not any(np.max(np.abs(s - d)) < 1e-6 * (1 + np.abs(s).max()) for d in distinct):
            distinct.append(s)
    failed = int(np.sum(ends.status == "failed"))
    complete = roots.complete and failed == 0
    reason = roots.why if not roots.complete else (
        f"{failed} path{'s' if failed != 1 else ''} failed on the way to the inputs" if failed else "")
    detail = {"roots": int(len(roots.X)), "symmetry": int(group.size), "paths": int(roots.paths + ends.paths),
              "failed": int(roots.failed + failed), "witnesses": int(roots.witnesses), "trace": roots.trace,
              "at_infinity": int(np.sum(ends.status == "infinity")), "spurious": int(np.sum(finite & ~closes)),
              "unknowns": int(closure.nt), "seconds": round(float(seconds), 3)}
    count = ModeCount(len(modes) + len(distinct), complete, "monodromy", len(modes), len(distinct),
                      "trace test" if complete else None, reason, detail)
    return Certified([(q, a, sets, simple) for _, q, a, sets, simple in modes], count)


def _best_twin(solver, closure, elements, x, q_in, ref):
    """(q, Assembly) of the joint-angle set of this root to report: its twins under the symmetry group
    polished on Pinocchio's closure, the one within the joint limits (and without a reversed leg or
    a turned link: analysis.motion.modes) nearest the reference configuration."""
    from .position import outside_limits

    mech = solver.mech
    best = None
    for e in elements:
        q = closure.to_q(e * x, q_in)
        bad = (len(outside_limits(mech, q)) > 0,)
        dist = float(np.linalg.norm(mech.difference(ref, q))) if ref is not None else 0.0
        key = (bad, dist)
        if best is None or key < best[0]:
            best = (key, q)
    a = newton.polish(mech.closure, best[1], solver.frozen)
    return solver._wrap(a.q), Assembly(solver._wrap(a.q), a.residual, a.iterations, "a homotopy's endpoint")


@dataclass
class Search:
    """What solve's search found: ``found`` [(signature, q, Assembly)] of the real modes, ``info`` per
    mode (angle sets, certified simple) by position in ``found``, ``count`` (a ModeCount, or None when
    the homotopy did not apply) and ``why`` (the reason it did not)."""

    found: list
    info: list
    count: ModeCount | None
    why: str = ""

    @property
    def complete(self) -> bool:
        return self.count is not None and self.count.complete


def search(solver, values: dict, seed: int = 0) -> Search:
    """certified_modes for solve: its modes as the (signature, q, Assembly) of PositionSolver.distinct."""
    got = certified_modes(solver, values, seed=seed)
    if isinstance(got, str):
        return Search([], [], None, got)
    found = [(solver.signature(q), q, a) for q, a, _, _ in got.modes]
    return Search(found, [(sets, simple) for _, _, sets, simple in got.modes], got.count)


def join(solver, found, more) -> list:
    """``found`` with the modes of ``more`` that are not already in it (by signature)."""
    out = list(found)
    tol = solver.mech.tolerances.geometry
    for sig, q, a in more:
        sig = solver.signature(q) if sig is None else sig
        if not any(np.max(np.abs(sig - (s if s is not None else solver.signature(p)))) < tol for s, p, _ in out):
            out.append((sig, q, a))
    return out


def count_after_starts(done: Search | None, found: list, starts: int) -> ModeCount:
    """The ModeCount of a result found (also) by damped Newton from ``starts`` starting configurations:
    never complete; the reason says why the homotopy did not settle it."""
    why = ("" if done is None else done.why or (done.count.reason if done.count else "")) or \
        "the random-start search does not know how many modes there are"
    if done is not None and done.count is not None:
        base = done.count
        return ModeCount(len(found) + (base.complex or 0), False, "monodromy and random starts", len(found),
                         base.complex, None, why, {**base.detail, "starts": starts})
    return ModeCount(len(found), False, "random starts", len(found), None, None, why, {"starts": starts})
