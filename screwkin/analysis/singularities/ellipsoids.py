"""Velocity and force ellipsoids of a Jacobian (issue 15 part 4).

For a map J from input rates to an output twist (v, w) -- a serial chain's frame Jacobian,
or for a closed loop the map through K q' = 0 with the inputs given -- made dimensionless as
everywhere in screwkin (linear velocities divided by the characteristic length L, the rates
of sliding inputs taken per L):

* the velocity ellipsoid {J qd : |qd| <= 1} has the left singular vectors u_i of J as its
  principal axes and the singular values s_i as its semi-axes (0 along directions J does not
  reach);
* the force ellipsoid {f : |J^T f| <= 1} -- the output wrenches that the unit ball of input
  efforts balances -- has the same axes and the reciprocal semi-axes 1 / s_i (inf where
  s_i = 0: a wrench there loads no input).  Its coordinates are the duals of (v / L, w):
  (L f, m), so that L f . v / L + m . w is the power.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...errors import UsageError
from ...tolerances import DEFAULT, Tolerances
from ..position.position import PositionSolver
from ...model.linalg import null_space, rank
from ..singular import SingularityReport, scaled_jacobians
from ...model.kernel.scaling import dimensionless
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["Ellipsoid", "Ellipsoids", "ellipsoids_of", "ellipsoids", "with_input_output_condition"]


@dataclass(frozen=True)
class Ellipsoid:
    """Principal axes (columns of ``axes``, unit, in the dimensionless output space) and the
    semi-axis along each (0 or inf where the map loses the direction)."""

    axes: np.ndarray
    semi_axes: np.ndarray


@dataclass(frozen=True)
class Ellipsoids:
    """Both ellipsoids of one dimensionless map ``jacobian`` (rows: ``rows``; the force
    ellipsoid's coordinates are ``force_rows``), with the inputs it takes, the characteristic
    length L [m] and the rank of the map."""

    velocity: Ellipsoid
    force: Ellipsoid
    jacobian: np.ndarray
    rows: tuple
    force_rows: tuple
    inputs: tuple
    length: float
    rank: int
    output: str | None = None
    point: bool = False


def _axis_labels(d: int, linear: int) -> tuple:
    lin = ("vx/L", "vy/L", "vz/L")[:linear]
    ang = ("wx", "wy", "wz")[: d - linear]
    flin = ("L fx", "L fy", "L fz")[:linear]
    fang = ("mx", "my", "mz")[: d - linear]
    return lin + ang, flin + fang


def _of_scaled(M: np.ndarray, L: float, inputs: list | tuple, tol: Tolerances, linear: int, output: str | None = None, point: bool=False) -> Ellipsoids:
    d = M.shape[0]
    U, s, _ = np.linalg.svd(M, full_matrices=True) if M.size else (np.eye(d), np.zeros(0), None)
    vel = np.zeros(d)
    vel[: len(s)] = s
    keep = vel > max(tol.rank_rtol * (vel[0] if d else 0.0), tol.rank_atol)
    vel[~keep] = 0.0
    force = np.full(d, np.inf)
    force[keep] = 1.0 / vel[keep]
    rows, frows = _axis_labels(d, linear)
    return Ellipsoids(Ellipsoid(U.copy(), vel), Ellipsoid(U.copy(), force), M, rows, frows, tuple(inputs), float(L),
                      int(keep.sum()), output, point)


def ellipsoids_of(J: np.ndarray, length: float = 1.0, linear: int = 3, sliding=None, inputs: list[str] | None=None,
                  tol: Tolerances = DEFAULT) -> Ellipsoids:
    """The ellipsoids of a Jacobian J (d x n) from input rates [rad/s, m/s] to an output twist
    whose first ``linear`` rows are linear velocities [m/s] (6 rows (v, w); 3 for a point:
    linear = 3; a planar (vx, vy, w): linear = 2): those rows are divided by ``length``, and the
    columns of the inputs marked in ``sliding`` (a mask: lengths) multiplied by it."""
    J = np.asarray(J, float)
    if J.ndim != 2 or not (0 <= linear <= J.shape[0]):
        raise ValueError("J must be a matrix whose first `linear` rows are linear velocities")
    if not (np.isfinite(length) and length > 0):
        raise ValueError("the characteristic length must be positive")
    M = dimensionless(J, slice(0, linear), np.zeros(J.shape[1], bool) if sliding is None else np.asarray(sliding, bool),
                      length)
    names = tuple(inputs) if inputs is not None else tuple(f"q{k + 1}" for k in range(J.shape[1]))
    return _of_scaled(M, length, names, tol, linear)


def ellipsoids(mech: Mechanism, q: np.ndarray, output: str, inputs: list | None=None, point: bool = False, length: float | None = None) -> Ellipsoids:
    """The velocity and force ellipsoids of link ``output``'s origin at the assembled
    configuration q (its twist (v, w) in world axes; ``point``: its velocity only).

    The inputs (default: the actuated joints; for a chain without loops and without declared
    actuators, every joint coordinate) drive the output through the passive joints' rates from
    K q' = 0 (PositionSolver.rates: the least-squares, minimum-norm passive rates, so idle
    spins stay still).  Lengths are divided by L = ``length`` or ``mech.length``."""
    q = np.asarray(q, float)
    L = float(length or mech.length)
    tol = mech.tolerances
    if mech.cuts:
        r = float(np.linalg.norm(mech.closure.residual(q)))
        if not r <= np.sqrt(tol.closure):  # a double root converges to about the square root of the tolerance
            raise UsageError(f"{mech.path}: the configuration does not close the loops (residual {r:.3g}); "
                             "solve or assemble it first")
    S = scaled_jacobians(mech, q, output, point, L)
    slide = mech.translational
    names = list(inputs) if inputs is not None else list(mech.actuated)
    if not names and not mech.cuts:
        return _of_scaled(S.J, L, mech.coordinate_names, tol, 3, output, point)
    solver = PositionSolver(mech, names)  # checks the names: 1-DOF joints, each once
    K = mech.closure.jacobian(q)
    cols = []
    for name, idx in zip(names, mech.velocity_indices(names)):
        qd = solver.rates(q, K, {name: 1.0})  # joint rates [rad/s, m/s] for a unit input rate
        x = qd.copy()
        x[slide] /= L  # in S.J's coordinates (its sliding columns are multiplied by L)
        cols.append(S.J @ x * (L if slide[idx] else 1.0))  # a sliding input's unit is L
    M = np.column_stack(cols) if cols else np.zeros((S.J.shape[0], 0))
    return _of_scaled(M, L, names, tol, 3, output, point)


def with_input_output_condition(mech: Mechanism, q: np.ndarray, rep: SingularityReport) -> SingularityReport:
    """``rep`` (singular.classify at q) with the condition number of the map from the input rates to the output's
    twist: Merlet's for a parallel robot, of its Jacobian J (input rates -> twist), = that of J^-1 (twist -> leg
    rates), dimensionless as every measure here -- the twist (v/L, w) at the output frame's origin, a sliding
    input's rate per L, L = ``rep.length``.  It is the largest over the smallest nonzero singular value of the map
    whose ellipsoids :func:`ellipsoids` gives.  inf where the output moves with the inputs held (an actuator
    singularity) or loses a direction (a serial one); None, with ``input_output_note`` saying why, without an
    output or where the inputs do not fix the output (fewer than it needs)."""
    io, note = _input_output_condition(mech, q, rep)
    return replace(rep, condition_input_output=io, input_output_note=note)


def _input_output_condition(mech: Mechanism, q: np.ndarray, rep: SingularityReport) -> tuple:
    tol = mech.tolerances
    if rep.output is None:
        return None, "give --output LINK, the moving platform"
    moving = next((t for t in rep.singular_twists if t.kind == "actuator"), None)
    if moving is not None and moving.twist is not None and np.linalg.norm(moving.twist) > tol.motion:
        return float("inf"), "the output moves with the inputs held: an actuator singularity"
    if rep.serial:
        return float("inf"), "the output loses a direction: a serial singularity"
    S = scaled_jacobians(mech, q, rep.output, rep.point, rep.length)
    inputs = list(rep.inputs)
    if inputs or mech.cuts:  # (a chain without loops or inputs: every joint is an input, as in ellipsoids)
        passive = np.setdiff1d(np.arange(mech.nv), mech.velocity_indices(inputs))
        held = null_space(S.K[:, passive] if S.K.size else np.zeros((0, len(passive))), tol, len(passive))
        if held.shape[1] and np.linalg.norm(S.J[:, passive] @ held, 2) > tol.motion * np.linalg.norm(S.J, 2):
            return None, "the inputs do not fix the output: it moves with them held (fewer inputs than it needs)"
    try:
        M = ellipsoids(mech, q, rep.output, inputs=inputs or None, point=rep.point, length=rep.length).jacobian
    except UsageError as exc:  # an input that is not a joint of one freedom, loops not closed
        return None, str(exc)
    s = np.linalg.svd(M, compute_uv=False)[:rank(M, tol)]
    return (float(s[0] / s[-1]), None) if len(s) else (None, "the inputs do not move the output")
