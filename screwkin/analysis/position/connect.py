"""Moving between assembly modes without a singularity: a loop of two inputs (issue 44).

A 3-RPR can change assembly mode without meeting a singularity by encircling a cusp of its singular curve
in the plane of two inputs (McAree & Daniel 1999; Zein, Wenger & Chablat 2008).  ``loop`` follows one
configuration round an ellipse of the inputs x and y (the other inputs held) by small steps, each a damped
Newton solve from the last configuration (PositionSolver.track), and checks the path as a sweep would:
every step short (no jump to another branch: at most JUMP, dimensionless, lengths over L) and the actuator
measure (analysis.singular.measures) above Tolerances.singular all along, its smallest value
reported.  ``joined`` says whether it came back to another mode of the start's inputs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import AssemblyError
from ..singular import Generic, measures
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.position.position import PositionSolver

__all__ = ["CuspLoop", "Loop", "apart", "cusp_loops", "follow_inputs", "loop", "wedge_direction"]

#: A step of the loop that moves the configuration further than this (dimensionless) jumped branches.
JUMP = 0.05
#: A loop's end this near its start (dimensionless) is its start again: the steps close the loops to
#: Tolerances.closure (1e-10), and modes near a cusp differ by about the square root of the loop's size.
SAME = 1e-6


def apart(mech: Mechanism, q1: np.ndarray, q2: np.ndarray) -> float:
    """How far apart two configurations are: the norm of their difference, lengths over the
    characteristic length (rad and characteristic lengths) [-]."""
    d = mech.difference(q1, q2)
    d[mech.translational] /= mech.length
    return float(np.linalg.norm(d))


@dataclass(frozen=True)
class Loop:
    inputs: np.ndarray  # (n, 2) x, y along the loop [SI]
    q: np.ndarray  # (n, nq) the configurations followed
    sigma_min: float  # smallest relative actuator measure along the path
    regular: bool  # no singularity met and no step jumped
    joined: bool  # the end is another assembly mode than the start (same inputs)
    why: str  # in words


def loop(solver: PositionSolver, x_name: str, y_name: str, fixed: dict, centre: tuple, radius: tuple, q0: np.ndarray, steps: int = 720, start: float = 0.0,
         turn: int = 1) -> Loop:
    """Follow q0 (at the angle ``start`` of the ellipse) once round the ellipse of the inputs with ``centre``
    and semi-axes ``radius``, counter-clockwise (turn 1) or clockwise (turn -1), in ``steps`` steps."""
    angles = start + turn * np.linspace(0.0, 2 * np.pi, steps + 1)
    xy = np.column_stack([centre[0] + radius[0] * np.cos(angles), centre[1] + radius[1] * np.sin(angles)])
    return follow_inputs(solver, x_name, y_name, fixed, xy, q0)


def follow_inputs(solver: PositionSolver, x_name: str, y_name: str, fixed: dict, xy: np.ndarray, q0: np.ndarray) -> Loop:
    """Follow q0 (at the inputs xy[0]) along the inputs xy (n, 2) of x and y (the others held at ``fixed``),
    each step a damped Newton solve from the last configuration, checked as a sweep is (see the module)."""
    mech = solver.mech
    tol = mech.tolerances
    g = Generic(mech, solver.inputs, configurations=solver.generic().configurations)
    Q = [np.array(q0, float)]
    sig = [measures(mech, Q[0], g)["actuator"]]
    for k in range(1, len(xy)):
        try:
            q = solver.track({x_name: float(xy[k, 0]), y_name: float(xy[k, 1]), **fixed}, Q[-1]).q
        except AssemblyError:
            return Loop(xy[:k], np.array(Q), min(sig), False, False, f"the closure failed at step {k}")
        if apart(mech, Q[-1], q) > JUMP:
            return Loop(xy[:k + 1], np.array(Q + [q]), min(sig), False, False,
                        f"step {k} jumped (another branch): the loop passes too near a singularity for its steps")
        Q.append(q)
        sig.append(measures(mech, q, g)["actuator"])
    smallest = float(min(sig))
    regular = smallest > tol.singular
    joined = apart(mech, Q[0], Q[-1]) > SAME
    why = ("the loop ends on another assembly mode, no singularity met" if regular and joined else
           "the loop returns to its start" if regular else "the loop meets a singularity")
    return Loop(xy, np.array(Q), smallest, regular, joined, why)


def wedge_direction(points, cusp: tuple, radius: float) -> float:
    """The angle of the direction in which a cusp's two branches leave it (its wedge, where three modes
    meet), from a traced locus (points (n, 2)): the mean direction of its points between half and three
    times ``radius`` from the cusp."""
    d = np.asarray(points, float) - np.asarray(cusp, float)
    r = np.linalg.norm(d, axis=1)
    near = (r > 0.5 * radius) & (r < 3 * radius)
    if not near.any():
        near = r > 0
    u = (d[near] / r[near, None]).mean(axis=0)
    return float(np.arctan2(u[1], u[0]))


@dataclass(frozen=True)
class CuspLoop:
    cusp: tuple  # (x, y) [SI]
    start: tuple  # the loop's first inputs, inside the cusp's wedge
    radius: tuple  # semi-axes [SI]
    modes: tuple  # (i, j): the start's solutions (0-based, as listed) it leaves and reaches
    turn: int  # 1 counter-clockwise, -1 clockwise
    loop: Loop


def cusp_loops(solver: PositionSolver, loci, x_name: str, y_name: str, fixed: dict, box: tuple, size: float = 0.02, steps: int = 720) -> tuple:
    """For each cusp of the actuator loci (analysis.singularities.loci.Loci): every mode at a point inside
    its wedge, followed once round the cusp each way on an ellipse of semi-axes ``size`` times the box's
    sides (``loop``).  Returns (CuspLoop of every regular loop that ends on another mode, loops tried)."""
    mech = solver.mech
    span = np.array([box[0][1] - box[0][0], box[1][1] - box[1][0]], float)
    span[span == 0] = 1.0
    pts = [lc.points for lc in loci.loci if lc.kind == "actuator"]
    if not pts:
        return (), 0
    P = np.concatenate(pts) / span
    out, tried = [], 0
    for (cx, cy), kind in loci.cusps:
        if kind != "actuator":
            continue
        th = wedge_direction(P, (cx / span[0], cy / span[1]), size)
        r = size * span
        start = (cx + r[0] * np.cos(th), cy + r[1] * np.sin(th))
        try:
            sols = [s.q for s in solver.solve({x_name: start[0], y_name: start[1], **fixed}).solutions]
        except AssemblyError:
            continue
        for i, q in enumerate(sols):
            for turn in (1, -1):
                tried += 1
                lp = loop(solver, x_name, y_name, fixed, (cx, cy), tuple(r), q, steps, start=th, turn=turn)
                if not (lp.regular and lp.joined):
                    continue
                gaps = [apart(mech, qk, lp.q[-1]) for qk in sols]
                j = int(np.argmin(gaps)) if min(gaps) < SAME else None  # the start's solution it ends on
                out.append(CuspLoop((cx, cy), start, tuple(r), (i, j), turn, lp))
    return tuple(out), tried
