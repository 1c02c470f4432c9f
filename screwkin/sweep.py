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
    mech, model = solver.mech, solver.model
    closure = mech.closure
    tol = mech.tolerances
    xs = np.linspace(start, stop, steps + 1)
    first = solver.solve({name: xs[0], **fixed}, near=near, starts=8 if near is None else 0)
    q = first.solutions[0].q
    rates_in = {n: 0.0 for n in solver.inputs}
    rates_in[name] = rate
    K = closure.jacobian(q)
    qd = solver.rates(q, K, rates_in)
    Q, V, A, X = [q], [qd], [solver.accelerations(q, K, qd, {})], [xs[0]]
    stopped = reason = None
    show = progress and sys.stderr.isatty() and steps >= 200
    for k in range(1, len(xs)):
        x = xs[k]
        try:
            q_new, qd_new, K_new = _step(solver, q, qd, X[-1], x, name, rate, rates_in)
        except _Limit as exc:
            stopped, reason = _locate_limit(solver, q, qd, X[-1], x, name, rate, rates_in), str(exc)
            break
        q, qd = q_new, qd_new
        Q.append(q)
        V.append(qd)
        A.append(solver.accelerations(q, K_new, qd, {}))
        X.append(x)
        if show and k % max(steps // 50, 1) == 0:
            sys.stderr.write(f"\rsweep {k}/{steps} [{'#' * (50 * k // steps):<50}]")
    if show:
        sys.stderr.write("\n")
    Qa = np.array(Q)
    return SweepResult(name, np.array(X), Qa, np.array([_values(solver, qq) for qq in Q]), np.array(V) / 1.0,
                       np.array(A), tuple(mech.coordinate_names), rate, stopped, reason, (start, stop, steps))


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
    Kp = K[:, solver.passive]
    s = np.linalg.svd(Kp, compute_uv=False) if Kp.size else np.ones(1)
    r = solver.expected_rank
    if r and (len(s) < r or s[r - 1] / s[0] < mech.tolerances.singular):
        raise _Limit("the passive joints become undetermined (limit position / singular configuration)")
    jump = np.linalg.norm(pin.difference(model, q_pred, a.q))
    predicted = np.linalg.norm(qd * dt) + 1e-12
    if jump > max(0.5 * predicted, 1e-6) and jump > 1e-3:
        raise _Limit("the correction jumps to another branch (a limit or singular position lies in this step)")
    return a.q, solver.rates(a.q, K, rates_in), K


def _locate_limit(solver, q, qd, x_ok, x_bad, name, rate, rates_in, iterations=40):
    """Bisection on the input between the last reachable value and the first failure."""
    for _ in range(iterations):
        mid = 0.5 * (x_ok + x_bad)
        try:
            q, qd, _ = _step(solver, q, qd, x_ok, mid, name, rate, rates_in)
            x_ok = mid
        except _Limit:
            x_bad = mid
        if abs(x_bad - x_ok) < 1e-10:
            break
    return 0.5 * (x_ok + x_bad)
