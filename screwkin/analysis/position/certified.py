"""Every assembly mode of a mechanism with polynomial loop closure, and how complete the set is.

For the inputs given, the closure of the passive joints (model.kernel.algebraic: cosines and sines of
revolute angles, prismatic lengths, quaternions) is solved over the complex numbers by monodromy,
certified by the trace test (model.homotopy.monodromy), then carried to the inputs by one parameter
homotopy.  Of the roots reached:
- a root that does not make every closure row vanish is a root of the random combination of rows
  only (spurious) and is dropped;
- a real root is an assembly mode: its configuration is polished by undamped Newton on Pinocchio's
  closure (model.kernel.newton.polish, the reference), then reported as solve reports every mode;
- the others are complex: no real assembly, counted.
Roots that differ only by the closure's sign symmetries (model.homotopy.symmetry: a universal joint
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
from dataclasses import dataclass, field, replace

import numpy as np

from ...errors import AssemblyError
from ...model.kernel import newton
from ...model.kernel.algebraic import PolynomialClosure, algebraic_obstacle
from ...model.homotopy.known_counts import STEWART, known_count
from ...model.homotopy.monodromy import all_roots, to_target
from ...model.homotopy.parameter import architecture
from ...model.homotopy.square import SquareSystem
from ...model.homotopy.symmetry import find_symmetries
from ...model.cuts import Assembly
from ...model.linalg import rank
from ...tolerances import Tolerances
from .dyad_modes import dyad_modes
from .three_distances import three_distance_modes
from . import generic_modes
from .modes import continuum_words
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.homotopy.known_counts import KnownCount
    from screwkin.model.homotopy.monodromy import Endpoints
    from screwkin.model.homotopy.monodromy import Roots

NO_LOOPS = "no loops"
#: Singular values below this, relative to the Jacobian's largest entry, count as zero (its generic rank).
_RANK = 1e-9

__all__ = ["ModeCount", "Certified", "Search", "Problem", "certified_modes", "search", "join", "count_after_starts",
           "closed_form", "planar_closed_form"]


@dataclass(frozen=True)
class ModeCount:
    """How many assembly modes there are for the inputs, and how that is known.

    found:       modes found, real and complex (distinct placements of the links);
    complete:    every mode is found (certified: ``certificate`` says how);
    method:      "closed form (dyads)" (a planar mechanism made of dyads: analysis.position.dyad_modes),
                 "closed form (a univariate polynomial of degree n in tan(phi/2))" (a planar platform on
                 three distances: analysis.position.three_distances), "monodromy" (homotopy
                 continuation) or "random starts" (damped Newton);
    real:        modes with real joint values: the mechanism's assembly modes, reported;
    complex:     modes with complex joint values (no real assembly), None when not known;
    certificate: how completeness is known ("closed form, 2 dyads, 4 branch vectors", "trace test", a
                 published count), None when it is not;
    reason:      why completeness is not certified ("" when it is);
    detail:      what the search did: paths tracked and failed, the trace test's value, the
                 symmetry group's size, roots at infinity and spurious ones, seconds;
    check:       the certificate's own counts, checked before it is given (``checked``: every check
                 held): what is counted, paths and failed paths, the bound, distinct solutions."""

    found: int
    complete: bool
    method: str
    real: int
    complex: int | None
    certificate: str | None
    reason: str = ""
    detail: dict = field(default_factory=dict)
    check: dict = field(default_factory=dict)


@dataclass
class Certified:
    """Real modes found (each (q, model.kernel.closure.Assembly, angle sets, simple)) and the count."""

    modes: list
    count: ModeCount


def obstacle(solver) -> str | None:
    """Why the certified search does not apply to this solver's mechanism and inputs, or None."""
    mech = solver.mech
    why = algebraic_obstacle(mech.model, mech.cuts, mech.closure.extra, mech.couplings)
    if why:
        return f"the loop closure is not polynomial: {why}"
    if solver.free_dofs:
        return continuum_words(solver.free_dofs)
    if not mech.cuts:
        return NO_LOOPS
    return None


