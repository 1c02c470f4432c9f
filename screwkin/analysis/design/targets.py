"""A synthesized design's targets (``<screwkin:targets>``, docs/format.md) against its linkage:
where the file's linkage puts the target's link at each precision position, and, for a path
(point targets), the point's curve over the whole motion through them -- the data of
``screwkin draw``'s picture of a design.  Nothing here draws or prints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ...errors import AssemblyError
from ...model.geometry import wrap_angle
from ...model.state import KinematicState
from ..course.figures import trace_points
from ..motion.links import Point, motion_along
from ..position.position import PositionSolver
from ..motion.sweep import sweep
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.files.description import TargetSpec

__all__ = ["TargetReached", "DesignTargets", "design_targets", "polished", "POLISH_CLOSURE"]

TWO_PI = 2 * math.pi
#: Closure residual a precision position's solution is polished to (the solver stops at its tolerance,
#: about 1e-10; a target is compared to 1e-9).
POLISH_CLOSURE = 1e-13


def polished(mech: Mechanism, solver: PositionSolver, q: np.ndarray) -> tuple:
    """(q, residual): ``q`` closed by damped Newton to a residual below POLISH_CLOSURE with the
    solver's inputs held (unchanged, residual None, when that does not converge)."""
    tight = replace(mech.tolerances, closure=POLISH_CLOSURE, max_iterations=60)
    try:
        out = mech.closure.solve(q, frozen=solver.frozen, tolerances=tight)
    except AssemblyError:
        return q, None
    return out.q, out.residual


@dataclass(frozen=True)
class TargetReached:
    """One target (files.description.TargetSpec) and what the file does there: ``q`` the
    configuration at the target's input value closest to the target (None: it does not
    assemble there), ``position`` [m] the target link's frame origin and ``yaw`` [rad] the
    angle of its x axis about z, ``error`` [m] (angle targets: [rad]) and ``angle_error``
    [rad] (poses)."""

    spec: object
    q: np.ndarray | None = field(default=None, repr=False)
    position: tuple | None = None
    yaw: float | None = None
    error: float = math.inf
    angle_error: float = 0.0


@dataclass(frozen=True)
class DesignTargets:
    """Every target of a file with the configuration it is drawn at, and for point targets
    ``curve``: the target link's origin along a whole turn of the input from the drawn
    configuration, or between the limit positions that stop it each way (``stops``), world [m] (N, 3), at
    the input values ``curve_inputs``, the precision inputs on the way included (``on_curve``:
    the curve's index of each target, None where the motion does not get there on this branch)."""

    targets: tuple
    curve: np.ndarray | None = field(default=None, repr=False)
    curve_inputs: np.ndarray | None = field(default=None, repr=False)
    on_curve: tuple = ()
    stops: tuple = ()  # ((input value, reason) or (None, None)) where the motion stopped: back, then forward


def _frame(mech: Mechanism, fid, q: np.ndarray) -> tuple[tuple, float]:
    M = KinematicState(mech, q).frame_placement(fid)
    return tuple(float(v) for v in M.translation), float(math.atan2(M.rotation[1, 0], M.rotation[0, 0]))


def _error(spec: TargetSpec, position, yaw) -> tuple:
    if spec.kind == "angle":
        return abs(wrap_angle(yaw - spec.yaw)), 0.0
    err = math.dist(position, spec.xyz)
    return err, (abs(wrap_angle(yaw - spec.yaw)) if spec.kind == "pose" else 0.0)


def design_targets(mech: Mechanism, q: np.ndarray, steps: int = 360) -> DesignTargets:
    """The targets of ``mech``'s file (mech.spec.targets) reached by its linkage: at each one's
    input value every assembly mode is solved (PositionSolver.solve) and the one nearest the
    target kept, as ``screwkin synthesize`` checks it; with point targets, the curve of their
    link's origin (analysis.course.figures.trace_points, ``steps`` over a turn of the input)."""
    specs = tuple(mech.spec.targets)
    reached = []
    for spec in specs:
        fid = mech.link_frame(spec.link)
        solver = PositionSolver(mech, [spec.input])
        try:
            res = solver.solve({spec.input: spec.value})
        except AssemblyError:
            reached.append(TargetReached(spec))
            continue
        best = None
        for s in res.solutions:
            err, aerr = _error(spec, *_frame(mech, fid, s.q))
            if best is None or err + aerr < best[0]:
                best = (err + aerr, s.q)
        q_k = np.asarray(polished(mech, solver, best[1])[0], float).copy()
        position, yaw = _frame(mech, fid, q_k)
        reached.append(TargetReached(spec, q_k, position, yaw, *_error(spec, position, yaw)))
    points = [s for s in specs if s.kind == "point"]
    if not points:
        return DesignTargets(tuple(reached))
    link, name = points[0].link, points[0].input
    point = Point("target", link, (0.0, 0.0, 0.0))
    res, motion = trace_points(mech, q, name, [point], steps)
    values = np.asarray(res.values, float)
    curve = np.asarray(motion.points["target"]["position"], float)
    Q = list(res.q)
    linear = bool(mech.translational[mech.coordinate(name).idx_v])
    solver = PositionSolver(mech, [name])
    stops = [(res.stopped_at, res.stop_reason)]
    if res.stopped_at is not None:  # the input cannot turn fully: the motion runs back to the other limit too
        start = float(values[0])
        near = {n: v for n, v in mech.joint_values(q).items() if n != name}
        back = sweep(solver, name, start, start - (mech.length if linear else TWO_PI), steps, near=near)
        if len(back.values) > 1:
            along = motion_along(mech, back.q, back.rates, back.accelerations, [point])
            values = np.concatenate([np.asarray(back.values, float)[:0:-1], values])
            curve = np.concatenate([np.asarray(along.points["target"]["position"], float)[:0:-1], curve])
            Q = list(back.q)[:0:-1] + Q
        stops.insert(0, (back.stopped_at, back.stop_reason))
    ends = [float(values.min()), float(values.max())] + [float(x) for x, _ in stops if x is not None]
    lo, hi = min(ends), max(ends)
    fid = mech.link_frame(link)
    extra = []  # (input, point, target index): each precision input met along the traced motion, on its branch
    for k, spec in enumerate(specs):
        if spec.kind != "point" or spec.link != link or spec.input != name:
            continue
        turns = (0,) if linear else range(math.floor((lo - spec.value) / TWO_PI),
                                          math.ceil((hi - spec.value) / TWO_PI) + 1)
        met = [spec.value + TWO_PI * m for m in turns if lo <= spec.value + TWO_PI * m <= hi]
        if not met:
            continue
        u = met[0]
        j = int(np.argmin(np.abs(values - u)))
        try:
            q_u = polished(mech, solver, solver.track({name: u}, Q[j]).q)[0]
        except AssemblyError:
            continue
        extra.append((u, _frame(mech, fid, q_u)[0], k))
    inputs = np.concatenate([values, [u for u, _, _ in extra]])
    xyz = np.concatenate([curve, np.array([p for _, p, _ in extra]).reshape(-1, 3)])
    order = np.argsort(inputs, kind="stable")
    where = {int(np.nonzero(order == len(values) + i)[0][0]): k for i, (_, _, k) in enumerate(extra)}
    on_curve = tuple(next((i for i, k in where.items() if k == t), None) for t in range(len(specs)))
    return DesignTargets(tuple(reached), xyz[order], inputs[order], on_curve, tuple(stops))
