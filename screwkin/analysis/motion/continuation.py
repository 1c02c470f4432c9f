"""One continuation (issue 37): the pieces every engine that follows a motion along an input shares.

The solutions of the closure equations with the other inputs held form a curve (one DOF; idle spins
aside).  An engine follows it by predictor-corrector steps, through one small interface (``Engine``):

- ``predict``: move a configuration a (dimensionless) step sigma along the curve's tangent;
- ``correct``: close the loops again with one joint held (the input, or near a limit position the
  one-DOF joint with the largest share of the tangent);
- ``accept``: the jump test -- a correction that moved the prediction by more than
  Tolerances.jump times the step (Tolerances.jump_floor at least) left the curve for another branch;
- ``choose_branch``: the branch rule -- of the two orientations of a tangent, the one that continues
  the previous (a positive dot product); a limit position lies between two configurations where the
  input's share of the so-oriented tangent changes sign (``passes_limit``);
- ``locate_limit``: the limit position bracketed between two configurations (Brent's method,
  ``locate``).

The tangent (``projections``) is the input's direction projected onto the null space of the
constraint Jacobian, in dimensionless coordinates (lengths divided by the characteristic length),
stacked so that one configuration and a batch of them are the same computation.  The engines:
``Curve`` here (one configuration at a time: the per-step tracker of analysis.motion.tracker walks
with it, and ``Neighbour`` takes a map's steps with it), ``BatchedCurve`` (analysis.motion.batch_sweep:
a chunk of grid values at once), ``ClosedFormCurve`` (analysis.motion.dyads: every value at once, its
limit positions located by ``locate``, its return to the start by ``returned``), the workspace's grid
growth (analysis.design.workspace_grid: the jump test, and ``keeps_orientation``, the branch rule in
several parameters), and the certified mode search's homotopy paths (model.homotopy.tracking.Paths: predict,
correct, accept -- in complex space there is no branch to choose nor limit to locate; the layers keep
that engine below this module, which it matches by its methods).  analysis.motion.sweep chooses among
the first three.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
import pinocchio as pin

from ...errors import AssemblyError
from ...model.geometry import TINY
from ..singular import measures
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.tolerances import Tolerances
    from collections.abc import Callable

__all__ = ["Engine", "Curve", "Stuck", "Motion", "Neighbour", "projections", "orient", "passes_limit", "keeps_orientation", "jumped",
           "locate", "returned", "continuation_steps",
           "LIMIT_REASON", "CHANGE_REASON", "at_change_point"]

LIMIT_REASON = ("limit position: the passive joints become undetermined (an actuator singularity); "
                "the input cannot go further on this branch")
#: Where an engine stops at a "limit position" where the loops' Jacobian K itself loses rank: a change point,
#: which the input passes (analysis.motion.sweep carries the motion on through it; the engine does not turn back).
CHANGE_REASON = "change point: branches of the motion cross here (the loops' Jacobian loses rank)"


class Stuck(Exception):
    """A continuation step that cannot be taken (the loops do not close, the correction jumped, the
    input does not move here); the engine shortens the step, holds another joint, or stops."""


@dataclass
class Motion:
    """What an engine reached: the configurations Q at the input values X in the order of the
    motion, the limit positions met ((input value, relative sigma, configuration) each), where and
    why it stopped short (None: it did not), the grid values it passed but could not solve at, its
    notes, and whether it came back to its start."""

    X: list
    Q: list
    limits: list = field(default_factory=list)
    stopped: float | None = None
    reason: str | None = None
    skipped: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    closed: bool = False


class Engine(Protocol):
    """The interface of a continuation engine along an input (see the module docstring): five questions,
    each engine answering them on its own state.  ``Curve`` answers them for one configuration: q (nq,),
    t its oriented unit tangent (nv,) in scaled coordinates, sigma a dimensionless step, ``held`` a
    velocity index; ``BatchedCurve`` (analysis.motion.batch_sweep) for a stack, one configuration per
    row (sigma (N,), the corrections (N, nq) with a flag per row).  ``ClosedFormCurve``
    (analysis.motion.dyads: input values instead of steps, a sign per dyad for the branch) and the
    homotopy's ``Paths`` (model.homotopy.tracking: complex paths) answer the same questions with signatures of
    their own: they are not Engines."""

    def predict(self, q: np.ndarray, t: np.ndarray, sigma: float | np.ndarray) -> np.ndarray:
        """Where the next configuration(s) should be: q moved sigma along t on the configuration
        manifold -- (nq,), or (N, nq) for sigma (N,)."""
        ...

    def correct(self, predicted: np.ndarray, held: int) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
        """The configuration closing the loops from the prediction with velocity index ``held`` held
        (nq,) (raises Stuck); for a stack (N, nq) and whether each row closed (N,) bool."""
        ...

    def accept(self, predicted: np.ndarray, corrected: np.ndarray, sigma: float | np.ndarray) -> bool | np.ndarray:
        """Whether the correction stayed on the curve (``jumped``; for a stack one flag per row (N,),
        and ``passes_limit``)."""
        ...

    def choose_branch(self, t: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
        """The tangent(s) t oriented to continue the motion of ``previous`` (``orient``)."""
        ...

    def locate_limit(self, qa: np.ndarray, ta: np.ndarray, qb: np.ndarray, held: int) -> tuple[np.ndarray, float]:
        """The limit position bracketed between qa (tangent ta) and qb, with ``held`` the parameter
        (``locate``): (its configuration (nq,), its input offset from qa)."""
        ...


def projections(K: np.ndarray, V: np.ndarray, scale: np.ndarray, free: np.ndarray, tol: Tolerances) -> np.ndarray:
    """The vectors V (N, nv) projected onto the null space of the scaled constraint Jacobians K
    (N, m, nv) -- columns times ``scale`` (characteristic lengths for sliding joints), restricted to
    the ``free`` columns (the held inputs have no part) -- with the rank rule of model.linalg (singular
    values above tol.rank_rtol * the largest and tol.rank_atol).  (N, nv), zero off ``free``.  With V
    the input's direction this is the curve's (unnormalized) tangent P e; the one definition of it."""
    K, V = np.asarray(K, float), np.atleast_2d(np.asarray(V, float))
    N, nv = V.shape
    out = np.zeros((N, nv))
    if K.ndim < 3 or K.shape[1] == 0:
        out[:, free] = V[:, free]
        return out
    Ks = (K * scale)[:, :, free]
    m, f = Ks.shape[1:]
    if N == 1:  # one configuration (the per-step engines): plain matrix products, no stacked einsum
        _, s, vt = np.linalg.svd(Ks[0], full_matrices=m < f)
        r = int(np.sum(s > max(tol.rank_rtol * s[0], tol.rank_atol))) if s.size and s[0] > tol.rank_atol else 0
        null = vt[r:]
        out[0, free] = null.T @ (null @ V[0, free])
        return out
    # a tall matrix's thin SVD has every right singular vector (as model.linalg.null_space)
    _, s, vt = np.linalg.svd(Ks, full_matrices=m < f)
    sp = np.zeros((N, f))
    sp[:, :s.shape[1]] = s
    ranked = (sp > np.maximum(tol.rank_rtol * sp[:, :1], tol.rank_atol)) & (sp[:, :1] > tol.rank_atol)
    coef = np.einsum("nkj,nj->nk", vt, V[:, free]) * ~ranked
    out[:, free] = np.einsum("nk,nkj->nj", coef, vt)
    return out


def orient(t: np.ndarray, previous: np.ndarray) -> np.ndarray:
    """The branch rule: t, or -t, whichever continues ``previous`` (a non-negative dot product);
    t itself without a previous one.  Rows of a stack are oriented each like the row before it,
    the first like ``previous``."""
    if previous is None:
        return t
    t = np.asarray(t, float)
    if t.ndim == 1:
        return -t if t @ previous < 0 else t
    prev = np.vstack([np.asarray(previous, float)[None], t[:-1]])
    d = np.sign(np.einsum("ij,ij->i", t, prev))
    d[d == 0] = 1.0
    return t * np.cumprod(d)[:, None]


def passes_limit(ta: np.ndarray, tb: np.ndarray, ix: int) -> bool:
    """A limit position between two configurations (oriented tangents ta, tb: ``orient``): the
    input's share of the tangent does not keep its sign (rows of stacks compared pairwise)."""
    return np.asarray(ta)[..., ix] * np.asarray(tb)[..., ix] <= 0