@dataclass
class Problem:
    """What the homotopy solves: the model and cut joints (an inverse-kinematics target among them),
    the Pinocchio closure that polishes and lifts (model.kernel.closure.ClosureSystem), the velocity indices
    held (inputs), the configuration that holds their values and the reference one."""

    model: object
    cuts: list
    system: object
    frozen: np.ndarray
    q_in: np.ndarray
    ref: np.ndarray | None
    target: bool = False


def certified_modes(solver, values: dict, seed: int = 0, tolerances: Tolerances | None = None,
                    problem: Problem | None = None):
    """The assembly modes for the input ``values`` by homotopy continuation (see the module): a
    Certified, or the reason (a string) why the method does not apply.  ``problem``: another system
    to solve (inverse kinematics); by default the solver's loops with its inputs held.  ``tolerances``:
    the homotopy's settings (the ``homotopy_`` and ``track_`` fields), the mechanism's by default."""
    mech = solver.mech
    options = mech.tolerances if tolerances is None else tolerances
    if problem is None:
        why = obstacle(solver)
        if why:
            return why
        ref = solver.reference()
        problem = Problem(mech.model, mech.cuts, mech.closure, solver.frozen,
                          solver.set_inputs(mech.neutral() if ref is None else ref, values), ref)
    t0 = time.perf_counter()
    closure = PolynomialClosure(problem.model, problem.cuts, problem.frozen, mech.length, points=solver._points,
                                output=solver.output_frame)
    closure.set_inputs(problem.q_in)
    rng = np.random.default_rng(seed)
    free = closure.nt - _rank(closure, rng)
    if free > 0:
        return (f"the closure leaves {free} unknown(s) free at every configuration"
                + (f" ({solver.idle_dofs} idle degree(s) of freedom: links that spin without moving a joint "
                   "centre, not on a leg that is a distance)" if solver.idle_dofs else "")
                + ": positive-dimensional solution sets are not tracked")
    known = known_count(closure, problem.frozen, problem.target)
    if known is STEWART:  # a parameter homotopy from the architecture's generic solution set
        arch = architecture(problem, closure, mech)
        if arch is not None:
            modes, *counts = generic_modes.platform_modes(solver, problem, closure, arch, seed, options,
                                                          lambda x: _lift(solver, problem, closure, x))
            found, real, cplx, certificate, reason, detail, check = counts
            return _reference_check(solver, problem, Certified(modes, ModeCount(
                found, certificate is not None, "parameter homotopy", real, cplx, certificate, reason, detail, check)))
    group = find_symmetries(closure, rng)
    system = SquareSystem(closure, rng)
    roots = all_roots(system, group, closure.random_points(rng, 1), rng, options, trace_test=known is None,
                      trace_limit=options.homotopy_trace_limit)
    ends = to_target(system, roots, np.zeros(system.n), options)
    got = _classify(solver, problem, closure, system, group, roots, ends, known, time.perf_counter() - t0, options)
    if known is not None and not got.count.complete and len(roots.X) <= options.homotopy_trace_limit:
        # fewer than the class's bound (a special geometry): the trace test decides, within a budget
        roots = all_roots(system, group, roots.X[:1], rng, replace(options, homotopy_budget=options.homotopy_fallback_budget),
                          seeds=roots.X, trace_test=True)
        ends = to_target(system, roots, np.zeros(system.n), options)
        got = _classify(solver, problem, closure, system, group, roots, ends, None, time.perf_counter() - t0,
                        options, also=got.count.reason)
    return _reference_check(solver, problem, got)


