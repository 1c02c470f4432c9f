"""The coefficient-parameter homotopy of a Stewart-Gough platform from a generic solution set kept per
architecture (Morgan and Sommese 1989; Sommese and Wampler 2005, ch. 7).

The platform's closure, whichever way the file writes it (on a floating joint, or carried by one leg
in the tree), is the same system: six distances between ground points A_k and platform points B_k,
in the platform's pose (model.distances.SixDistances).  Its family over the squared leg lengths c is
solved once, at random complex c0, by monodromy (model.homotopy.monodromy): complete when it holds
40 poses (the most for any geometry: Raghavan 1993, Wampler 1996), else when the trace test closes.
That set is kept in the cache folder (files.generic_cache) under the hash of (A, B).  Each query --
the legs' lengths of the inputs -- is one straight segment from c0 to c (``to_query``): by the theory
of coefficient-parameter homotopy every isolated pose of the query is the end of one of these paths
(some paths end at infinity, or at a singular pose).  Here the endpoints are sorted (closing, real,
distinct up to q -> -q, shared by several paths, complex without their conjugate); carrying the real
ones back to the file's joints and the certificate are analysis.position.generic_modes'.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from ...files import generic_cache
from ...tolerances import Tolerances
from ..distances import SixDistances
from ..legs import chain_distance
from ..state import KinematicState
from .monodromy import Endpoints, Roots, all_roots, to_target
from .symmetry import SignGroup

if TYPE_CHECKING:
    from ..kernel.algebraic import PolynomialClosure
    from ..mechanism import Mechanism

__all__ = ["BOUND", "SOURCE", "Architecture", "architecture", "platform_group", "generic_set", "QueryEnds",
           "to_query"]

BOUND = 40
SOURCE = "Raghavan 1993; Wampler 1996: at most 40"
#: |G(x) - c0| of a cached root, relative: above it the file is not used.
_CACHED_ROOT = 1e-8
#: A complex pose and its conjugate's endpoint agree to this (relative): both are tracked separately.
_CONJUGATE = 1e-6


class PlatformProblem(Protocol):
    """What ``architecture`` reads of the problem the certified search solves
    (analysis.position.certified.Problem)."""

    model: Any  # a pinocchio.Model
    frozen: np.ndarray
    q_in: np.ndarray
    target: bool


class Architecture:
    """A platform as six distances: ``A``, ``B`` (6, 3) [m] (A in the world, B in the frame of the
    platform's joint ``joint``), ``r2`` the squared lengths at the inputs [m^2], ``L`` the scale (the
    largest coordinate of A and B);
    ``carrier`` the leg in the tree as (head joints, tail joints) or None (a floating joint)."""

    def __init__(self, A: object, B: object, r2: object, joint: int,
                 carrier: tuple[list[int], list[int]] | None) -> None:
        self.A, self.B, self.r2 = np.asarray(A, float), np.asarray(B, float), np.asarray(r2, float)
        # the scale from the geometry alone: the same platform written either way shares its generic set
        L = self.L = float(max(np.abs(self.A).max(), np.abs(self.B).max(), 1e-9))
        self.joint, self.carrier = joint, carrier
        self.system = SixDistances(self.A / L, self.B / L)
        self.key = generic_cache.key("six distances", [self.A / L, self.B / L])


def architecture(problem: PlatformProblem, closure: PolynomialClosure, mech: Mechanism) -> Architecture | None:
    """The platform of a closure (its legs eliminated) that known_counts recognized as a Stewart-Gough
    platform (of ``mech``), or None."""
    L = mech.length
    model = problem.model
    if problem.target or any(leg.parent != 0 for leg in closure.legs):
        return None
    joints = {model.frames[leg.other].parentJoint for leg in closure.legs}
    if len(joints) != 1:
        return None
    joint = joints.pop()
    A = [np.asarray(leg.centre, float) for leg in closure.legs]
    B = [np.asarray(model.frames[leg.other].placement.translation, float) for leg in closure.legs]
    r2 = list(np.asarray(closure.r2, float) * L ** 2)
    carrier = None
    if len(closure.legs) == 6:
        if closure.kind[joint] != "F" or model.parents[joint] != 0 or set(closure.slices) != {joint}:
            return None
    elif len(closure.legs) == 5:
        got = chain_distance(model, problem.frozen, joint, L)
        if got is None:
            return None
        a, b = got
        chain = []
        j = joint
        while j > 0:
            chain.append(j)
            j = model.parents[j]
        chain.reverse()
        head, tail = chain[:2], chain[-3:]
        if any(closure.kind[j] != "R" or j not in closure.slices for j in head + tail):
            return None
        if set(closure.slices) != set(head + tail):  # nothing else unknown: the pose sets every joint
            return None
        placement = KinematicState(mech, problem.q_in).joint_placement(joint)
        A.insert(0, np.asarray(a, float))
        B.insert(0, np.asarray(b, float))
        r2.insert(0, float(np.sum((placement.act(np.asarray(b)) - a) ** 2)))
        carrier = (head, tail)
    else:
        return None
    return Architecture(A, B, r2, joint, carrier)


def platform_group() -> SignGroup:
    """The platform's one sign symmetry: q -> -q is the same pose."""
    return SignGroup(7, [[1, 1, 1, -1, -1, -1, -1]])


