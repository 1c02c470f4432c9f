"""The motions a textbook figure is drawn along: the output link a textbook names when none is given,
the input's range, one skeleton per singular configuration met along the input (located by the
sweep), and the paths named points trace over a turn of the input.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import UsageError
from ..motion.link_inputs import holding_angles
from ..motion.links import motion_along
from ..position.position import PositionSolver
from ..motion.change_points import change_points
from ..motion.singular_points import locate_singularities
from ..motion.sweep import SweepSingularity, sweep
from .skeleton import numbering
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["SingularConfiguration", "SingularSearch", "default_output", "input_range", "singular_configurations",
           "trace_points"]


@dataclass(frozen=True)
class SingularConfiguration:
    """A singular configuration met along the input's range (screwkin.analysis.motion.sweep's
    SweepSingularity): kind "actuator" (limit position: ``limit``), "serial" (of ``output``) or
    "constraint"; ``input`` its value [rad or m]; ``q`` the configuration."""

    kind: str
    input: float
    sigma: float
    q: np.ndarray
    limit: bool
    output: str | None
    point: object = None  # analysis.motion.crossing.ChangePoint of a constraint singularity: what it is


@dataclass(frozen=True)
class SingularSearch:
    input: str
    unit: str  # "rad" | "m"
    start: float
    stop: float
    output: str | None
    fixed: dict  # the other inputs' values
    found: tuple  # SingularConfiguration, by input value
    turned: bool  # the sweep passed limit positions onto the other branch
    circuit_closed: bool
    motion: object = None  # the SweepResult followed (joint values, rates, accelerations along the range)


def default_output(mech: Mechanism, input_joint, q: np.ndarray | None = None):
    """The link a textbook calls the output when none is given: the link of the last joint to
    the ground (in lettering order) that does not carry the input joint's link -- a four-bar's
    rocker, a slider-crank's slider; None when there is none (a serial arm: its last link)."""
    topo = mech.topology(q)
    number, _, ordered = numbering(topo, [input_joint])
    input_links = {lk for j in topo.joints if input_joint in j.members for lk in j.links}
    cands = [j for j in ordered if topo.ground in j.links and input_joint not in j.members]
    for j in reversed(cands):
        other = j.links[1] if j.links[0] == topo.ground else j.links[0]
        if other not in input_links:
            return other
    if not topo.loops:
        far = max(number, key=number.get)
        return None if far == topo.ground else far
    return None


def input_range(mech: Mechanism, name: str, q: np.ndarray) -> tuple:
    """(start, stop) of an input's range, from its value at q: a full turn for a revolute joint
    whose limits span a turn or more (or have none), else its limits; a sliding joint's limits
    when finite and within 100 L, else 2 L either side."""
    c = mech.coordinate(name)
    short = mech.model.joints[c.joint_id].shortname()
    value = mech.joint_values(q)[name]
    if c.nq == 2:  # continuous
        return value, value + 2 * np.pi
    lo, hi = float(mech.model.lowerPositionLimit[c.idx_q]), float(mech.model.upperPositionLimit[c.idx_q])
    x = float(q[c.idx_q])
    if short.startswith("JointModelR"):
        if not (np.isfinite(lo) and np.isfinite(hi)) or hi - lo >= 2 * np.pi - mech.tolerances.equal:
            return x, x + 2 * np.pi
        return lo, hi
    L = mech.length
    if np.isfinite(lo) and np.isfinite(hi) and 0 < hi - lo <= 100 * L:
        return lo, hi
    return x - 2 * L, x + 2 * L


def singular_configurations(mech: Mechanism, input_joint=None, output=None, fixed: dict | None = None, q: np.ndarray | None = None, steps: int = 360,
                            near=None, rate: float = 1.0, held=None) -> SingularSearch:
    """The singular configurations along ``input_joint``'s range (:func:`input_range` from q,
    the assembled configuration by default): one assembly mode followed by
    screwkin.analysis.motion.sweep.sweep through limit positions (``turn``) and located by
    analysis.motion.singular_points.locate_singularities (the
    limit positions, and the serial singularities of ``output`` -- by default
    :func:`default_output`: a four-bar's rocker, whose limit positions are the crank and
    coupler collinear -- and the constraint ones).  ``fixed``: the other inputs' values
    (default: their values at q); ``rate``: the input's constant rate [rad/s or m/s] the motion's rates
    and accelerations are for; ``held``: links of a planar mechanism held at absolute angles [rad] along
    the motion (analysis.motion.link_inputs.holding_angles), the inputs then the joints of ``fixed``."""
    inputs = list(mech.actuated)
    if input_joint is None:
        if not inputs:
            raise UsageError(f"{mech.path}: no input joint: declare actuated joints or give --input NAME")
        input_joint = inputs[0]
    mech.coordinate(input_joint)  # a usage error when unknown
    if input_joint not in inputs:
        inputs = [input_joint]
    if held:  # the other inputs are the joints given; the held links are no joints
        inputs = [input_joint, *(k for k in (fixed or {}) if k != input_joint)]
    if q is None:
        q = mech.generic_configurations()[0].q
    values = mech.joint_values(q)
    fixed = {k: (fixed or {}).get(k, values[k]) for k in inputs if k != input_joint}
    if output is None:
        output = default_output(mech, input_joint, q)
    else:
        mech.link_frame(output)
    solver = PositionSolver(holding_angles(mech, inputs, held) if held else mech, inputs, output=output)
    start, stop = input_range(mech, input_joint, q)
    if near is None:
        near = values
    res = sweep(solver, input_joint, start, stop, steps, fixed=fixed, near=near, turn=True, rate=rate)
    found = locate_singularities(solver, res, output=output)
    points = change_points(solver, res, found)  # change points and shaky points too, each analysed
    found = found + [SweepSingularity("constraint", p.input, p.sigma, p.q, point=p) for p in points if p.located]
    found.sort(key=lambda s: s.input)
    out = tuple(SingularConfiguration(s.kind, s.input, s.sigma, s.q, s.limit, output if s.kind == "serial" else None,
                                      s.point) for s in found)
    return SingularSearch(input_joint, res.unit, float(start), float(stop), output, fixed, out, bool(res.limits),
                          res.circuit_closed, res)


def trace_points(mech: Mechanism, q: np.ndarray, input_name: str, points: list, steps: int = 360, fixed: dict | None = None) -> tuple:
    """The paths of ``points`` while ``input_name`` turns a whole turn (or, for a slider or an input
    that cannot turn, runs to its limit position) from its value at ``q``, on the assembly mode of
    ``q``: (SweepResult, MotionAlong).  The sweep is analysis.motion.sweep's, so its limits are reported."""
    fixed = dict(fixed or {})
    solver = PositionSolver(mech, [input_name, *[n for n in fixed if n != input_name]])
    start = mech.joint_values(q)[input_name]
    c = mech.coordinate(input_name)
    stop = start + (2 * np.pi if not mech.translational[c.idx_v] else mech.length)
    near = {n: v for n, v in mech.joint_values(q).items() if n != input_name and n not in fixed}
    res = sweep(solver, input_name, start, stop, steps, fixed=fixed, near=near)
    return res, motion_along(mech, res.q, res.rates, res.accelerations, points)