def _reference_check(solver, problem: Problem, got: Certified) -> Certified:
    """A certificate held against one root found another way before it is given: damped Newton from the
    reference configuration (the file's drawing, the inputs set) on Pinocchio's closure.  A real root there
    that the certified set does not hold, or one where the closure's Jacobian in the unknowns loses rank (a
    positive-dimensional solution set, which no path of the square system reaches, or a multiple root),
    takes the certificate back, with the reason (an ik target at a point every configuration reaches: the
    homotopy's 'trace test' closed on 2 complex roots beside a whole circle of real ones)."""
    if not got.count.complete or got.count.method == "closed form (dyads)":
        return got
    mech, tol = solver.mech, solver.mech.tolerances
    try:
        a = problem.system.solve(problem.q_in, frozen=problem.frozen)
    except AssemblyError:
        return got  # Newton did not converge from there: nothing to hold the set against
    q = solver._wrap(a.q)
    unknown = np.setdiff1d(np.arange(mech.nv), np.asarray(problem.frozen, int))
    free = unknown.size - solver.idle_dofs - rank(problem.system.jacobian(q)[:, unknown], tol)
    sig = solver.signature(q)
    held = any(solver.same_mode(sig, solver.signature(m[0])) for m in got.modes)
    if held and free <= 0:
        return got
    why = ("the root Newton reaches from the file's configuration is not among them" if not held else
           "the root Newton reaches from the file's configuration is not simple")
    if free > 0:
        why += (f" (the closure's Jacobian there leaves {free} unknown(s) free: a positive-dimensional solution "
                "set or a multiple root, which the homotopy's paths do not count)")
    c = got.count
    count = replace(c, complete=False, certificate=None, reason=f"{c.certificate} does not hold: {why}",
                    check={**c.check, "checked": False, "reference_root": {"held": held, "free": int(max(free, 0))}})
    return Certified(got.modes, count)


def _rank(closure: PolynomialClosure, rng: np.random.Generator) -> int:
    """The generic rank of the closure rows' Jacobian (at random complex points of the variety)."""
    if closure.nt == 0 or closure.m == 0:
        return 0
    _, J = closure.rows(closure.random_points(rng, 2))
    return int(max(np.linalg.matrix_rank(j, tol=_RANK * np.abs(j).max(initial=0.0)) for j in J))