def generic_set(arch: Architecture, rng: np.random.Generator,
                tol: Tolerances) -> tuple[Roots, str | None, Path | None, bool]:
    """(Roots at generic c0, how its completeness is known or None, where it is kept or None, reused)."""
    system, group = arch.system, platform_group()
    got = generic_cache.read(arch.key, 7, 6)
    if got is not None:
        c0, X, how, kept = got
        ok = (system.residual(X, c0) <= _CACHED_ROOT * (1 + np.abs(c0).max())) & system.on_variety(X, 1e-8)
        distinct = all(group.match(X[i][None], X[:i], tol.homotopy_same)[0] < 0 for i in range(len(X)))
        whole = len(X) == BOUND if how.startswith("the published bound") else len(X) <= BOUND
        if ok.all() and distinct and whole:
            roots = Roots(X, c0, True, None, "", 0, 0, 0, 0, 0.0, group)
            return roots, how, kept, True
    x0 = system.random_points(rng, 1)
    roots = all_roots(system, group, x0, rng, tol, trace_test=False, stop_at=BOUND)
    how = None
    if len(roots.X) == BOUND:
        how = f"the published bound ({SOURCE})"
    elif len(roots.X) < BOUND:
        roots = all_roots(system, group, roots.X[:1], rng, replace(tol, homotopy_budget=tol.homotopy_fallback_budget),
                          seeds=roots.X, trace_test=True, trace_limit=None)
        if roots.complete and len(roots.X) <= BOUND:
            how = f"the trace test (relative singular value {roots.trace:.1g})"
    path = generic_cache.write(arch.key, roots.c0, roots.X, how) if how else None
    return roots, how, path, False


@dataclass(frozen=True)
class QueryEnds:
    """The generic set's paths carried to a query's leg lengths, sorted.

    ends: the endpoints (model.homotopy.monodromy.Endpoints; X (P, 7) in (t / L, q));
    closes (P,): a finite endpoint where the six rows hold; real (P,): one of those with a real pose;
    distinct: the index of one endpoint per pose (q and -q one pose), in path order;
    meets (P,): an endpoint another path reached too (a multiple pose);
    lone: complex poses whose conjugate is not among the distinct ones (the lengths are real: a lone
    one is a real pose misjudged, or a path gone astray)."""

    ends: Endpoints
    closes: np.ndarray
    real: np.ndarray
    distinct: list[int]
    meets: np.ndarray
    lone: int


def to_query(arch: Architecture, roots: Roots, tol: Tolerances) -> QueryEnds:
    """The generic set ``roots`` carried to the leg lengths of ``arch`` (its ``r2``) and sorted."""
    target = arch.r2 / arch.L ** 2
    ends = to_target(arch.system, roots, target, tol)
    group, system = platform_group(), arch.system
    X, status = ends.X, ends.status
    finite = np.isin(status, ("regular", "singular"))
    safe = np.where(np.isfinite(X), X, 0)
    scale = 1.0 + np.abs(safe).max(axis=1)
    closes = finite & (system.residual(safe, target) <= tol.homotopy_closes * scale ** 2)
    real = closes & (np.abs(safe.imag).max(axis=1) <= tol.homotopy_real * scale)
    distinct: list[int] = []
    meets = np.zeros(len(X), bool)
    for i in np.flatnonzero(closes):
        j = group.match(X[i][None], X[distinct], tol.homotopy_same)[0] if distinct else -1
        if j >= 0:
            meets[i] = meets[distinct[j]] = True
        else:
            distinct.append(int(i))
    cplx = [i for i in distinct if not real[i]]
    lone = sum(group.match(np.conj(X[i])[None], X[[k for k in cplx if k != i]], _CONJUGATE)[0] < 0 for i in cplx) \
        if len(cplx) > 1 else len(cplx)
    return QueryEnds(ends, closes, real, distinct, meets, int(lone))
