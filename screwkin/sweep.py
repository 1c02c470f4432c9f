"""Tracking one assembly mode along an input motion (sweeps).

Predictor-corrector continuation: the previous solution and its velocity
predict the next configuration (q + q' dx on the manifold), the closure solver
corrects it with the input held.  A step whose correction fails, jumps to
another branch, or lands on a singular configuration marks a limit of the
branch; the limit input value is located by bisection and the sweep stops
there, as the physical mechanism would (it cannot be driven past it).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ._pin import frame_jacobian
from .errors import AssemblyError, UsageError

__all__ = ["SweepResult", "sweep"]


@dataclass(frozen=True)
class SweepResult:
    input: str
    values: np.ndarray  # input values reached [rad or m]
    q: np.ndarray  # (steps, nq)
    joints: np.ndarray  # (steps, n coordinates) joint values, names in `names`
    rates: np.ndarray  # (steps, nv): rates for an input rate of `rate`
    accelerations: np.ndarray  # (steps, nv)
    names: tuple  # coordinate names (velocity coordinates)
    rate: float
    stopped_at: float | None  # input value of a branch limit, None when the sweep completed
    stop_reason: str | None
    requested: tuple  # (from, to, steps)

    def to_dict(self) -> dict:
        return {
            "input": self.input,
            "from": self.requested[0], "to": self.requested[1], "steps": self.requested[2],
            "completed": self.stopped_at is None,
            "stopped_at": self.stopped_at, "stop_reason": self.stop_reason,
            "coordinates": list(self.names),
            "values": self.values.tolist(),
            "joints": self.joints.tolist(),
            "rates": self.rates.tolist(),
            "accelerations": self.accelerations.tolist(),
        }

    def csv(self) -> str:
        head = ["step", self.input + "_input"] + list(self.names) + [f"d_{n}" for n in self.names] + [
            f"dd_{n}" for n in self.names]
        lines = [",".join(head)]
        for k in range(len(self.values)):
            row = [str(k), f"{self.values[k]:.12g}"] + [f"{x:.12g}" for x in self.joints[k]]
            row += [f"{x:.12g}" for x in self.rates[k]] + [f"{x:.12g}" for x in self.accelerations[k]]
            lines.append(",".join(row))
        return "\n".join(lines) + "\n"


def _values(solver, q):
    return np.array(list(solver.joint_values(q).values()))


def sweep(solver, name: str, start: float, stop: float, steps: int, fixed: dict | None = None,
          near: dict | None = None, rate: float = 1.0, progress: bool = False) -> SweepResult:
    """Track one assembly mode while input ``name`` goes from start to stop in ``steps`` steps.

    solver: a PositionSolver whose inputs include ``name``; the other inputs stay at ``fixed``.
    """
    if steps < 1:
        raise UsageError("a sweep needs at least 1 step")
    if name not in solver.inputs:
        raise UsageError(f"{solver.mech.path}: '{name}' is not one of the inputs ({', '.join(solver.inputs)})")
    fixed = dict(fixed or {})
    others = [n for n in solver.inputs if n != name]
    missing = [n for n in others if n not in fixed]
    if missing:
        raise UsageError(f"{solver.mech.path}: give values for the other inputs with --set: {', '.join(missing)}")
    mech = solver.mech
    closure = mech.closure
    xs = np.linspace(start, stop, steps + 1)
    first = solver.solve({name: xs[0], **fixed}, near=near, starts=8 if near is None else 0)
    q = first.solutions[0].q
    rates_in = {n: 0.0 for n in solver.inputs}
    rates_in[name] = rate
    K = closure.jacobian(q)
    solve, _ = solver.passive_solver(K)
    qd = solver.rates(q, K, rates_in, solve)
    Q, V, A, X = [q], [qd], [solver.accelerations(q, K, qd, {}, solve)], [xs[0]]
    stopped = reason = None
    show = progress and sys.stderr.isatty() and steps >= 200
    for k in range(1, len(xs)):
        x = xs[k]
        try:
            q_new, qd_new, K_new, solve = _step(solver, q, qd, X[-1], x, name, rate, rates_in)
        except _Limit as exc:
            stopped, reason = _locate_limit(solver, q, qd, X[-1], x, name, rate, rates_in), str(exc)
            break
        q, qd = q_new, qd_new
        Q.append(q)
        V.append(qd)
        A.append(solver.accelerations(q, K_new, qd, {}, solve))
        X.append(x)
        if show and k % max(steps // 50, 1) == 0:
            sys.stderr.write(f"\rsweep {k}/{steps} [{'#' * (50 * k // steps):<50}]")
    if show:
        sys.stderr.write("\n")
    Qa = np.array(Q)
    return SweepResult(name, np.array(X), Qa, np.array([_values(solver, qq) for qq in Q]), np.array(V) / 1.0,
                       np.array(A), tuple(mech.coordinate_names), rate, stopped, reason, (start, stop, steps))


@dataclass(frozen=True)
class SweepSingularity:
    kind: str  # "serial" | "actuator" | "constraint"
    input: float  # input value, refined [rad or m]
    sigma: float  # relative smallest singular value there
    q: np.ndarray


def _matrix(mech, q, kind, g, output, L, V_ref=None):
    """The matrix whose rank loss defines a singularity of this kind at q."""
    from .mobility import null_space

    K = mech.closure.jacobian(q)
    if kind == "constraint":
        return K
    if kind == "actuator":
        return K[:, g.p]
    data = mech.data
    pin.computeJointJacobians(mech.model, data, q)
    pin.updateFramePlacements(mech.model, data)
    J = frame_jacobian(mech.model, data, mech.link_frame(output), pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).copy()
    J[:3] /= L  # the output frame origin's twist, as singular.classify measures it
    N = null_space(K, mech.tolerances, mech.nv) if K.size else np.eye(mech.nv)
    V = N if V_ref is None else N @ (N.T @ V_ref)  # a basis that varies smoothly with q
    return J @ V


def locate_singularities(solver, res: SweepResult, output=None, xtol: float = 1e-12):
    """Singular input values along a sweep, each refined to about 1e-9 or better.

    Each relative smallest singular value is scanned over the sweep; around each
    local minimum the singular vectors u, v of that step give a smooth signed
    measure u . M(x) v that changes sign where M loses rank, and Brent's method
    finds its root (solutions re-closed at a tight tolerance).  Minima that are
    not zeros (no sign change) are not singular and are dropped.
    """
    from dataclasses import replace

    from scipy.optimize import brentq

    from .singular import Generic, characteristic_length, measures

    mech = solver.mech
    tight = replace(mech.tolerances, closure=1e-14, max_iterations=60)
    g = Generic(mech, solver.inputs, output)
    L = characteristic_length(mech, res.q[0])
    table = [measures(mech, q, g, output, L) for q in res.q]
    rank_of = {"constraint": g.rank_K, "actuator": g.rank_Kp, "serial": g.out_dim or 0}
    found = []
    xs = res.values
    for kind in table[0]:
        m = np.array([t[kind] for t in table])
        r = rank_of[kind]
        if r == 0:
            continue
        for k in range(len(m)):
            left = m[k - 1] if k > 0 else np.inf
            right = m[k + 1] if k + 1 < len(m) else np.inf
            if not (m[k] <= left and m[k] <= right) or m[k] > 0.5:
                continue
            q_k = res.q[k]
            V_ref = None
            if kind == "serial":
                from .mobility import null_space

                K = mech.closure.jacobian(q_k)
                V_ref = null_space(K, mech.tolerances, mech.nv) if K.size else np.eye(mech.nv)
            U, _, Vt = np.linalg.svd(_matrix(mech, q_k, kind, g, output, L, V_ref))
            u, v = U[:, r - 1], Vt[r - 1]

            def q_at(x, q_k=q_k):
                try:
                    return mech.closure.solve(solver.set_inputs(q_k, {res.input: x}), frozen=solver.frozen,
                                              tolerances=tight).q
                except AssemblyError:
                    return mech.closure.solve(solver.set_inputs(q_k, {res.input: x}), frozen=solver.frozen).q

            def signed(x, u=u, v=v, V_ref=V_ref):
                return float(u @ _matrix(mech, q_at(x), kind, g, output, L, V_ref) @ v)

            lo, hi = xs[max(k - 1, 0)], xs[min(k + 1, len(xs) - 1)]
            try:
                f_lo, f_hi = signed(lo), signed(hi)
            except AssemblyError:
                continue
            if f_lo == 0 or f_hi == 0 or np.sign(f_lo) == np.sign(f_hi):
                continue
            x = brentq(signed, lo, hi, xtol=xtol, rtol=4 * np.finfo(float).eps, maxiter=200)
            q = q_at(x)
            sigma = measures(mech, q, g, output, L)[kind]
            if sigma < mech.tolerances.singular and not any(
                    s.kind == kind and abs(s.input - x) < 1e-7 for s in found):
                found.append(SweepSingularity(kind, float(x), float(sigma), q))
    found.sort(key=lambda s: s.input)
    return found


class _Limit(Exception):
    pass


def _step(solver, q, qd, x0, x1, name, rate, rates_in):
    mech, model = solver.mech, solver.model
    dt = (x1 - x0) / rate
    q_pred = pin.integrate(model, q, qd * dt)
    q_pred = solver.set_inputs(q_pred, {name: x1})
    try:
        a = mech.closure.solve(q_pred, frozen=solver.frozen)
    except AssemblyError as exc:
        raise _Limit(f"the loops cannot be closed beyond this input (residual {exc.residual:.2g})") from None
    K = mech.closure.jacobian(a.q)
    solve, s = solver.passive_solver(K)
    s = s if s.size else np.ones(1)
    r = solver.expected_rank
    if r and (len(s) < r or s[r - 1] / s[0] < mech.tolerances.singular):
        raise _Limit("the passive joints become undetermined (limit position / singular configuration)")
    jump = np.linalg.norm(pin.difference(model, q_pred, a.q))
    predicted = np.linalg.norm(qd * dt) + 1e-12
    if jump > max(0.5 * predicted, 1e-6) and jump > 1e-3:
        raise _Limit("the correction jumps to another branch (a limit or singular position lies in this step)")
    return a.q, solver.rates(a.q, K, rates_in, solve), K, solve


def _locate_limit(solver, q, qd, x_ok, x_bad, name, rate, rates_in, iterations=40):
    """Bisection on the input between the last reachable value and the first failure."""
    for _ in range(iterations):
        mid = 0.5 * (x_ok + x_bad)
        try:
            q, qd, _, _ = _step(solver, q, qd, x_ok, mid, name, rate, rates_in)
            x_ok = mid
        except _Limit:
            x_bad = mid
        if abs(x_bad - x_ok) < 1e-10:
            break
    return 0.5 * (x_ok + x_bad)