def _classify(solver, problem: Problem, closure: PolynomialClosure, system: SquareSystem, group, roots: Roots, ends: Endpoints, known: KnownCount, seconds, o: Tolerances,
              also: str = "") -> Certified:
    """The real modes (polished, one angle set each) and the counts, from the target's endpoints."""
    mech, tol = solver.mech, solver.mech.tolerances
    finite = np.isin(ends.status, ("regular", "singular"))
    X = ends.X
    scale = 1.0 + np.abs(np.where(np.isfinite(X), X, 0)).max(axis=1)
    closes = np.zeros(len(X), bool)
    if finite.any():
        closes[finite] = system.closes(X[finite]) <= o.homotopy_closes * scale[finite] ** 2
    real = closes & (np.abs(X.imag).max(axis=1) <= o.homotopy_real * scale)
    modes = []  # [signature, q, assembly, angle sets, simple]
    full = closure if not closure.legs else PolynomialClosure(
        problem.model, problem.cuts, problem.frozen, mech.length, points=solver._points,
        output=solver.output_frame, compiled=False, eliminate=False)
    full_group = group if full is closure else find_symmetries(full, np.random.default_rng(1))
    elements = full_group.elements()
    lost = 0
    multiple = _coinciding(X, real, group, o.homotopy_same)  # paths that met: a multiple root
    for i in np.flatnonzero(real):
        q = _lift(solver, problem, closure, X[i].real)
        if q is None:
            lost += 1
            continue
        xf = full.from_q(q)
        q, a = _best_twin(solver, problem, full, elements, xf)
        if a.residual > tol.closure:
            lost += 1
            continue  # not polished onto Pinocchio's closure: left out (counted in the detail)
        size = int(full_group.orbit_sizes(xf[None], 1e-9)[0])
        sig = solver.signature(q)
        for mode in modes:
            if solver.same_mode(mode[0], sig):
                mode[3] += size
                mode[4] = mode[4] and not multiple[i] and ends.status[i] == "regular"
                break
        else:
            modes.append([sig, q, a, size, ends.status[i] == "regular" and ends.cycles[i] == 1 and not multiple[i]])
    # complex modes: distinct complex signatures of the roots that close and are not real
    cplx = np.flatnonzero(closes & ~real)
    sigs = closure.signature(X[cplx]) if cplx.size else np.zeros((0, 0))
    distinct = []
    for s in sigs:
        if not any(np.max(np.abs(s - d)) < o.homotopy_same * (1 + np.abs(s).max()) for d in distinct):
            distinct.append(s)
    failed = int(np.sum(ends.status == "failed"))
    sets = int(np.sum(group.orbit_sizes(np.where(np.isfinite(X[closes]), X[closes], 0), 1e-9))) if closes.any() else 0
    found = len(modes) + len(distinct)
    certificate, reason = None, roots.why
    if known is not None:
        reached = found if known.of == "poses" else sets
        if reached == known.bound and failed == 0 and lost == 0:
            certificate, reason = f"{known.bound} {known.of}, the most for {known.what} ({known.source})", ""
        elif reached > known.bound:  # a count past the bound: solutions counted twice, or not solutions
            reason = (f"{reached} {known.of} found, more than the {known.bound} at most for {known.what} "
                      f"({known.source}): some are counted twice, so the count is no certificate")
        else:
            reason = (f"{reached} {known.of} found of at most {known.bound} for {known.what} ({known.source})"
                      + (f"; {failed} path(s) failed" if failed else "")
                      + (f"; {lost} real root(s) did not polish onto Pinocchio's closure" if lost else ""))
    elif roots.complete and failed == 0 and lost == 0:
        certificate, reason = "trace test", ""
    elif roots.complete:
        reason = "; ".join(([f"{failed} path{'s' if failed != 1 else ''} failed on the way to the inputs"] if failed
                            else []) + ([f"{lost} real root(s) did not polish onto Pinocchio's closure"] if lost else []))
    if reason and also:
        reason = f"{also}, and {reason}"
    detail = {"roots": int(len(roots.X)), "symmetry": int(full_group.size), "legs_eliminated": len(closure.legs),
              "lost_polishing": lost, "paths": int(roots.paths + ends.paths),
              "failed": int(roots.failed + failed), "witnesses": int(roots.witnesses), "trace": roots.trace,
              "at_infinity": int(np.sum(ends.status == "infinity")), "spurious": int(np.sum(finite & ~closes)),
              "angle_sets": sets, "unknowns": int(closure.nt), "seconds": round(float(seconds), 3)}
    check = {"method": "monodromy" + (", published count" if known is not None else ", trace test"),
             "paths": int(roots.paths + ends.paths), "failed_paths": int(roots.failed + failed),
             "bound": known.bound if known is not None else None, "counts": known.of if known is not None else
             "distinct placements of the links", "distinct": found, "real_not_polished": lost,
             "checked": certificate is not None}
    count = ModeCount(found, certificate is not None, "monodromy", len(modes), len(distinct), certificate, reason,
                      detail, check)
    # a regular endpoint leaves the verdict to the measures (and, where they are small, to Newton's
    # convergence: modes.simple_root); two paths that met, or a singular endpoint, are a multiple root
    return Certified([(q, a, n, None if simple else False) for _, q, a, n, simple in modes], count)


def _coinciding(X: np.ndarray, mask, group, tol) -> np.ndarray:
    """(P,) where an endpoint of ``mask`` lies on another's orbit (two paths ended together)."""
    out = np.zeros(len(X), bool)
    idx = np.flatnonzero(mask)
    for k, i in enumerate(idx[1:], 1):
        j = group.match(X[i][None], X[idx[:k]], tol)[0]
        if j >= 0:
            out[i] = out[idx[j]] = True
    return out