def keeps_orientation(Ks_from: np.ndarray, Ks_new: np.ndarray, r: int) -> bool:
    """The branch rule of a continuation in several parameters (a workspace's grid growth): each new
    Jacobian (N, m, n; dimensionless) restricted to the old one's range and row space (rank r) keeps the
    sign of its determinant -- a jump across a fold to another working mode flips it.  With one
    parameter it is ``passes_limit``'s rule.  The old row space C: the top r eigenvectors of
    Ks^T Ks (half the cost of an SVD); the old range is Ks C / s, so det(B^T K_new C) has the sign
    of det(C^T Ks^T K_new C).  (N,) bool."""
    C = np.linalg.eigh(Ks_from.transpose(0, 2, 1) @ Ks_from)[1][:, :, -r:]
    KC = Ks_from @ C
    return np.linalg.det(KC.transpose(0, 2, 1) @ Ks_new @ C) > 0


def jumped(miss: float | np.ndarray, sigma: float, tol: Tolerances) -> np.ndarray | bool:
    """The jump test: a correction of (dimensionless) length ``miss`` after a predicted step of
    length sigma left the curve when it is more than tol.jump * |sigma| and tol.jump_floor (NaN:
    it did)."""
    return ~(np.asarray(miss) <= np.maximum(tol.jump * np.abs(sigma), tol.jump_floor))


