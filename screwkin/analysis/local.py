"""What a mechanism can do near one configuration: the local analysis of its configuration space.

At an assembled configuration q the loops' Jacobian K loses rank, or not.  The *infinitesimal*
mobility is dim ker K; the *finite* (local) mobility is the dimension of the configuration space
at q, which the kernel only bounds.  Both are decided from the loops' Taylor series in closed form
(analysis.loop_series: Lie brackets of the joint screws, Mueller's higher-order analysis):

- order 1: K has full row rank (no redundant row at q, once the rows a plane or a sphere makes
  vanish identically are dropped): q is a regular point, finite = infinitesimal mobility;
- order 2: for a tangent x in ker K the series continues only if the second-order term R_1(x) lies
  in the range of K: the c quadratic forms y -> u_i^T R_1(N y) on ker K (u_i spanning coker K, N ker
  K) vanish.  Their real zeros on the unit sphere are the candidate branch tangents (exactly for one
  form, by its eigenvalues; in two variables, as binary forms; else refined from
  ``Tolerances.local_starts`` starting directions).  No zero: the point is isolated -- rigid,
  *shaky* when ker K is not zero -- a theorem (the tangent cone lies in the zero set).  Zeros where
  the forms' Jacobian has full rank c and no form vanishes identically: the tangent cone is their
  zero set (a blow-up and the implicit function theorem), each linear component a branch of
  mobility d - c: decided at order 2;
- beyond: where a form vanishes identically on ker K (the rows of an overconstrained linkage such as
  Bennett's, redundant along every motion) or a zero is degenerate, each candidate's series is
  continued to ``Tolerances.local_order``, the kernel part of each coefficient chosen (least squares)
  to satisfy the next order, and a candidate that leaves a residual in coker K is dropped at that
  order.  What survives is said to hold to that order, never more.

Each surviving branch is then confirmed apart from the series: from q a step of
``Tolerances.local_step`` along its tangent is closed again by Gauss-Newton with the step's
component along the branch's tangent space held; the configuration reached exists, lies near the
predictor, and the rank of K there gives the branch's own mobility.

Kinds: "regular" (one smooth branch, finite = infinitesimal), "bifurcation" (branches of one
mobility cross: a change point), "kinematotropic" (branches of different mobilities meet),
"shaky" (the configuration space smooth here -- an isolated point: infinitesimally mobile, finitely
rigid; or a branch along which the instantaneous mobility stays above the finite one, Mueller's shaky
linkage), "singular" (one branch with more instantaneous than finite mobility here only, or a cone
point), "rigid" (no motion at all: ker K = 0), "undecided" (the series alone cannot tell).
Ranks are decided as analysis.singular decides a constraint singularity: singular
values of the dimensionless K below ``Tolerances.singular`` times the largest are lost.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import AssemblyError
from ..model.kernel.contract import ClosureKernel
from ..model.kernel.newton import undamped
from ..model.kernel.scaling import dimensionless, dimensionless_rows
from ..model.linalg import rank
from .loop_series import Series, loop_system
from .singular import scaled_jacobians
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.loop_series import LoopSystem
    from screwkin.tolerances import Tolerances
    from collections.abc import Callable

__all__ = ["Branch", "LocalAnalysis", "local_analysis", "KINDS", "quadratic_forms", "rates_of"]

KINDS = ("regular", "bifurcation", "kinematotropic", "shaky", "singular", "rigid", "undecided")

#: Where every quadratic form vanishes, the series is continued along at most this many basis directions of
#: ker K (and two mixes of all of them): a bound on the work for mechanisms with many idle freedoms.
MAX_DIRECTIONS = 6

#: The size below which a term of the series is compared with 1 rather than with itself: the screws are
#: dimensionless (translations in characteristic lengths), their products of order 1 where the mechanism is.
UNIT = 1.0

#: A branch's tangent space is listed (a basis, joint rates) up to this dimension; beyond, only its tangent.
SHOWN_SPACE = 12

#: A tangent's joint rates are shown with the first joint whose rate is at least this fraction of the
#: largest set to 1 (a display normalization, not a decision).
SHOWN_REFERENCE = 0.1


@dataclass(frozen=True)
class Branch:
    """One branch of the configuration space through the configuration.

    tangent: joint -> rate of a tangent of the branch (the first joint moving noticeably at rate 1);
    mobility: the branch's finite mobility, the dimension of its tangent space (the cone's component);
    nearby: dim ker K at the configuration reached on it a step away: the mobility again at a kinematic
    singularity, more on a shaky linkage (its instantaneous mobility stays above the finite one);
    tangent_space: a basis of its tangent space when 1 < mobility <= SHOWN_SPACE (dicts as tangent);
    linear: its tangent cone is a linear space (False: a quadric cone, the point singular on it);
    order: the order to which its series was continued;
    confirmed: the step along it closed again (Gauss-Newton), with step, deviation from the
    predictor and residual (dimensionless: rad, characteristic lengths)."""

    tangent: dict
    mobility: int
    nearby: int | None = None  # the infinitesimal mobility at the configuration reached on it (None: not reached)
    tangent_space: tuple = ()
    linear: bool = True
    order: int = 1
    confirmed: bool | None = None  # None: not needed (decided at order 1)
    step: float = 0.0
    deviation: float | None = None
    residual: float | None = None


@dataclass(frozen=True)
class LocalAnalysis:
    """The local analysis at one configuration (see the module docstring)."""

    rank: int  # rank of K here (coordinates nv)
    generic_rank: int | None  # the largest over the mechanism's generic configurations: the check
    rank_drop: int  # generic_rank - rank (0 without a generic rank)
    coordinates: int
    infinitesimal_mobility: int  # dim ker K
    inputs_held: int | None  # dim ker K with the inputs held (None without inputs)
    finite_mobility: int | None  # None when undecided
    kind: str
    order: int | None  # the order at which the cone was decided (None: undecided)
    checked_order: int  # the order to which the series was continued
    certain: bool  # decided by a theorem at that order (not only continued to checked_order)
    decided_by: str  # how, in words
    branches: tuple  # Branch
    algebra: str  # "se(3)", "se(2)" or "so(3)": where the loops were written
    redundant_rows: int  # rows of K minus its rank here, in that algebra (coker K)
    identically_zero: int  # of those, rows whose quadratic form vanishes identically on ker K
    sigma: float  # the smallest kept singular value of the dimensionless K, relative to the largest
    inputs: tuple
    notes: tuple = ()


def rates_of(mech: Mechanism, x: np.ndarray, scale: np.ndarray) -> dict:
    """The tree part of a dimensionless direction x as joint rates (sliding ones times L), shown with the
    first joint moving at least SHOWN_REFERENCE of the largest at rate 1."""
    v = np.asarray(x[:mech.nv], float) * scale[:mech.nv]
    big = np.max(np.abs(v)) if v.size else 0.0
    if big > 0:
        ref = next(k for k in range(len(v)) if abs(v[k]) >= SHOWN_REFERENCE * big)
        v = v / v[ref]
    names = mech.coordinate_names
    return {n: float(r) for n, r in zip(names, v)}


def quadratic_forms(system: LoopSystem, N: np.ndarray, U: np.ndarray) -> np.ndarray:
    """(c, d, d): the quadratic forms y -> U^T R_1(N y) of the second-order term, by polarization."""
    d, c = N.shape[1], U.shape[1]
    F = np.zeros((c, d, d))

    def q(y):
        return U.T @ Series(system, N @ y).residual()

    diag = [q(e) for e in np.eye(d)]
    for j in range(d):
        F[:, j, j] = diag[j]
        for k in range(j + 1, d):
            F[:, j, k] = F[:, k, j] = (q(np.eye(d)[j] + np.eye(d)[k]) - diag[j] - diag[k]) / 2
    return F


@dataclass
class _Candidate:
    T: np.ndarray  # (d, b) orthonormal basis of its tangent space, in kernel coordinates
    samples: list  # unit directions (kernel coordinates) to continue
    linear: bool
    regular: bool  # the forms' Jacobian has full rank at its zeros (decided at order 2)


def _orth(M: np.ndarray, tol: float) -> np.ndarray:
    if M.size == 0:
        return M.reshape(M.shape[0], 0)
    U, s, _ = np.linalg.svd(M, full_matrices=False)
    return U[:, s > tol * max(s[0], 1.0)] if s.size else M[:, :0]


def _one_form(Q: np.ndarray, zero: float) -> list:
    """The zero set of one quadratic form y^T Q y on R^d, as candidates."""
    lam, V = np.linalg.eigh(Q)
    pos, neg = V[:, lam > zero], V[:, lam < -zero]
    lp, ln = lam[lam > zero], lam[lam < -zero]
    null = V[:, np.abs(lam) <= zero]
    if not pos.shape[1] or not neg.shape[1]:  # semidefinite: the zeros are Q's kernel, degenerate
        return [] if not null.shape[1] else [_Candidate(null, list(null.T), True, False)]
    if pos.shape[1] == 1 and neg.shape[1] == 1:  # a pair of hyperplanes, meeting in Q's kernel
        out = []
        for sign in (1.0, -1.0):
            normal = np.sqrt(lp[0]) * pos[:, 0] - sign * np.sqrt(-ln[0]) * neg[:, 0]
            P = np.eye(len(Q)) - np.outer(normal, normal) / (normal @ normal)
            T = _orth(P, zero)
            y = np.sqrt(-ln[0]) * pos[:, 0] + sign * np.sqrt(lp[0]) * neg[:, 0]
            y = y / np.linalg.norm(y)
            # directions of the hyperplane off the kernel (where the zeros are regular): y, y + each kernel vector
            samples = [y] + [(y + w) / np.linalg.norm(y + w) for w in null.T]
            out.append(_Candidate(T, samples, True, True))
        return out
    # an irreducible quadric cone: curved, one candidate sampled along it
    samples = []
    for i in range(pos.shape[1]):
        for j in range(neg.shape[1]):
            y = np.sqrt(-ln[j]) * pos[:, i] + np.sqrt(lp[i]) * neg[:, j]
            samples.append(y / np.linalg.norm(y))
    y = samples[0]
    T = _orth(np.eye(len(Q)) - np.outer(Q @ y, Q @ y) / ((Q @ y) @ (Q @ y)), zero)
    return [_Candidate(T, samples, False, True)]


def _sampled_zeros(F: np.ndarray, zero: float, starts: int, tol: Tolerances, seed: int=0) -> list:
    """Common zeros of the forms F (c, d, d) on the unit sphere, refined by Gauss-Newton from
    ``starts`` directions, as candidates grouped by their tangent spaces."""
    c, d, _ = F.shape
    rng = np.random.default_rng(seed)
    found = []
    for y in list(np.eye(d)) + list(rng.normal(size=(starts, d))):
        y = y / np.linalg.norm(y)
        for _ in range(40):
            g = np.einsum("ijk,j,k->i", F, y, y)
            J = 2 * np.einsum("ijk,k->ij", F, y)
            P = np.eye(d) - np.outer(y, y)
            dy = -np.linalg.lstsq(J @ P, g, rcond=None)[0]
            y = y + P @ dy
            y /= np.linalg.norm(y)
            if np.linalg.norm(dy) <= tol.zero:
                break
        g = np.einsum("ijk,j,k->i", F, y, y)
        if np.linalg.norm(g) <= zero:
            found.append(y)
    groups = []
    for y in found:
        J = 2 * np.einsum("ijk,k->ij", F, y)
        _, s, vt = np.linalg.svd(J)
        r = int(np.sum(s > zero))
        T = vt[r:].T
        for g in groups:
            if abs(np.linalg.norm(g.T.T @ y) - 1) <= tol.geometry and g.T.shape[1] == T.shape[1]:  # same subspace
                g.samples.append(y)
                break
        else:
            groups.append(_Candidate(T, [y], True, r == c))
    for g in groups:  # linear when the forms vanish on its whole tangent space
        g.linear = all(np.linalg.norm(g.T.T @ Fi @ g.T) <= zero for Fi in F)
        g.samples = g.samples + list(g.T.T)
    return groups


def _cone(F: np.ndarray, zero: float, starts: int, tol) -> list:
    """Candidates: the real zeros of the forms F (c2, d, d) (none identically zero)."""
    c, d, _ = F.shape
    if d == 1:
        return []
    if c == 1 or d == 2:
        out = []
        for cand in _one_form(F[0], zero):
            if all(np.linalg.norm(np.einsum("ijk,j,k->i", F, y, y)) <= zero * max(1.0, 10 * c) for y in cand.samples[:1]):
                if c > 1:  # a binary form's zero lines, kept when the others vanish there too
                    y = cand.samples[0]
                    J = 2 * np.einsum("ijk,k->ij", F, y)
                    cand.regular = int(np.sum(np.linalg.svd(J, compute_uv=False) > zero)) == c
                out.append(cand)
        return out
    return _sampled_zeros(F, zero, starts, tol)


def _continue(system: LoopSystem, x: np.ndarray, Ainv: np.ndarray, N: np.ndarray, U: np.ndarray, order: int, tol: Tolerances, lookahead: bool=True) -> tuple:
    """Continue the series from X[0] = x to ``order``: each X[k] = -A^+ R_k + N y, y chosen (least
    squares) so that the next order's residual in coker K is least (0 without ``lookahead``).  Returns (the first order whose
    residual stays -- None when every order to ``order`` holds --, X coefficients, residuals)."""
    s = Series(system, x)
    residuals = []
    for k in range(1, order):
        R = s.residual()
        left = U.T @ R
        residuals.append(float(np.linalg.norm(left)))
        if np.linalg.norm(left) > tol.local_form * max(float(np.linalg.norm(R)), UNIT):
            return k + 1, s.X, residuals
        base = -Ainv @ R
        if lookahead and k + 1 < order and N.shape[1] and U.shape[1]:
            t0 = s.copy()
            t0.push(base)
            r0 = U.T @ t0.residual()
            M = U.T @ t0.residual_change(N)  # (the next residual is affine in X[k]: exact, one pass for all of N)
            base = base + N @ np.linalg.lstsq(M, -r0, rcond=None)[0]
        s.push(base)
    return None, s.X, residuals


class _HeldRows(ClosureKernel):
    """The minimal closure rows made dimensionless (model.kernel.scaling), and below them the held
    rows B^T (q - q0) / scale - target: a step's component along a branch's tangent space B (nv, k)
    kept.  Steps are in the scaled columns (sliding ones times L): q moves by step * scale."""

    def __init__(self, mech: Mechanism, q0: np.ndarray, B: np.ndarray, target: np.ndarray, scale: np.ndarray, L: float) -> None:
        self.mech, self.q0, self.B, self.target, self.scale, self.L = mech, q0, B, target, scale, L
        self.nq, self.nv = mech.model.nq, mech.nv
        self.m = mech.closure.nrows + B.shape[1]
        self.length_rows = np.r_[mech.closure.position_rows, np.zeros(B.shape[1], bool)]
        self.sliding = np.flatnonzero(mech.translational)

    def evaluate(self, Q: np.ndarray, jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        mech, q = self.mech, Q[0]
        r, K = mech.closure.evaluate(q, jacobian=True)
        rows = mech.closure.position_rows
        r, K = dimensionless_rows(r, rows, self.L), dimensionless(K, rows, mech.translational, self.L)
        hold = self.B.T @ (pin.difference(mech.model, self.q0, q) / self.scale) - self.target
        J = np.vstack([K, self.B.T]) if K.size else self.B.T
        return np.concatenate([r, hold])[None], J[None]

    def integrate(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        return np.array([pin.integrate(self.mech.model, q, v * self.scale) for q, v in zip(Q, V)])


def _confirm(mech: Mechanism, q0: np.ndarray, system: LoopSystem, X: np.ndarray, B: np.ndarray, h: float) -> tuple:
    """Close the loops again at a step h along the branch of tangent X[0] (dimensionless, column space)
    with tangent space B (tree part, orthonormal): Gauss-Newton from q0 + h x with B^T (q - q0) = h B^T x
    held.  Returns (configuration or None, its distance from q0 + h x -- O(h^2) on a branch --, residual)."""
    tol = mech.tolerances
    nv, L = mech.nv, system.length
    scale = system.scale[:nv]
    x = X[0][:nv]
    predicted = pin.integrate(mech.model, q0, h * x * scale)  # the tangent alone: the series is not used
    rows = _HeldRows(mech, q0, B, h * (B.T @ x), scale, L)  # Gauss-Newton: the undamped step of model.kernel.newton
    closed = undamped(rows, predicted, np.arange(nv), tol.max_iterations - 1, closure=tol.closure)
    q, norm = closed.q, closed.residual
    if not norm < tol.closure:
        return None, None, norm
    deviation = float(np.linalg.norm(pin.difference(mech.model, predicted, q) / scale))
    return q, deviation, norm


def local_analysis(mech: Mechanism, q: np.ndarray, inputs: list[str] | None=None, generic_rank: int | None=None, progress: Callable[[int, int], object] | None=None) -> LocalAnalysis:
    """The local analysis of ``mech`` at the assembled configuration q (see the module docstring);
    inputs: the joints held for ``inputs_held`` (default the actuated ones); generic_rank: the rank of
    K at generic configurations (default: the largest over mech.generic_configurations()); progress: a
    callable progress(done, total) told of each tangent direction whose series is continued (the long part
    of a long loop at a singular point; at most Tolerances.local_samples a tangent space)."""
    tol = mech.tolerances
    inputs = tuple(mech.actuated if inputs is None else inputs)
    nv = mech.nv
    if generic_rank is None:
        try:
            configs = mech.generic_configurations()[1]
            generic_rank = max(rank(mech.closure.jacobian(c), tol) for c in configs) if mech.closure.nrows else 0
        except AssemblyError:
            generic_rank = None
    S = scaled_jacobians(mech, q)
    sv = np.linalg.svd(S.K, compute_uv=False) if S.K.size else np.zeros(0)
    cut = max(tol.singular * (sv[0] if sv.size else 0.0), tol.rank_atol)
    rk = int(np.sum(sv > cut))
    sigma = float(sv[rk - 1] / sv[0]) if rk else 1.0
    d = nv - rk
    held = None
    if inputs:
        p = np.setdiff1d(np.arange(nv), mech.velocity_indices(inputs))
        Kp = S.K[:, p] if S.K.size else np.zeros((0, len(p)))
        sp = np.linalg.svd(Kp, compute_uv=False) if Kp.size else np.zeros(0)
        held = len(p) - int(np.sum(sp > max(tol.singular * (sv[0] if sv.size else 0.0), tol.rank_atol)))
    drop = max(generic_rank - rk, 0) if generic_rank is not None else 0
    base = dict(rank=rk, generic_rank=generic_rank, rank_drop=drop, coordinates=nv, infinitesimal_mobility=d,
                inputs_held=held, sigma=sigma, inputs=inputs)
    system = loop_system(mech, q)
    A = system.jacobian
    cols = A.shape[1]
    U_A, s_A, Vt_A = np.linalg.svd(A) if A.size else (np.eye(A.shape[0]), np.zeros(0), np.eye(cols))
    rA = min(cols - d, A.shape[0])
    notes = []
    own = int(np.sum(s_A > max(tol.singular * (s_A[0] if s_A.size else 0.0), tol.rank_atol)))
    if own != rA:  # the loops' Jacobian decides its own kernel (K and A straddle the threshold differently)
        notes.append(f"the loops written with their cut joints' freedoms have rank {own}, not {rA} as K's rank "
                     f"says: the analysis follows their kernel, of dimension {cols - own}")
        rA = own
        d = cols - own
    base.update(algebra=system.algebra, redundant_rows=A.shape[0] - rA, identically_zero=0)
    if d == 0:
        return LocalAnalysis(**base, finite_mobility=0, kind="rigid", order=1, checked_order=1, certain=True,
                             decided_by="order 1: K has full column rank, no motion at all", branches=(),
                             notes=tuple(notes))
    N = Vt_A[rA:].T
    U = U_A[:, rA:]
    Ainv = Vt_A[:rA].T @ np.diag(1.0 / s_A[:rA]) @ U_A[:, :rA].T if rA else np.zeros((cols, A.shape[0]))
    c = U.shape[1]
    if system.algebra != "se(3)":
        what = "a plane" if system.algebra == "se(2)" else "a sphere"
        notes.append(f"every loop lies in {what} ({system.algebra}): its other rows vanish identically and are "
                     "left out")
    if c == 0:
        space = tuple(rates_of(mech, N[:, k], system.scale) for k in range(d)) if 1 < d <= SHOWN_SPACE else ()
        branch = Branch(rates_of(mech, N[:, 0], system.scale), d, None, space, True, 1)
        among = {"se(2)": " among the rows in the plane", "so(3)": " among the rows on the sphere"}.get(system.algebra, "")
        how = (f"order 1: the loops' Jacobian has full row rank here (no redundant row{among}): a regular point"
               if A.shape[0] else "order 1: no loops: every coordinate is free")
        return LocalAnalysis(**base, finite_mobility=d, kind="regular", order=1, checked_order=1, certain=True,
                             decided_by=how, branches=(branch,), notes=tuple(notes))
    if not system.supported:
        notes.append(f"the series beyond order 1 is not available: {system.note}")
        return LocalAnalysis(**base, finite_mobility=None, kind="undecided", order=None, checked_order=1,
                             certain=False, decided_by="not decided: " + system.note, branches=(), notes=tuple(notes))
    F = quadratic_forms(system, N, U)
    # a form is zero next to the second-order terms themselves (they grow with the mechanism's distance from
    # the world origin, the projections on coker K of the ones that vanish identically only by round-off)
    second = max([float(np.linalg.norm(Series(system, N[:, k]).residual())) for k in range(d)] + [UNIT])
    zero = tol.local_form * second
    Uf, sf, _ = np.linalg.svd(F.reshape(c, d * d), full_matrices=True)
    c2 = int(np.sum(sf > zero))
    F2 = np.einsum("ia,ijk->ajk", Uf[:, :c2], F)
    c0 = c - c2
    base["identically_zero"] = c0
    order_max = max(int(tol.local_order), 2)
    if c2 == 0:  # every direction of ker K: its basis (the first MAX_DIRECTIONS) and two mixes
        candidates = [_Candidate(np.eye(d), list(np.eye(d))[:MAX_DIRECTIONS] + _mixes(d), True, False)]
    else:
        candidates = _cone(F2, zero, int(tol.local_starts), tol)
    # two or more forms on a kernel of dimension 3 or more: their common zeros are searched from starting
    # directions (_sampled_zeros), which finds them but cannot prove there are no others
    sampled = d + int(tol.local_starts) if c2 > 1 and d > 2 else 0
    if c2 and not candidates:
        if sampled:
            how = (f"order 2: {_forms(c2)} of the loops on ker K (dimension {d}): no common real zero but 0 found "
                   f"from {sampled} starting directions (sampled, not proved): no motion found leaving this "
                   "configuration")
        else:
            how = (f"order 2: {_forms(c2)} of the loops on ker K (dimension {d}) "
                   f"{'have no common real zero' if c2 > 1 else 'has no real zero'} but 0: no motion leaves this "
                   "configuration")
        return LocalAnalysis(**base, finite_mobility=0, kind="shaky", order=2, checked_order=2,
                             certain=not sampled, decided_by=how, branches=(), notes=tuple(notes))
    candidates, thinned = _at_most_samples(candidates, max(int(tol.local_samples), 1))
    if thinned:
        notes.append(thinned)
    branches, failed = [], []
    total, done = sum(len(c.samples) for c in candidates), 0
    for cand in candidates:
        reached, X0 = order_max, None
        for y in cand.samples:
            fail, X, _ = _continue(system, N @ y, Ainv, N, U, order_max, tol, lookahead=c2 > 0)
            done += 1
            if progress is not None:
                progress(done, total)
            if X0 is None:
                X0 = X
            if fail is not None:
                reached = min(reached, fail - 1)
                if y is cand.samples[0] or reached <= 1:  # (no later sample can stop it earlier than order 2)
                    break
        if reached < order_max and cand.samples:
            failed.append((cand, reached + 1))
            continue
        branch = _branch(mech, q, system, N, cand, X0, order_max)
        branches.append(branch)
    return _decide(base, branches, failed, c2, c0, candidates, order_max, notes, d, sampled)


def _at_most_samples(candidates: list, cap: int) -> tuple:
    """The candidates with at most ``cap`` samples each (an irreducible quadric cone on a kernel of dimension d
    has up to d^2 / 4 sampled generators, each continued at a cost growing with d: a 40-joint loop folded flat
    has 361), spread evenly over the list and always its first; and the note that says so (None when
    nothing was left out)."""
    out, left = [], []
    for c in candidates:
        if len(c.samples) <= cap:
            out.append(c)
            continue
        keep = sorted(set(np.linspace(0, len(c.samples) - 1, cap).round().astype(int).tolist()))
        out.append(_Candidate(c.T, [c.samples[k] for k in keep], c.linear, c.regular))
        left.append((len(keep), len(c.samples)))
    if not left:
        return out, None
    kept, of = sum(k for k, _ in left), sum(n for _, n in left)
    return out, (f"the series was continued along {kept} of the {of} directions sampled on the tangent cone (sampled, "
                 f"at most {cap} a tangent space: Tolerances.local_samples, mobility --local-samples N raises it)")


def _mixes(d: int, count: int=2, seed: int=0) -> list:
    """A few fixed random unit directions in R^d (more directions checked than the basis)."""
    if d < 2:
        return []
    rng = np.random.default_rng(seed)
    return [v / np.linalg.norm(v) for v in rng.normal(size=(count, d))]


def _branch(mech: Mechanism, q: np.ndarray, system: LoopSystem, N: np.ndarray, cand: _Candidate, X: np.ndarray, order: int) -> Branch:
    tol = mech.tolerances
    nv = mech.nv
    T = N @ cand.T
    B = _orth(T[:nv], tol.geometry)
    qh, deviation, residual = _confirm(mech, q, system, X, B, tol.local_step)
    confirmed = qh is not None
    nearby = nv - rank(mech.closure.jacobian(qh), tol) if confirmed else None
    space = (tuple(rates_of(mech, T[:, k], system.scale) for k in range(T.shape[1]))
             if 1 < T.shape[1] <= SHOWN_SPACE else ())
    return Branch(rates_of(mech, X[0], system.scale), int(cand.T.shape[1]), nearby, space, cand.linear, order,
                  confirmed, float(tol.local_step), deviation, residual)


def _decide(base: dict, branches: list, failed: list, c2: int, c0: int, candidates: list, order_max: int, notes: list, d: int, sampled: int) -> LocalAnalysis:
    """The kind, finite mobility, order and words from the surviving branches (``sampled``: the number of
    starting directions the quadratic cone's zeros were searched from, 0 where they are found exactly)."""
    notes = list(notes)
    common = {k: v for k, v in base.items()}
    regular_roots = all(c.regular for c in candidates) and c2 > 0
    for _cand, at in failed:
        notes.append(f"a candidate tangent of the quadratic cone does not continue: its series leaves a residual at "
                     f"order {at}")
    unconfirmed = [b for b in branches if not b.confirmed]
    for b in unconfirmed:
        notes.append("a branch whose series continues to order "
                     f"{order_max} was not closed again at a step of {b.step:g} (residual {b.residual:.2g})")
    if not branches:
        at = max((f for _, f in failed), default=2)
        return LocalAnalysis(**common, finite_mobility=None, kind="undecided", order=None, checked_order=at,
                             certain=False,
                             decided_by=f"not decided: every tangent of the quadratic cone stops at order {at} or before "
                                        "in a power series (a cusp's half-branch, a branch of lower dimension inside "
                                        "the cone, or no motion: the series alone cannot tell)", branches=(),
                             notes=tuple(notes))
    finite = max(b.mobility for b in branches)
    mobilities = {b.mobility for b in branches}
    if len(branches) == 1:
        b = branches[0]
        if b.mobility == d and b.linear:
            kind = "regular"
        elif b.linear and b.nearby == d:  # smooth here, and as mobile instantaneously a step away: shaky
            kind = "shaky"
        else:
            kind = "singular"
    else:
        kind = "bifurcation" if len(mobilities) == 1 else "kinematotropic"
    certain = (regular_roots and c0 == 0 and not failed and not unconfirmed and all(b.linear for b in branches)
               and not sampled)
    if certain:
        order = 2
        how = (f"order 2: {_forms(c2)} on ker K (dimension {d}) {'vanish' if c2 > 1 else 'vanishes'} on "
               f"{len(branches)} linear space{'s' if len(branches) > 1 else ''} and {'their' if c2 > 1 else 'its'} "
               "Jacobian has full rank there: the tangent cone is decided")
    elif c2 == 0:
        order = order_max
        how = (f"to order {order_max}: every quadratic form on ker K vanishes identically ({c0} redundant "
               f"row{'s' if c0 > 1 else ''} along every motion) and the series continues in every direction "
               f"checked to order {order_max}; not decided beyond")
    else:
        order = order_max
        how = (f"to order {order_max}: the quadratic cone gives the tangents"
               + (f" (its zeros found from {sampled} starting directions: sampled, others not excluded)"
                  if sampled else "") + "; "
               + (f"{c0} row{'s' if c0 > 1 else ''} vanish identically at order 2 and " if c0 else "")
               + f"the series continues along each branch to order {order_max}; not decided beyond")
    return LocalAnalysis(**common, finite_mobility=int(finite), kind=kind, order=order, checked_order=order_max,
                         certain=certain, decided_by=how, branches=tuple(branches), notes=tuple(notes))


def _rates_text(rates: dict) -> str:
    return "(" + ", ".join(f"{n} {v:.4g}" for n, v in rates.items() if abs(v) > 0) + ")"


def _order_text(la: LocalAnalysis) -> str:
    if la.order is None:
        return "not decided"
    if la.certain:
        return f"decided at order {la.order}"
    return f"to order {la.checked_order} of the series, not decided beyond"


def words(la: LocalAnalysis) -> str:
    """The local analysis in words: the kind, the branches with their tangents, the order."""
    d, f = la.infinitesimal_mobility, la.finite_mobility
    n = len(la.branches)
    if la.kind == "regular":
        text = f"a regular point: the configuration space is smooth here, mobility {f}"
    elif la.kind == "bifurcation":
        b = la.branches[0].mobility
        text = (f"a change point: {_number_word(n)} branches of mobility {b} cross here (infinitesimal mobility {d}); "
                f"tangents " + "; ".join(_rates_text(x.tangent) for x in la.branches))
    elif la.kind == "kinematotropic":
        text = (f"branches of different mobility meet here (kinematotropic; infinitesimal mobility {d}): "
                + "; ".join(f"mobility {x.mobility} along {_rates_text(x.tangent)}" for x in la.branches))
    elif la.kind == "shaky" and not f:
        text = (f"a shaky point: infinitesimally mobile ({d} instantaneous degree{'s' if d > 1 else ''} of freedom) "
                "but finitely rigid")
    elif la.kind == "shaky":
        text = (f"a shaky linkage at a regular point: the configuration space is smooth here with mobility {f}, but "
                f"the instantaneous mobility is {d} here and a step away along it")
    elif la.kind == "singular":
        x = la.branches[0]
        cone = "" if x.linear else ", its tangent cone a quadric cone"
        text = (f"a singular point of one branch of mobility {x.mobility} (infinitesimal mobility {d}{cone}); "
                f"tangent {_rates_text(x.tangent)}")
    elif la.kind == "rigid":
        text = "rigid: no motion, not even an infinitesimal one"
    else:
        text = f"not decided (infinitesimal mobility {d}): {la.decided_by}"
        return text
    return f"{text} ({_order_text(la)})"


def _forms(c: int) -> str:
    return "the quadratic form" if c == 1 else f"the {c} quadratic forms"


def _number_word(n: int) -> str:
    return {2: "two", 3: "three", 4: "four"}.get(n, str(n))