def _lift(solver, problem: Problem, closure: PolynomialClosure, x):
    """The real configuration of a real root x of the closure: its joints, and the eliminated legs'
    angles (model.legs) solved by damped Newton with every other joint held -- from the inputs'
    configuration, then from random angles -- or None."""
    mech = solver.mech
    q = closure.to_q(x, problem.q_in)
    if not closure.legs:
        return q
    legs = mech.velocity_indices([problem.model.names[j] for j in sorted(closure.eliminated)])
    held = np.union1d(np.setdiff1d(np.arange(mech.nv), legs), np.asarray(problem.frozen, int))  # inputs stay
    rng = np.random.default_rng(3)
    for k in range(8):
        start = q if k == 0 else mech._keep(mech.random_configuration(rng), q, held)
        try:
            return problem.system.solve(start, frozen=held).q
        except AssemblyError:
            continue
    return None


def _best_twin(solver, problem: Problem, closure, elements, x) -> tuple:
    """(q, Assembly) of the joint-angle set of this root to report: of its twins under the symmetry group
    (which place the links alike), the one within the joint limits nearest the reference configuration,
    polished on Pinocchio's closure."""
    mech, ref = solver.mech, problem.ref
    best = None
    for e in elements:
        q = closure.to_q(e * x, problem.q_in)
        bad = (len(solver.outside(q)) > 0,)
        dist = float(np.linalg.norm(mech.difference(ref, q))) if ref is not None else 0.0
        key = (bad, dist)
        if best is None or key < best[0]:
            best = (key, q)
    a = newton.polish(problem.system.pinocchio, best[1], problem.frozen)
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


def closed_form(solver, values: dict):
    """The modes of a planar mechanism made of dyads (analysis.position.dyad_modes) as a Certified, or
    why the closed form does not apply (a string)."""
    got = dyad_modes(solver, values)
    if isinstance(got, str):
        return got
    k, s = got.dyads, "s" if got.dyads != 1 else ""
    double = sum(n > 1 for _, _, n, _ in got.modes)
    certificate = (f"closed form, {k} dyad{s} ({', '.join(got.kinds)}), {got.choices} branch vectors"
                   + (f", {got.complex} with a negative discriminant" if got.complex else "")
                   + (f", {2 * double} meeting at a limit position" if double else ""))
    detail = {"dyads": k, "kinds": list(got.kinds), "branch_vectors": got.choices, "real_branch_vectors":
              got.real_choices, "swept_from": got.swept, "seconds": round(float(got.seconds), 3)}
    count = ModeCount(len(got.modes) + got.complex, True, "closed form (dyads)", len(got.modes), got.complex,
                      certificate, "", detail)
    return Certified(got.modes, count)