def locate(f: Callable[[float], float], lo: float, hi: float, xtol: float=1e-14, maxiter: int=100) -> float:
    """The root of f bracketed in [lo, hi] (f changes sign there) by Brent's method, to xtol and
    four units of round-off: where every engine locates its limit positions (the tangent's input
    share, a closed form's discriminant) and the input values on an arc near them."""
    from scipy.optimize import brentq  # (here: importing scipy.optimize takes 0.3 s, a sweep 20 ms)

    return brentq(f, lo, hi, xtol=xtol, rtol=4 * np.finfo(float).eps, maxiter=maxiter)


def returned(mech: Mechanism, x: float, start: float, h: float, q: np.ndarray, q0: np.ndarray, scale: np.ndarray) -> bool:
    """The motion is back at its start: the input at ``start`` (Tolerances.equal relative to the grid
    step h) and the configuration q at q0 (Tolerances.geometry, dimensionless)."""
    tol = mech.tolerances
    return bool(abs(x - start) < tol.equal * max(1.0, abs(h))
                and np.linalg.norm(pin.difference(mech.model, q, q0) / scale) < tol.geometry)


def at_change_point(solver, q: np.ndarray) -> dict:
    """The singularity measures at a located limit position q (analysis.singular.measures),
    with "change": whether K itself loses rank there (a change point, not a limit position: the input
    passes it on a branch that goes on)."""
    m = measures(solver.mech, q, solver.generic())
    return {**m, "change": solver.generic().rank_K > 0 and m["constraint"] < solver.mech.tolerances.singular}


def continuation_steps(mech: Mechanism, name: str, dx: float) -> int:
    """How many steps a continuation takes to move input ``name`` by ``dx`` [rad or m]: steps of at most
    Tolerances.max_step (scaled: characteristic lengths for a sliding input), as the sweep takes them."""
    c = mech.coordinate(name)
    scale = mech.length if mech.translational[c.idx_v] else 1.0
    return int(np.ceil(abs(dx) / (mech.tolerances.max_step * scale)))


