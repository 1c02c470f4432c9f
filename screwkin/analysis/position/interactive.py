"""The state behind an interactive view (``view --interactive``): input values -> configuration,
kept on one assembly mode as the inputs move, with the modes at the current inputs, the
singularity measure, and the output pose and named points to read out.  No browser, no
printing: a GUI (screwkin.present.interactive) calls :meth:`Interactive.move` and
:meth:`Interactive.switch` and shows the :class:`LiveState` they return.

Moving an input is analysis.motion.sweep's continuation from the current configuration to the new
value (the other inputs held), in steps of at most ``MAX_STEP`` (an angle) or ``MAX_STEP``
times the characteristic length (a slide): the assembly mode is kept as a physical mechanism
keeps it, and a limit position met on the way is located and stops the move.  A move that
cannot be completed changes nothing: the state says where and why it stopped.

The named points leave traced paths: each point's position at every continuation step of the
moves carried out (at most ``MAX_PATH`` positions: the oldest are dropped), with the input values
of each step.  Switching the assembly mode jumps: the paths start again there.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, replace

import numpy as np

from ...errors import AssemblyError, UsageError
from ...model.state import KinematicState
from ..motion.links import point_motions
from .modes import choose_mode
from .position import PositionSolver
from ..singular import measures
from ..motion.sweep import sweep
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["Control", "LiveState", "Interactive", "MAX_STEP", "MAX_PATH"]

MAX_STEP = math.radians(2.0)  # largest continuation step [rad]; for a slide, this times the characteristic length
MAX_PATH = 2000  # positions kept in a point's traced path (the oldest dropped first): ten turns of 2 deg steps


@dataclass(frozen=True)
class Control:
    """One input's control: the joint, its unit ("rad" or "m") and range [rad or m] (the file's
    <limit>, else a turn either side of its starting value for an angle, the characteristic
    length either side for a slide)."""

    name: str
    unit: str
    low: float
    high: float
    start: float


@dataclass(frozen=True)
class LiveState:
    """Where the mechanism is.

    q: the configuration; inputs: input name -> value [rad or m] (as moved: not wrapped);
    mode: its index (1-based) among the ``modes`` assembly modes solve finds at these inputs
    (0: none of them matched); sigma: the relative smallest singular value of the actuator and
    constraint measures (analysis.singular.measures), singular when below Tolerances.singular;
    output_pose: 4x4 world pose of the output link (or None); points: name -> world position [m];
    moved: the last request was carried out; message: why not (a limit position, an input the
    loops cannot reach), or None."""

    q: np.ndarray
    inputs: dict
    mode: int
    modes: int
    sigma: float
    singular: bool
    output_pose: np.ndarray | None
    points: dict
    moved: bool = True
    message: str | None = None


class Interactive:
    """Inputs -> configuration for a GUI, one assembly mode followed as the inputs move.

    inputs: the input joints (default: the actuated ones); values: their starting values, all or some
    (default, for each input not given: the file's value when the file's configuration assembles with
    them, else the value in the first configuration the assembly search closes; ``opened`` says which);
    mode: the starting assembly mode (1-based, as solve lists them: analysis.position.modes.choose_mode);
    output: the output link whose pose is read out; points: analysis.motion.links.Point objects read out."""

    def __init__(self, mech: Mechanism, inputs: list[str] | None=None, values: dict | None = None, mode: int = 1, output: str | None = None,
                 points=()) -> None:
        self.mech = mech
        self.solver = PositionSolver(mech, list(inputs) if inputs else None, output=output)
        self.inputs = tuple(self.solver.inputs)
        if not self.inputs:
            raise UsageError(f"{mech.path}: no input to move: declare actuated joints or give --inputs")
        self.output, self.points = output, tuple(points)
        given = {n: float(v) for n, v in (values or {}).items()}
        unknown = [n for n in given if n not in self.inputs]
        if unknown:
            raise UsageError(f"{mech.path}: {', '.join(unknown)}: not an input (inputs: {', '.join(self.inputs)})")
        missing = [n for n in self.inputs if n not in given]
        drawn = mech.joint_values(mech.neutral())  # the file's own values
        self._values = {n: given.get(n, drawn.get(n, 0.0)) for n in self.inputs}
        source = "the file's value" if missing else None
        try:
            q, k, n, res = choose_mode(self.solver, dict(self._values), mode)
        except AssemblyError:
            if not missing:
                raise
            # the file's drawing does not close at its own input values: the first configuration that closes
            assembled = mech.joint_values(mech.assemble().q)
            self._values.update({n: assembled[n] for n in missing})
            source = ("the first assembled configuration's: the file's configuration does not close at its own "
                      "input values")
            q, k, n, res = choose_mode(self.solver, dict(self._values), mode)
        self.notes = res.notes  # (a continuum's sample: said, as choose_mode says it)
        self.opened = "opened at " + ", ".join(
            f"{name} = " + (f"{v * 1000:.6g} mm" if mech.translational[mech.coordinate(name).idx_v]
                            else f"{math.degrees(v):.6g} deg") + ("" if name in given else f" ({source})")
            for name, v in self._values.items())
        self.mode_index = (k, n)
        self.controls = tuple(self._control(name, self._values[name]) for name in self.inputs)
        self._modes = None
        self.state = self._state(q, k)
        self._trace = deque(maxlen=MAX_PATH)  # (inputs, {point: position}) per step
        self._record(self.state.inputs, self.state.points)

    # ------------------------------------------------------------------ traced paths
    def _record(self, inputs: dict, points: dict) -> None:
        if self.points:
            self._trace.append((dict(inputs), {n: np.array(p, float) for n, p in points.items()}))

    def path(self, name: str) -> np.ndarray:
        """(k, 3) world positions [m] of point ``name`` along the moves since the start or the last
        mode switch, oldest first (at most MAX_PATH)."""
        if name not in {p.name for p in self.points}:
            known = ", ".join(p.name for p in self.points) or "none"
            raise UsageError(f"{self.mech.path}: no point named '{name}' is traced (points: {known})")
        return np.array([pts[name] for _, pts in self._trace], float).reshape(-1, 3)

    def path_inputs(self) -> list:
        """The input values (name -> value [rad or m]) at each position of :meth:`path`."""
        return [dict(inputs) for inputs, _ in self._trace]

    def _positions(self, q: np.ndarray) -> dict:
        return {n: np.asarray(p["position"], float)
                for n, p in point_motions(KinematicState(self.mech, q), self.points).items()}

    # ------------------------------------------------------------------ controls
    def _control(self, name: str, start: float) -> Control:
        mech = self.mech
        c = mech.coordinate(name)
        linear = bool(mech.translational[c.idx_v])
        lo = hi = None
        if c.nq == 1:
            lo, hi = float(mech.model.lowerPositionLimit[c.idx_q]), float(mech.model.upperPositionLimit[c.idx_q])
        span = mech.length if linear else math.pi
        if lo is None or not (np.isfinite(lo) and np.isfinite(hi)) or hi - lo <= 0 or (not linear and hi - lo > 2 * math.pi):
            lo, hi = start - span, start + span  # no usable <limit>: a turn (or a characteristic length) around
        return Control(name, "m" if linear else "rad", lo, hi, float(start))

    def control(self, name: str) -> Control:
        found = next((c for c in self.controls if c.name == name), None)
        if found is None:
            raise UsageError(f"{self.mech.path}: '{name}' is not an input ({', '.join(self.inputs)})")
        return found

    # ------------------------------------------------------------------ modes
    def modes(self) -> list:
        """The assembly modes' configurations at the current inputs (solve's order), cached until they move."""
        if self._modes is None:
            self._modes = [s.q for s in self.solver.solve(dict(self._values)).solutions]
        return self._modes

    def _mode_of(self, q: np.ndarray, modes) -> int:
        """The index (1-based) of the mode whose joint centres and cut-joint frames are where q's are
        (PositionSolver's signature: idle spins aside); 0 when none is."""
        c = self.solver.signature(q)
        d = [float(np.linalg.norm(self.solver.signature(m) - c)) for m in modes]
        k = int(np.argmin(d)) if d else -1
        return k + 1 if k >= 0 and d[k] <= self.mech.tolerances.geometry * self.mech.length * math.sqrt(max(len(c), 1)) else 0

    # ------------------------------------------------------------------ state
    def _state(self, q: np.ndarray, mode: int | None=None) -> LiveState:
        mech = self.mech
        modes = self.modes()
        g = self.solver.generic()
        m = measures(mech, q, g)
        sigma = float(min(m["actuator"], m["constraint"])) if g.rank_K or g.rank_Kp else 1.0
        pose = None
        if self.output is not None:
            pose = KinematicState(mech, q).link_pose(self.output)
        points = self._positions(q) if self.points else {}
        return LiveState(np.array(q, float), dict(self._values), self._mode_of(q, modes) if mode is None else mode,
                         len(modes), sigma, sigma < mech.tolerances.singular, pose, points)

    def _refused(self, message: str) -> LiveState:
        self.state = replace(self.state, moved=False, message=message)
        return self.state

    def move(self, name: str, value: float) -> LiveState:
        """Move input ``name`` to ``value`` [rad or m] by continuation from the current
        configuration (the other inputs held): the new state, or the unchanged one with a
        message when a limit position (or an unreachable input) stops the motion on the way."""
        ctl = self.control(name)
        value = float(value)
        start = self._values[name]
        if value == start:
            return self.state
        if not ctl.low <= value <= ctl.high:
            return self._refused(f"{name}: {value:.6g} {ctl.unit} is outside its control's range "
                                 f"[{ctl.low:.6g}, {ctl.high:.6g}] {ctl.unit}; nothing moved")
        step = MAX_STEP * (self.mech.length if ctl.unit == "m" else 1.0)
        steps = max(1, math.ceil(abs(value - start) / step))
        fixed = {n: v for n, v in self._values.items() if n != name}
        try:  # continued from the current configuration: its assembly mode is kept
            res = sweep(self.solver, name, start, value, steps, fixed=fixed, q_start=self.state.q)
            if self.state.singular and res.stopped_at is not None and res.values.size <= 1:
                # at a limit position itself (a double root, where no tangent leads off): from the mode a
                # millionth of the way along, nearest this one
                nudge = start + 1e-6 * (value - start)
                near = min((s.q for s in self.solver.solve({**fixed, name: nudge}).solutions),
                           key=lambda q: float(np.linalg.norm(self.solver.signature(q) - self.solver.signature(self.state.q))))
                res = sweep(self.solver, name, nudge, value, steps, fixed=fixed, q_start=near)
        except AssemblyError as exc:
            return self._refused(f"{name} cannot move from here: {exc}")
        if res.stopped_at is not None or res.skipped:
            where = res.stopped_at if res.stopped_at is not None else res.skipped[0]
            shown = f"{math.degrees(where):.6g} deg" if ctl.unit == "rad" else f"{where * 1000:.6g} mm"
            why = res.stop_reason or "the loops cannot be closed there"
            return self._refused(f"{name} stopped at {shown}: {why}; nothing moved")
        for x, qk in zip(res.values[1:-1], res.q[1:-1]):  # the steps on the way, then the end's state
            if self.points:
                self._record({**fixed, name: float(x)}, self._positions(qk))
        self._values[name] = value
        self._modes = None
        self.state = self._state(res.q[-1])
        self._record(self.state.inputs, self.state.points)
        return self.state

    def switch(self, mode: int) -> LiveState:
        """Go to the assembly mode ``mode`` (1-based) of the current inputs."""
        modes = self.modes()
        if not 1 <= mode <= len(modes):
            return self._refused(f"mode {mode}: these inputs give {len(modes)} assembly mode"
                                 f"{'s' if len(modes) != 1 else ''}")
        self.state = self._state(modes[mode - 1], mode)
        self._trace.clear()  # a jump to another mode: the paths start again here
        self._record(self.state.inputs, self.state.points)
        return self.state