def planar_closed_form(solver, values: dict):
    """The modes of a planar platform on three distances (analysis.position.three_distances) as a
    Certified; None where the mechanism is no such platform, a sentence where the closed form does not
    settle it (the polynomial vanishes identically, a root or a pose not accounted for)."""
    got = three_distance_modes(solver, values)
    if got is None or isinstance(got, str):
        return got
    r = got.roots
    n, real, cplx = r.degree, len(r.real), len(r.complex)
    n_real, n_cplx = sum(p.roots for p in r.real), sum(p.roots for p in r.complex)
    parts = [f"{n_real} real" + (f" ({real} pose{'s' if real != 1 else ''}, some multiple)" if n_real != real else ""),
             f"{n_cplx} complex" + (f" ({cplx // 2} conjugate pair{'s' if cplx != 2 else ''})" if cplx else "")]
    if r.spurious:
        parts.append(f"{r.spurious} where det M = 0 and the linear equations have no solution (a pose at infinity)")
    certificate = (f"closed form, a polynomial of degree {n} in tan(phi/2) of three distances in the plane, every "
                   f"root accounted for: {', '.join(parts)}" + (f"; {r.at_pi} at phi = pi" if r.at_pi else "")
                   + (f"; the factor (1 + t^2)^{r.circular} (t = +-i, no angle) taken out" if r.circular else ""))
    multiple = sum(p.roots > 1 for p in r.poses)
    detail = {"degree": n, "roots_real": sum(p.roots for p in r.real), "roots_complex": sum(p.roots for p in r.complex),
              "roots_spurious": r.spurious, "roots_at_pi": r.at_pi, "circular_factors": r.circular,
              "multiple_poses": multiple, "t_real": [round(t, 12) + 0.0 for t in got.t_real],
              "polynomial": [float(v) for v in r.coefficients], "seconds": round(float(got.seconds), 4)}
    check = {"method": "closed form (polynomial in tan(phi/2))", "degree": n, "accounted": r.accounted,
             "real_poses": real, "complex_poses": cplx, "spurious_roots": r.spurious, "checked": True}
    count = ModeCount(len(got.modes) + cplx, True, f"closed form (a univariate polynomial of degree {n} in tan(phi/2))",
                      len(got.modes), cplx, certificate, "", detail, check)
    return Certified(got.modes, count)


def closed_forms(solver, values: dict) -> tuple:
    """(every mode in closed form as a Certified, or None; why each closed form did not apply, by name): the
    one order of them, dyads (``closed_form``) then the planar platform on three distances
    (``planar_closed_form``); nothing is searched."""
    why: dict = {}
    if obstacle(solver):
        return None, why
    got = closed_form(solver, values)
    if isinstance(got, str):
        got, why["closed_form"] = None, got
        got = planar_closed_form(solver, values)
        if isinstance(got, str):
            got, why["three_distances"] = None, got
    return got, why


def search(solver, values: dict, seed: int = 0, problem: Problem | None = None) -> Search:
    """Every mode for solve (and ik, with its ``problem``): in closed form where the mechanism is made
    of dyads (``closed_form``) or is a planar platform on three distances (``planar_closed_form``), else
    by certified_modes; its modes as the (signature, q, Assembly) of PositionSolver.distinct."""
    got, why = closed_forms(solver, values) if problem is None else (None, {})
    if got is None:
        got = certified_modes(solver, values, seed=seed, problem=problem)
        if why and not isinstance(got, str):
            got.count = replace(got.count, detail={**got.count.detail, **why})
    if isinstance(got, str):
        return Search([], [], None, got)
    found = [(solver.signature(q), q, a) for q, a, _, _ in got.modes]
    return Search(found, [(sets, simple) for _, _, sets, simple in got.modes], got.count)


def join(solver, found, more) -> list:
    """``found`` with the modes of ``more`` that are not already in it (by signature)."""
    out = list(found)
    for sig, q, a in more:
        sig = solver.signature(q) if sig is None else sig
        if not any(solver.same_mode(sig, s if s is not None else solver.signature(p)) for s, p, _ in out):
            out.append((sig, q, a))
    return out


def count_after_starts(done: Search | None, found: list, starts: int) -> ModeCount:
    """The ModeCount of a result found (also) by damped Newton from ``starts`` starting configurations:
    never complete; the reason says why the homotopy did not settle it."""
    if done is not None and done.why == NO_LOOPS and len(found) == 1:  # the inputs set every joint
        return ModeCount(1, True, "no loops", 1, 0, "no loops: the inputs set every joint", "", {"starts": starts})
    why = ("" if done is None else done.why or (done.count.reason if done.count else "")) or \
        "the random-start search does not know how many modes there are"
    if done is not None and done.count is not None:
        base = done.count
        return ModeCount(len(found) + (base.complex or 0), False, "monodromy and random starts", len(found),
                         base.complex, None, why, {**base.detail, "starts": starts})
    return ModeCount(len(found), False, "random starts", len(found), None, None, why, {"starts": starts})
