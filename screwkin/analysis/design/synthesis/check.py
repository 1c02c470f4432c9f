"""Checking a written design with screwkin's own analyses: checked, not trusted.

The file is loaded as any mechanism file is (screwkin.model.loader.load), then:

1. the assembly search must close it at its own configuration without a Newton step
   (the file is drawn closed at the first precision position);
2. at each precision position the input is set and the loops solved
   (PositionSolver.solve, every assembly mode); the mode closest to the target is
   polished to a closure residual below 1e-13 (analysis.design.targets.polished) and compared with the target (the guided
   frame's pose, the coupler point, or the output link's angle) and with the closed-form
   four-bar (screwkin.analysis.design.synthesis.fourbar) at that input;
3. the Grashof class comes from screwkin.analysis.motion.planar.identify;
4. the motion is followed with screwkin.analysis.motion.sweep.sweep from the first position, each
   way, a full turn of the crank or until a limit position stops it (or over the input
   range ``design.span``): each precision position is looked for at its input value on the
   branch being followed (solver.track from the nearest step).  Defects:
   - branch (circuit): the crank passes the position's input value with the linkage in
     another assembly mode;
   - limit: a limit position stops the crank before it gets there;
   - order: every position is reached, but not in the order given;
5. the transmission angle is measured at every step of the motion from the first position
   to the farthest one reached.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ....errors import AssemblyError, ScrewkinError
from ....model.geometry import wrap_angle
from ....model.loader import load
from ....model.state import KinematicState
from ...mobility import analyze_mobility
from ...motion.planar import identify, transmission_angles
from ...position.position import PositionSolver
from ...motion.sweep import sweep
from ...course.skeleton import numbering
from ..targets import polished
from .designs import Check, ChainFile, Design, PrecisionCheck
from .fourbar import positions
if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.design.synthesis.designs import Target
    from pathlib import Path

if TYPE_CHECKING:
    from ...motion.sweep import SweepResult

__all__ = ["check_design", "check_chain_file", "TOLERANCE"]

#: Precision positions must be reached to this [m, rad] (times the mechanism's size when above 1 m).
TOLERANCE = 1e-9
TWO_PI = 2 * math.pi


class _Probe:
    """What the check reads off a configuration of the written four-bar."""

    def __init__(self, mech: Mechanism, design: Design) -> None:
        self.mech = mech
        self.design = design
        self.out = mech.link_frame(design.output_link)
        jid = {mech.model.names[k]: k for k in range(1, mech.model.njoints)}
        self.jA = jid.get("coupler_joint")
        self.fB = mech.cuts[0].frame1 if mech.cuts else None
        self.linkage = None  # analysis.motion.planar.identify's LinkageInfo, set at the first position

    def value(self, q: np.ndarray) -> tuple:
        M = KinematicState(self.mech, q).frame_placement(self.out)
        kind = self.design.targets[0].kind
        if kind == "pose":
            return (float(M.translation[0]), float(M.translation[1]), float(math.atan2(M.rotation[1, 0], M.rotation[0, 0])))
        if kind == "point":
            return (float(M.translation[0]), float(M.translation[1]))
        return (float(math.atan2(M.rotation[1, 0], M.rotation[0, 0])),)

    def error(self, q: np.ndarray, target: Target) -> tuple:
        v = self.value(q)
        t = target.value
        if target.kind == "pose":
            return math.hypot(v[0] - t[0], v[1] - t[1]), abs(float(wrap_angle(v[2] - t[2], upper=True)))
        if target.kind == "point":
            return math.hypot(v[0] - t[0], v[1] - t[1]), 0.0
        return abs(float(wrap_angle(v[0] - t[0], upper=True))), 0.0

    def mus(self, Q: np.ndarray | list) -> list:
        """Transmission angles [rad] at the configurations Q (analysis.motion.planar.transmission_angles
        of the file's four-bar as identified at the first position); none when it was not
        identified (the check then says the angle was not measured)."""
        if self.linkage is None or not len(Q):
            return []
        return transmission_angles(self.mech, self.linkage, Q).tolist()

    def pins(self, q: np.ndarray) -> tuple:
        state = KinematicState(self.mech, q)
        return state.centre(("joint", self.jA))[:2], state.centre(("frame", self.fB))[:2]


def _closed_form_error(design: Design, probe: _Probe, q: np.ndarray, target: Target) -> float:
    """Distance between the file's moving pivots (and guided frame) at q and the closed-form
    four-bar at the same crank angle, on the branch that is nearer."""
    fb = design.fourbar
    A, B = probe.pins(q)
    theta = math.atan2(A[1] - fb.A0[1], A[0] - fb.A0[0])
    best = np.inf
    for sigma in (1.0, -1.0):
        p = positions(fb, theta, sigma)
        err = max(float(np.hypot(*(p["A"] - A))), float(np.hypot(*(p["B"] - B))))
        v = probe.value(q)
        if target.kind in ("pose", "point") and fb.tool is not None:
            err = max(err, math.hypot(float(p["x"]) - v[0], float(p["y"]) - v[1]))
        best = min(best, err)
    return float(best)


def check_design(design: Design, path: str, tolerance: float | None = None, steps: int = 360, warn=None) -> Check:
    """Check the four-bar ``design`` written at ``path`` (see the module docstring)."""
    mech = load(path, warn=warn or (lambda _m: None))
    tol = tolerance if tolerance is not None else TOLERANCE * max(1.0, mech.length)
    defects = []
    try:
        assembled = mech.assemble()
        iterations = assembled.iterations
    except ScrewkinError as exc:
        iterations = -1
        defects.append(f"the file does not assemble: {exc}")
    if iterations > 0:
        defects.append(f"the file is not drawn closed: {iterations} Newton iterations closed it")
    name = design.input_joint
    solver = PositionSolver(mech, [name], output=design.output_link)
    probe = _Probe(mech, design)
    precision, configs, q_first = [], [], None
    for k, target in enumerate(design.targets):
        try:
            res = solver.solve({name: target.input})
        except AssemblyError as exc:
            precision.append(PrecisionCheck(target, False, (), math.inf, 0.0, exc.residual, math.inf))
            configs.append(None)
            defects.append(f"{target.label or f'position {k + 1}'}: the file cannot be assembled at "
                           f"{name} = {math.degrees(target.input):.6g} deg")
            continue
        best = min(res.solutions, key=lambda s: sum(probe.error(s.q, target)))
        q, residual = polished(mech, solver, best.q)
        residual = best.residual if residual is None else residual
        if k == 0:
            q_first = q
        configs.append(q)
        err, aerr = probe.error(q, target)
        reached = err <= tol and aerr <= tol
        precision.append(PrecisionCheck(target, bool(reached), probe.value(q), err, aerr, float(residual),
                                        _closed_form_error(design, probe, q, target)))
    for k, p in enumerate(precision):
        if not p.reached and math.isfinite(p.error) and design.exact:
            label = p.target.label or f"position {k + 1}"
            what = f"{math.degrees(p.error):.3g} deg" if p.target.kind == "angle" else f"{p.error:.3g} m"
            if p.target.kind == "pose" and p.angle_error > tol:
                what += f" and {math.degrees(p.angle_error):.3g} deg"
            defects.append(f"{label} is missed by {what} (tolerance {tol:.3g})")
    grashof, lengths = None, {}
    if q_first is not None:
        info = identify(mech, mech.topology(q_first), q_first, name)
        probe.linkage = info
        if info is not None:
            grashof, lengths = info.grashof, dict(info.lengths)
    direction, travel, mus = 0, (), []
    if q_first is not None and len(design.targets) > 1:
        direction, travel, mus, found = _follow(design, solver, probe, configs, steps)
        defects += found
    mu_range = (min(mus), max(mus)) if mus else None
    # the letters `draw` gives the joints (its skeleton numbering from the input): the text names them so
    letters = numbering(mech.topology(q_first), [name])[1] if q_first is not None else {}
    return Check(str(path), iterations, tuple(precision), grashof, lengths, mu_range, tuple(defects), direction,
                 tuple(travel), tol, letters)


def _locate(design: Design, solver: PositionSolver, probe: _Probe, res: SweepResult, x: float, q_target: np.ndarray) -> bool:
    """Whether the branch followed by sweep ``res`` is, at input value x, in the configuration
    q_target (the solution found for that precision position): same moving pivots."""
    if q_target is None:
        return False
    values = res.values
    j = int(np.argmin(np.abs(values - x)))
    try:
        q = solver.track({design.input_joint: x}, res.q[j]).q
    except AssemblyError:
        return False
    A, B = probe.pins(q)
    A_t, B_t = probe.pins(q_target)
    size = max(design.fourbar.lengths.values())
    return max(float(np.hypot(*(A - A_t))), float(np.hypot(*(B - B_t)))) < probe.mech.tolerances.geometry * size


class _Follower:
    """The motion of a design's crank from its first precision position, followed by sweep, and where the
    other positions lie along it."""

    def __init__(self, design: Design, solver: PositionSolver, probe: _Probe, configs: list, steps: int) -> None:
        self.design, self.solver, self.probe, self.configs, self.steps = design, solver, probe, configs, steps
        self.name = design.input_joint
        self.tol = probe.mech.tolerances
        self.targets = design.targets
        self.n = len(self.targets)
        self.label = [t.label or f"position {k + 1}" for k, t in enumerate(self.targets)]
        self.u1 = self.targets[0].input

    def follow(self, direction: int, reach: float) -> tuple[SweepResult, float]:
        """The sweep from the first position ``reach`` [rad] one way round, and how far it got."""
        u1 = self.u1
        count = max(int(round(self.steps * reach / TWO_PI)), 4)
        res = sweep(self.solver, self.name, u1, u1 + direction * reach, count, near={self.name: u1})
        covered = float(np.max(direction * (res.values - u1))) if len(res.values) else 0.0
        if res.stopped_at is not None:  # up to the located limit position, not only the last grid value before it
            covered = max(covered, float(direction * (res.stopped_at - u1)))
        return res, covered

    def typed(self, x: float) -> str:
        """Function generation: the crank's angle as typed beside the file's."""
        offset = self.design.input_offset
        return "" if offset is None else f" (phi {math.degrees(x + offset):.6g} deg as typed)"

    def locate(self, res: SweepResult, x: float, k: int) -> bool:
        return _locate(self.design, self.solver, self.probe, res, x, self.configs[k])

    def over_span(self) -> tuple[int, list, list[float], list[str]]:
        """The motion over the design's input range, both ways from the first position."""
        design, tol, targets, name, u1, label = self.design, self.tol, self.targets, self.name, self.u1, self.label
        defects, travel, mus = [], [0.0] + [None] * (self.n - 1), []
        runs = {}
        for direction, reach in ((1, design.span[1] - u1), (-1, u1 - design.span[0])):
            if reach <= tol.zero:
                continue
            res, covered = self.follow(direction, reach)
            runs[direction] = (res, covered)
            mus += self.probe.mus(res.q)  # the sweep's grid ends at the range's ends
            if res.stopped_at is not None and covered < reach - tol.equal:
                defects.append(f"the input range is cut short by a limit position at {name} = "
                               f"{math.degrees(res.stopped_at):.6g} deg{self.typed(res.stopped_at)}: the linkage "
                               "cannot run through it")
        for k in range(1, self.n):
            d = targets[k].input - u1
            direction = 1 if d >= 0 else -1
            res, covered = runs.get(direction, (None, 0.0))
            if res is None or abs(d) > covered + tol.equal:
                defects.append(f"{label[k]} lies beyond a limit position: the input stops before "
                               f"{math.degrees(targets[k].input):.6g} deg{self.typed(targets[k].input)}")
            elif self.locate(res, targets[k].input, k):
                travel[k] = abs(d)
            else:
                defects.append(f"branch (circuit) defect: {label[k]} is on another assembly mode than "
                               f"{label[0]}")
        return 0, travel, mus, defects

    def one_way(self, direction: int) -> tuple[tuple[int, bool], int, list, list, list[float]]:
        """Turning the crank one way round: ((positions missed, out of order), direction, each position's
        status, travel to each, the transmission angles along)."""
        tol, targets, u1, configs = self.tol, self.targets, self.u1, self.configs
        # as far as the farthest position this way round (a full turn when one sits at the start's input)
        travels = [float(np.mod(direction * (t.input - u1), TWO_PI)) for t in targets[1:]]
        reach = min(max(max(travels) + 0.05, 0.5), TWO_PI) if min(travels) > tol.equal else TWO_PI
        res, covered = self.follow(direction, reach)
        status, travel = [], [0.0]
        for k in range(1, self.n):
            d = float(np.mod(direction * (targets[k].input - u1), TWO_PI))
            if d > covered + tol.equal:
                status.append(("limit", res.stopped_at))
                travel.append(None)
            elif self.locate(res, u1 + direction * d, k):
                status.append(("reached", d))
                travel.append(d)
            elif d < tol.equal and covered >= TWO_PI - tol.equal and self.locate(res, u1 + direction * TWO_PI, k):
                status.append(("reached", TWO_PI))
                travel.append(TWO_PI)
            else:
                status.append(("branch", None))
                travel.append(None)
        got = [t for t in travel if t is not None]
        ordered = all(a < b for a, b in zip(got, got[1:]))
        far = max(got)
        mus = self.probe.mus([q for q, x in zip(res.q, res.values) if direction * (x - u1) <= far + tol.zero])
        mus += self.probe.mus([configs[k] for k, t in enumerate(travel) if t is not None])  # the ends exactly
        missing = sum(t is None for t in travel)
        return (missing, not ordered), direction, status, travel, mus

    def missing_defects(self, outcomes: list, status: list) -> list[str]:
        """Why positions are missed: another branch, beyond a limit position, or reached only the other way."""
        label, targets, u1 = self.label, self.targets, self.u1
        defects = []
        for k in range(1, self.n):
            seen = [o[2][k - 1] for o in outcomes]
            if any(s[0] == "reached" for s in seen):  # reached the other way round: the order is the defect
                continue
            kinds = {s[0] for s in seen}
            if "branch" in kinds:
                defects.append(f"branch (circuit) defect: the crank passes {label[k]}'s input "
                               f"({math.degrees(targets[k].input):+.6g} deg from {label[0]}) with the linkage in "
                               f"another assembly mode: {label[k]} is on another branch than {label[0]}")
            if "limit" in kinds:
                stops = sorted({s[1] - u1 for s in seen if s[0] == "limit" and s[1] is not None})
                where = (" (the crank stops " + ", ".join(
                    f"{math.degrees(abs(x)):.6g} deg {'counterclockwise' if x > 0 else 'clockwise'}" for x in stops)
                         + f" from {label[0]})") if stops else ""
                defects.append(f"{label[k]} lies beyond a limit position{where}: the crank cannot turn from "
                               f"{label[0]} to it")
        if any(any(s[0] == "reached" for s in [o[2][k - 1] for o in outcomes]) and status[k - 1][0] != "reached"
               for k in range(1, self.n)):
            defects.append("order defect: the positions are reached only by turning the crank both ways")
        return defects


def _follow(design: Design, solver: PositionSolver, probe: _Probe, configs: list,
            steps: int) -> tuple[int, list, list[float], list[str]]:
    """(direction, travel per position, transmission angles along the motion, defects)."""
    f = _Follower(design, solver, probe, configs, steps)
    if design.span is not None:  # the motion is the input range: both ways from the first position
        return f.over_span()
    outcomes = []
    for direction in (1, -1):
        outcome = f.one_way(direction)
        outcomes.append(outcome)
        if not any(outcome[0]):  # every position, in order: the other way round is not needed
            break
    outcomes.sort(key=lambda o: o[0])
    (missing, disordered), direction, status, travel, mus = outcomes[0]
    defects = f.missing_defects(outcomes, status) if missing else []
    if disordered:
        got = sorted((t, k) for k, t in enumerate(travel) if t is not None)
        defects.append("order defect: turning the crank " + ("counterclockwise" if direction > 0 else "clockwise")
                       + " from " + f.label[0] + " reaches the positions in the order "
                       + ", ".join(str(k + 1) for _, k in got))
    return direction, travel, mus, defects


def check_chain_file(path: str | Path, chain: int, ground: int, dof: int) -> ChainFile:
    """A written chain: it must load, be drawn closed, and have screwkin's mobility ``dof``."""
    try:
        mech = load(path, warn=lambda _m: None)
        iterations = mech.assemble().iterations
        m = analyze_mobility(mech).mobility
    except ScrewkinError as exc:
        return ChainFile(chain, ground, str(path), -1, None, str(exc))
    problem = ""
    if iterations:
        problem = f"not drawn closed ({iterations} Newton iterations)"
    elif m != dof:
        problem = f"screwkin finds mobility {m}, not {dof}"
    return ChainFile(chain, ground, str(path), iterations, m, problem)
