"""Telling assembly modes apart (analysis.position.position's solver): which solutions are one root (a
double root computed from several starts, or solutions joined by a motion with the inputs held:
a continuum), and why a mode is not one the mechanism reaches by moving from its reference
configuration (outside the joint limits, a prismatic leg reversed through its pivot, a link that
only translates found turned: a mirrored assembly).  Every placement is read from a
model.state.KinematicState of its own.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin

from ...errors import AssemblyError, UsageError
from ...model.linalg import null_space, rank
from ...model.state import KinematicState
from ..singular import scaled_jacobians
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any

__all__ = ["merge", "moves", "connected", "ModeLabels", "choose_mode", "simple_root", "continuum_words"]

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def choose_mode(solver, values: dict, k: int | None = None, near: dict | None = None, starts: int = 24,
                **options: Any) -> tuple:
    """The assembly mode a configuration is analysed in, or a motion starts from: the ``k``-th of
    ``solver.solve(values, near=near, **options)``'s solutions (default 1: the one nearest the reference
    configuration, or ``near``'s), as (q, k, n, result) with n the modes found and result solve's
    PositionResult.  A usage error when k is more than n.  Where the inputs leave a continuum (free degrees of
    freedom), the solutions are samples of it, not modes: n is 1, the first sample is used, a k over 1 is a
    usage error, and the result's notes say so (continuum_words).  The one rule every command's ``--mode K`` (and a
    study's ``mode``) goes by.  A k over 1 needs the list of every mode: solve searches them (method "auto",
    whatever ``options`` say), listed from the reference configuration (``near`` is not used: it picks one
    mode, not a list)."""
    if k is not None and k > 1:
        near, options = None, {**options, "method": "auto"}
    res = solver.solve(values, near=near, starts=starts, **options)
    n, k = len(res.solutions), k or 1
    if res.free_dofs:  # a continuum: its configurations found are samples of it, not modes to number
        if k > 1:
            raise UsageError(f"--mode {k}: {continuum_words(res.free_dofs)}: the configurations found are samples of "
                             "it, not assembly modes to choose among; --set more inputs (or --near) to choose one")
        note = (f"{continuum_words(res.free_dofs)}: the configuration used is one sample of it, the one nearest "
                "the starting configuration (--near's, else the file's), not an assembly mode")
        return res.solutions[0].q, 1, 1, replace(res, notes=res.notes + (note,))
    if k > n:
        raise UsageError(f"--mode {k}: these inputs give {n} assembly mode{'s' if n != 1 else ''}")
    return res.solutions[k - 1].q, k, n, res


def continuum_words(free: int) -> str:
    """The words every command says a continuum in: the inputs leave ``free`` degrees of freedom free."""
    return f"these inputs leave {free} degree{'s' if free != 1 else ''} of freedom free (a continuum)"


def merge(solver, sols) -> list:
    """Solutions that are one root: a singular solution and others within the accuracy a
    double root can be computed to (about the square root of the closure tolerance), or
    joined to it by a motion with the inputs held (a continuum)."""
    tol = solver.mech.tolerances
    close = 100 * np.sqrt(tol.closure) * solver.mech.length
    groups = []
    for s in sols:
        for g in groups:
            if not (s.singular or g[0].singular):
                continue
            d = solver._distance(g[0].q, s.q)
            if d < close or connected(solver, g[0].q, s.q):
                g.append(s)
                break
        else:
            groups.append([s])
    out = []
    for g in groups:
        spread = max([solver._distance(g[0].q, s.q) for s in g[1:]], default=0.0)
        keep = min(g, key=lambda s: s.sigma_min)
        continuum = spread >= close or (keep.singular and moves(solver, keep.q))
        out.append(replace(keep, singular=keep.singular or len(g) > 1, continuum=continuum,
                           merged=sum(s.merged for s in g)))
    return out


def moves(solver, q: np.ndarray, step: float = 1e-3) -> bool:
    """Whether the mechanism can move a finite distance from q with the inputs held (a
    continuum), not only to first order (a double root): a step of ``step`` (dimensionless)
    along each direction the passive joints lost at q, closed again with the inputs frozen,
    stays where it went (the correction is small next to the step) at a double root the
    solver pulls it back."""
    mech, g = solver.mech, solver.generic()
    S = scaled_jacobians(mech, q)
    Kp = S.K[:, g.p]
    if not Kp.size or g.rank_Kp == 0:
        return False
    _, s, vt = np.linalg.svd(Kp)
    lost = [k for k in range(min(g.rank_Kp, len(s))) if s[k] < mech.tolerances.singular * s[0]]
    scale = np.where(mech.translational, mech.length, 1.0)
    for k in lost:
        for sign in (1.0, -1.0):
            dq = np.zeros(mech.nv)
            dq[g.p] = sign * step * vt[k]
            pred = pin.integrate(solver.model, q, dq * scale)
            try:
                got = mech.closure.solve(pred, frozen=solver.frozen).q
            except AssemblyError:
                continue
            back = np.linalg.norm(mech.difference(pred, got) / scale)
            if back < 0.1 * step:
                return True
    return False


def connected(solver, q1: np.ndarray, q2: np.ndarray, pieces: int = 12) -> bool:
    """Whether q2 is reached from q1 by a motion with the inputs held: a walk of small steps
    toward q2, each closed again with the inputs frozen, whose corrections stay small next
    to the step (between two distinct roots the correction pulls the walk back)."""
    closure, model = solver.mech.closure, solver.model
    q = q1
    for k in range(pieces):
        step = solver.mech.difference(q, q2) / (pieces - k)
        size = float(np.linalg.norm(step))
        if size < solver.mech.tolerances.zero:
            return True
        pred = pin.integrate(model, q, step)
        try:
            q = closure.solve(pred, frozen=solver.frozen).q
        except AssemblyError:
            return False
        if np.linalg.norm(solver.mech.difference(pred, q)) > 0.3 * size:
            return False
    gap = float(np.linalg.norm(solver.mech.difference(q, q2)))
    return gap < solver.mech.tolerances.geometry * max(solver.mech.length, 1e-3)


class ModeLabels:
    """The labels of analysis.position.solution.Solution.labels for one solver: built once (the prismatic
    legs between a pivot and a far joint, with their signed length at the reference configuration,
    and the links that only translate, with their reference orientation), then read at each
    solution.  Nothing is labelled for mechanisms without loops or without a reference."""

    def __init__(self, solver) -> None:
        mech, model = solver.mech, solver.model
        self.mech, self.model = mech, model
        self.legs, self.turned = [], []
        ref = solver.reference() if mech.cuts else None
        self.active = ref is not None
        if not self.active:
            return
        state = KinematicState(mech, ref)
        cut_frames = {}
        for c in mech.cuts:
            for f in (c.frame1, c.frame2):
                cut_frames.setdefault(model.frames[f].parentJoint, []).append(f)
        axes = {j.name: np.asarray(j.axis, float) for j in mech.spec.joints}
        for c in mech.coordinates:
            parent = model.parents[c.joint_id]
            if c.nq != 1 or not mech.translational[c.idx_v] or parent == 0 or c.joint not in axes:
                continue
            fars = [("joint", k) for k in model.children[c.joint_id]]
            fars += [("frame", f) for f in cut_frames.get(c.joint_id, [])]
            if not fars:
                continue
            axis = axes[c.joint]
            s_ref = self._signed_length(state, c.joint_id, fars[0], axis)
            if abs(s_ref) > mech.tolerances.geometry * mech.length:
                self.legs.append((c.joint, c.joint_id, fars[0], axis, s_ref))
        configs = solver.generic().configurations
        topo = mech.topology(ref)
        held = len(mech.closure.row_inputs)  # rows of links held at an angle (the last ones): inputs, not loops
        Vs = [null_space(mech.closure.jacobian(q)[:mech.closure.nrows - held], mech.tolerances, mech.nv)
              for q in configs]
        states = [KinematicState(mech, q) for q in configs]
        for link in topo.links:
            if link == topo.ground:
                continue
            fid = mech.link_frame(link)
            if not any(rank(st.frame_jacobian(fid, LWA)[3:] @ V, mech.tolerances) for st, V in zip(states, Vs)):
                self.turned.append((link, fid, state.frame_placement(fid).rotation.copy()))

    def _signed_length(self, state: KinematicState, jid, far, axis: np.ndarray) -> float:
        kind, i = far
        p = state.joint_placement(i).translation if kind == "joint" else state.frame_placement(i).translation
        return float((p - state.joint_placement(self.model.parents[jid]).translation)
                     @ (state.joint_placement(jid).rotation @ axis))

    def __call__(self, q: np.ndarray, outside) -> tuple:
        """Why the solution at q is not reached by moving from the reference configuration."""
        labels = [f"outside the joint limits: {', '.join(outside)}"] if outside else []
        if not self.active:
            return tuple(labels)
        state = KinematicState(self.mech, q)
        reversed_ = [name for name, jid, far, axis, s_ref in self.legs
                     if s_ref * self._signed_length(state, jid, far, axis) < 0]
        if reversed_:
            labels.append(f"legs reversed through their pivots: {', '.join(reversed_)}")
        turned_ = [link for link, fid, R_ref in self.turned
                   if np.linalg.norm(pin.log3(R_ref.T @ state.frame_placement(fid).rotation))
                   > self.mech.tolerances.geometry]
        if turned_:
            labels.append(f"turned although they only translate as the mechanism moves (a mirrored assembly): "
                          f"{', '.join(turned_)}")
        return tuple(labels)


def simple_root(solver, q: np.ndarray, step: float = 1e-7) -> bool:
    """Whether the closed configuration q is a simple root of the closure with the inputs held (isolated,
    its passive Jacobian of the generic rank however ill-conditioned): from q moved by ``step``
    (dimensionless) along the passive direction the Jacobian resolves worst, one undamped Newton step
    comes back within a twentieth of the step.  At a simple root the error after the step is about
    gamma step^2 (Newton's quadratic convergence); at a double root half the step (linear
    convergence along the lost direction); on a continuum the whole step (no force back)."""
    mech, g = solver.mech, solver.generic()
    closure = mech.closure
    free = closure.free_columns(tuple(int(f) for f in solver.frozen))
    scale = np.where(mech.translational, mech.length, 1.0)[free]
    K = closure.evaluate(q, jacobian=True, solver=True)[1][:, free]
    k = g.rank_Kp
    if k == 0 or not K.size:
        return True
    _, s, vt = np.linalg.svd(K * scale)
    if k > len(s):
        return False
    dq = np.zeros(mech.nv)
    dq[free] = step * vt[k - 1] * scale
    qp = pin.integrate(solver.model, q, dq)
    r, K = closure.evaluate(qp, jacobian=True, solver=True)
    back = np.zeros(mech.nv)
    back[free] = -np.linalg.lstsq(K[:, free], r, rcond=None)[0]
    q1 = pin.integrate(solver.model, qp, back)
    err = mech.difference(q, q1)[free] / scale
    return bool(np.linalg.norm(err) < 0.05 * step)