class Curve:
    """The curve along input ``name`` of a PositionSolver, one configuration at a time: an ``Engine``."""

    def __init__(self, solver, name: str) -> None:
        mech = self.mech = solver.mech
        self.solver, self.model, self.closure = solver, solver.model, mech.closure
        self.name = name
        self.tol = mech.tolerances
        self.ix = int(mech.velocity_indices([name])[0])
        others = [n for n in solver.inputs if n != name]
        self.frozen_other = tuple(int(i) for i in mech.velocity_indices(others))
        self.free = np.setdiff1d(np.arange(mech.nv), self.frozen_other)
        self.scale = np.where(mech.translational, mech.length, 1.0)  # scaled rate -> rate
        self.e = np.zeros(mech.nv)
        self.e[self.ix] = 1.0
        # joints that can be held: one-DOF coordinates (revolute, prismatic, continuous)
        self.holdable = np.zeros(mech.nv, bool)
        for c in mech.coordinates:
            if c.nv == 1:
                self.holdable[c.idx_v] = True
        self.holdable[list(self.frozen_other)] = False

    @property
    def unit(self) -> str:
        return "m" if self.mech.translational[self.ix] else "rad"

    def input_directions(self, K: np.ndarray) -> np.ndarray:
        """The unnormalized tangents P e at configurations of constraint Jacobians K (N, m, nv)."""
        return projections(K, self.e[None].repeat(len(K), 0), self.scale, self.free, self.tol)

    def tangent(self, q: np.ndarray, previous: np.ndarray | None=None) -> np.ndarray:
        """Unit tangent of the curve at q in scaled coordinates (nv; zero on the held inputs),
        oriented like ``previous`` (``choose_branch``): the input's direction projected onto the null
        space of K; at a limit position itself (tol.limit_share), ``previous`` projected instead."""
        K = self.closure.jacobian(q)
        K = K[None] if K.size else np.zeros((1, 0, self.mech.nv))
        t = self.input_directions(K)[0]
        if np.linalg.norm(t) < self.tol.limit_share and previous is not None:
            t = projections(K, previous[None], self.scale, self.free, self.tol)[0]
        n = np.linalg.norm(t)
        if n < TINY:
            raise Stuck("the mechanism cannot move along this input here")
        return self.choose_branch(t / n, previous)

    def choose_branch(self, t: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
        return orient(t, previous)

    def along(self, q: np.ndarray, direction: float) -> np.ndarray:
        """The unit tangent at q oriented so that the input moves the way of ``direction`` (its sign;
        zero: increasing) -- where a motion starts."""
        t = self.tangent(q)
        return -t if t[self.ix] * (np.sign(direction) or 1.0) < 0 else t

    def hold(self, t: np.ndarray) -> int:
        """The velocity index of the joint to hold for a step along t: the input when it has a
        large share of the tangent, else the one-DOF joint with the largest share."""
        scores = np.where(self.holdable, np.abs(t), -1.0)
        best = int(np.argmax(scores))
        return self.ix if abs(t[self.ix]) >= 0.5 * scores[best] else best

    def frozen(self, held: int) -> tuple:
        return tuple(sorted(set(self.frozen_other) | {held}))

    def predict(self, q: np.ndarray | list, t: np.ndarray | list, sigma: float) -> np.ndarray:
        return pin.integrate(self.model, q, self.scale * t * sigma)

    def correct(self, predicted: np.ndarray, held: int) -> np.ndarray:
        try:
            return self.closure.solve(predicted, frozen=self.frozen(held)).q
        except AssemblyError:
            raise Stuck("the loops cannot be closed") from None

    def accept(self, predicted: np.ndarray, corrected: np.ndarray, sigma: float) -> bool:
        miss = np.linalg.norm(pin.difference(self.model, predicted, corrected) / self.scale)
        return not jumped(miss, sigma, self.tol)

    def step(self, q: np.ndarray, t: np.ndarray, sigma: float, held: int) -> np.ndarray:
        """Move sigma (scaled) along t, hold joint ``held`` there, close the loops again."""
        pred = self.predict(q, t, sigma)
        q_new = self.correct(pred, held)
        if not self.accept(pred, q_new, sigma):
            raise Stuck("the correction jumps away from the curve")
        return q_new

    def at_input(self, q_from: np.ndarray, x_from: float, x: float, t: np.ndarray) -> np.ndarray:
        """The configuration at input value x, predicted from q_from (input x_from) along t."""
        dx = (x - x_from) / self.scale[self.ix]
        if abs(t[self.ix]) < self.tol.zero:
            raise Stuck("the input does not move here")
        return self.step(q_from, t, dx / t[self.ix], self.ix)

    def input_change(self, q0: np.ndarray, q1: np.ndarray) -> float:
        return float(pin.difference(self.model, q0, q1)[self.ix])

    def _arc(self, qa: np.ndarray, qb: np.ndarray, held: int, message: str) -> Callable:
        """The configuration a share u of the way from qa to qb with joint ``held`` as the parameter."""
        delta = pin.difference(self.model, qa, qb)
        frozen, cache = self.frozen(held), {0.0: qa, 1.0: qb}

        def at(u: float):
            if u not in cache:
                try:
                    cache[u] = self.closure.solve(pin.integrate(self.model, qa, u * delta), frozen=frozen).q
                except AssemblyError:
                    if message is None:
                        raise
                    raise Stuck(message) from None
            return cache[u]

        return at

    def on_arc(self, qa: np.ndarray, xa: float, qb: np.ndarray, held, x: float):
        """The configuration at input value x on the arc from qa (input xa) to qb, followed with
        joint ``held`` as the parameter (the input changes monotonically along it: no limit
        position strictly between): Brent's method on the held joint's share of the way.  Near a
        limit position the tangent predictor of ``at_input`` overshoots the curve's bend; this
        does not.  Raises Stuck when x is not between the ends."""
        xb = xa + self.input_change(qa, qb)
        if (x - xa) * (x - xb) > 0:
            raise Stuck("the value is not on this arc")
        at = self._arc(qa, qb, held, "the loops cannot be closed on the arc")

        def f(u: float):
            return xa + self.input_change(qa, at(u)) - x

        fa, fb = f(0.0), f(1.0)
        if fa == 0:
            return qa
        if fb == 0:
            return qb
        if np.sign(fa) == np.sign(fb):
            raise Stuck("the value is not on this arc")
        u = locate(f, 0.0, 1.0)
        # polish at the exact input value (the held joint then follows); where the loops cannot be closed
        # with the input held there, the value is a hole of the motion (the tracker records it), not an error
        try:
            return self.closure.solve(self.solver.set_inputs(at(u), {self.name: x}), frozen=self.frozen(self.ix)).q
        except AssemblyError:
            raise Stuck("the loops cannot be closed at this input value") from None

    def locate_limit(self, qa: np.ndarray, ta: np.ndarray, qb: np.ndarray, held: int) -> tuple:
        """The limit position between qa and qb (the input's tangent component changes sign),
        with joint ``held`` as the parameter: (configuration, input offset from qa)."""
        at = self._arc(qa, qb, held, None)

        def f(s: float) -> float:
            return float(self.tangent(at(s), ta)[self.ix])

        fa, fb = float(ta[self.ix]), f(1.0)
        if fa == 0 or fb == 0 or np.sign(fa) == np.sign(fb):  # pragma: no cover - the caller saw a change
            s = 1.0
        else:
            s = locate(f, 0.0, 1.0)
        q = at(s)
        return q, self.input_change(qa, q)


class Neighbour:
    """One continuation step along input ``name`` of a PositionSolver, from a configuration to
    a nearby input value on the same branch: the sweep's predictor along the curve's tangent,
    its corrector and its branch tests (a correction that jumps away from the curve, or a
    limit position between the two values, refuses the step).  Maps walk their grids with it."""

    def __init__(self, solver, name: str) -> None:
        self.curve = Curve(solver, name)

    def __call__(self, q: np.ndarray, x_from: float, x_to: float) -> np.ndarray | None:
        """The configuration at input value x_to on q's branch (q at x_from), or None."""
        c = self.curve
        direction = np.sign(x_to - x_from)
        if direction == 0:
            return q
        pieces = continuation_steps(c.mech, c.name, x_to - x_from)
        try:
            t = c.along(q, direction)
            x = x_from
            for k in range(1, pieces + 1):
                x_next = x_to if k == pieces else x_from + (x_to - x_from) * k / pieces
                q = c.at_input(q, x, x_next, t)
                t_next = c.tangent(q, t)
                if passes_limit(t, t_next, c.ix):
                    return None  # a limit position lies between the two values
                x, t = x_next, t_next
        except Stuck:
            return None
        return q
