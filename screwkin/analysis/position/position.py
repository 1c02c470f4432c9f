"""Position, velocity and acceleration analysis of closed-loop mechanisms.

Given values of input joints (by default the actuated ones; any joints may be
chosen instead), the other coordinates follow from the loop-closure equations
r(q) = 0, solved by damped Newton with the inputs held, from the inputs
themselves: the file's configuration with the inputs set, and random
configurations within the joint limits with the inputs set (the file's own
configuration need not close).  Every assembly mode the solver reaches is
reported once:

- two solutions are the same mode when every joint centre and the output frame
  are in the same place (idle spins, which move no joint, do not make new modes);
- a double root (a limit position) is one solution flagged singular, however
  the starts approached it; solutions joined by a motion with the inputs held (a
  continuum: the inputs do not determine the mechanism there) are one solution
  flagged singular and ``continuum``;
- modes that cannot be reached by moving the mechanism from the reference
  configuration without passing a singularity are labelled: outside the joint
  limits, a leg reversed through its pivot, a link that only translates found
  turned (a mirrored parallelogram).  Solutions without a label come first.

Rates and accelerations come from the differentiated closure equations
    K q' = 0,        K q'' + K' q' = 0,
split into input and passive columns, with K' q' from Pinocchio's classical
frame accelerations.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pinocchio as pin

from ...errors import AssemblyError, UsageError
from ...model.kernel import newton
from ...model.cuts import Assembly
from ...model.geometry import wrap_angle
from ...model.linalg import complement
from ...model.manifold import set_continuous_angle
from ...model.state import KinematicState, angular_loop_joints, frame_parent
from ...model.limits import outside_limits, spelled_within_limits
from ...model.topology import open_joints
from ...model.kernel.algebraic import algebraic_obstacle
from . import certified, given, modes
from ..motion.dyads import cached_plan
from ..mobility import analyze_mobility
from ..motion.links import link_motions, point_motions
from .turns import engaged, turn_on, whole_turns
from ..motion.planar import LinkAngles, identify
from .solution import NEWTON_FROM_FILE, PositionResult, Solution, TraceStep, search_method
from ..singular import Generic, measures
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.model.kernel.closure import ClosureSystem
    from screwkin.analysis.mobility import MobilityResult

__all__ = ["PositionSolver"]



class PositionSolver:
    """Solves a mechanism for given input joints; reuses the model and data
    between calls (build once, solve many times)."""

    def __init__(self, mech: Mechanism, input_joints: list[str] | None=None, output: str | None=None, compiled: bool | None = None) -> None:
        """compiled: True to solve the closure equations with the compiled kernels of
        screwkin.model.kernel.compiled (numba, ``pip install -e '.[fast]'``) when the mechanism's cut
        joints are all fixed or spherical, False for numpy, None to leave the mechanism's
        setting; ``self.compiled`` says which is used."""
        self.mech = mech
        if compiled is not None:
            mech.closure.accelerate(compiled)
        self.model = mech.model
        self.data = mech.scratch_data()
        held = mech.closure.row_inputs  # links whose angle the closure holds (analysis.motion.link_inputs)
        names = list(input_joints) if input_joints or (held and input_joints is not None) else list(mech.actuated)
        if not names and not held:
            raise UsageError(f"{mech.path}: no input joints: declare actuated joints or give --set NAME=VALUE")
        for n in names:
            c = mech.coordinate(n)
            if c.nv != 1:
                raise UsageError(f"{mech.path}: joint '{n}' has {c.nv} coordinates; inputs must be 1-DOF joints")
        if len(set(names)) != len(names):
            raise UsageError(f"{mech.path}: an input joint is named twice: {', '.join(names)}")
        self.inputs = names
        # joints no loop passes through and no input names: nothing decides them but a value
        loose = [mech.coordinate(j) for j in open_joints(mech) if j not in names]
        self.unset = tuple(c.joint for c in loose if c.nv == 1)  # solve refuses them unset (unset_error)
        # a multi-coordinate one (a floating base, a ball joint in the tree) keeps the file's value
        self.kept = tuple(c.joint for c in loose if c.nv > 1)
        self._kept_q = np.concatenate([np.arange(c.idx_q, c.idx_q + c.nq) for c in loose if c.nv > 1]).astype(int) \
            if self.kept else np.zeros(0, int)
        self.frozen = mech.velocity_indices(names)
        self.passive = complement(mech.nv, self.frozen)
        self.output = output
        self.output_frame = mech.link_frame(output) if output else None
        # (joint, placement in it) of the output frame: a tool or named point is no frame of the model
        self._output_at = frame_parent(mech, self.output_frame) if output else None
        self._generic = None
        self._labelling = None
        self._angles = False  # LinkAngles, None when not planar, False before the first look
        self._points = [f for f in range(len(self.model.frames))
                        if self.model.frames[f].type == pin.FrameType.JOINT]
        self._points += [c.frame1 for c in mech.cuts]
        self._angular = self.angular_names()

    @property
    def compiled(self) -> bool:
        """Whether the closure equations are solved by the compiled kernels."""
        return self.mech.closure.accelerated

    # --------------------------------------------------------------- generic data
    def generic(self, hint: np.ndarray | None=None, starts: int | None = None) -> Generic:
        """Generic ranks for these inputs and output (screwkin.analysis.singular.Generic) over the
        mechanism's generic configurations; ``hint``: an assembled configuration to start
        from when the mechanism's own assembly search has not been made (``starts``: its random
        starts, Mechanism.generic_configurations)."""
        if self._generic is None:
            # the hint only starts a search not made yet (the mechanism's own result is reused when it exists)
            known = self.mech.generic_known
            configs = self.mech.generic_configurations(hint=None if known else hint,
                                                       starts=None if known else starts)[1]
            self._generic = Generic(self.mech, self.inputs, self.output, configurations=configs)
        return self._generic

    def reference(self):
        """The reference configuration (the mechanism's assembled one), or None when the
        assembly search finds none (the solutions for the inputs then stand in)."""
        try:
            return self.generic().configurations[0]
        except AssemblyError:
            return None

    @property
    def idle_dofs(self) -> int:
        return self._mobility().idle_dofs

    @property
    def mobility(self) -> int:
        return self._mobility().mobility

    @property
    def free_dofs(self) -> int:
        """DOFs left free with the inputs held, beyond the idle ones (0 = the inputs determine
        the mechanism)."""
        g = self.generic()
        kept = sum(self.mech.coordinate(j).nv for j in self.kept)  # held at the file's values, not free
        free = len(self.passive) - g.rank_Kp - kept
        return max(free - self.idle_dofs, 0) if free > 0 else 0  # (idle DOFs, a mobility analysis: only if any is left)

    def _mobility(self) -> MobilityResult:
        self.generic()  # the assembly the mobility analysis starts from
        return analyze_mobility(self.mech)

    # --------------------------------------------------------------- coordinates
    def angular_names(self) -> tuple:
        """Coordinate names that are angles (revolute and continuous joints)."""
        names = []
        for c in self.mech.coordinates:
            if self.model.joints[c.joint_id].shortname().startswith("JointModelR") and c.nv == 1:
                names.append(c.joint)
        return tuple(names)

    def _angular_coupled(self) -> tuple:
        return tuple(c.joint for c in self.mech.couplings if self.mech._revolute_like(c.joint))

    def set_inputs(self, q: np.ndarray, values: dict):
        """q with the named coordinates set: joint names of 1-DOF joints [rad or m], and the
        'joint[qk]' names that joint_values gives to the coordinates of multi-DOF joints."""
        q = np.array(q, float)
        multi = False
        for name, v in values.items():
            if name.endswith("]") and "[q" in name:
                joint, k = name[:-1].rsplit("[q", 1)
                c = self.mech.coordinate(joint)
                if not k.isdigit() or int(k) >= c.nq:
                    raise UsageError(f"{self.mech.path}: joint '{joint}' has no coordinate q{k}")
                q[c.idx_q + int(k)] = v
                multi = True
                continue
            c = self.mech.coordinate(name)
            if c.nq == 2 and c.nv == 1:
                set_continuous_angle(q, c.idx_q, v)
            elif c.nq == 1:
                q[c.idx_q] = v
            else:
                raise UsageError(f"{self.mech.path}: joint '{name}' has {c.nq} coordinates: give them as "
                                 f"{name}[q0] ... {name}[q{c.nq - 1}]")
        return pin.normalize(self.model, q) if multi else q

    def outside(self, q: np.ndarray) -> tuple:
        """The joints of q outside the file's limits (outside_limits)."""
        return outside_limits(self.mech, q)

    def joint_values(self, q: np.ndarray) -> dict:
        """Every joint coordinate name -> value [rad or m] (Mechanism.joint_values)."""
        return self.mech.joint_values(q)

    def _wrap(self, q: np.ndarray) -> np.ndarray:
        q = np.array(q, float)
        _, _, _, _, idx, wrap = self.mech._value_layout()
        w = idx[wrap]
        if len(w):
            q[w] = wrap_angle(q[w])
        return q

    def signature(self, q: np.ndarray) -> np.ndarray:
        """World positions of every joint centre (and the output pose): equal for
        configurations that differ only by idle spins."""
        pin.framesForwardKinematics(self.model, self.data, q)
        parts = [self.data.oMf[f].translation for f in self._points]
        if self.output_frame is not None:
            joint, placement = self._output_at
            parts.append((self.data.oMi[joint] * placement).homogeneous[:3].ravel() * 0.1)
        return np.concatenate(parts) if parts else np.zeros(0)

    def same_mode(self, sig_a, sig_b) -> bool:
        """Whether two signatures are one assembly mode: every joint centre (and the output pose) within
        the geometry tolerance, scaled by the mechanism's size where it is over a metre (the one rule of
        the random-start search, the homotopy and the closed form)."""
        return bool(np.max(np.abs(sig_a - sig_b), initial=0.0)
                    < self.mech.tolerances.geometry * max(self.mech.length, 1.0))

    def _starts(self, count: int, seed: int):
        """The reference configuration (when there is one), the file's configuration, and
        ``count`` random configurations within the joint limits."""
        rng = np.random.default_rng(seed)
        ref = self.reference()
        starts = ([ref] if ref is not None else []) + [self.mech.neutral()]
        starts += [self.mech.random_configuration(rng) for _ in range(count)]
        return starts

    # --------------------------------------------------------------- solving
    def _check_inputs(self, values: dict, every: bool = True) -> None:
        unknown = [n for n in values if n not in self.inputs]
        missing = [n for n in self.inputs if n not in values] if every else []
        if unknown or missing:
            raise UsageError(f"{self.mech.path}: give a value for each input joint ({', '.join(self.inputs)})"
                             + (f"; not inputs: {', '.join(unknown)}" if unknown else ""))

    def file_values_hint(self, names: list | None = None) -> str:
        """--set options that give the joints ``names`` (default: the inputs) the file's values (SI:
        rad, m), as a way to name them in an error: one option where the values are equal."""
        names = list(self.inputs if names is None else names)
        file_values = self.mech.joint_values(self.mech.neutral())
        shown = {n: file_values[n] for n in names}
        if len(set(shown.values())) == 1:
            return f"--set {','.join(names)}={next(iter(shown.values())):g}"
        return " ".join(f"--set {n}={v:g}" for n, v in shown.items())

    def unset_error(self) -> UsageError:
        """The usage error of a solve whose inputs leave out joints that no loop passes through
        (``unset``): they are inputs too, named with the file's values as a way to give them."""
        names = list(self.unset)
        hint = self.file_values_hint(names)
        return UsageError(f"{self.mech.path}: no loop passes through {', '.join(names)}: "
                          f"{'each is an input' if len(names) > 1 else 'it is an input'} that only its own value "
                          f"decides; give {'them' if len(names) > 1 else 'it'} with --set (the file's values: {hint})")

    def track(self, values: dict, q: np.ndarray) -> Assembly:
        """The configuration that damped Newton reaches from the configuration ``q`` with the
        named inputs moved to ``values`` (inputs not named keep their values in q): the
        closed-loop forward kinematics of a control or simulation loop, in the assembly
        mode of q when the step is small.  The result is checked like every solution
        (closure residual below the tolerance, no cut joint assembled upside down);
        AssemblyError otherwise.  No modes are searched and nothing else is analysed:
        ``solve`` does that."""
        self._check_inputs(values, every=False)
        a = self.mech.closure.solve(self.set_inputs(q, values), frozen=self.frozen)
        return Assembly(self._wrap(a.q), a.residual, a.iterations)

    def solve(self, values: dict, near: dict | None = None, rates: dict | None = None,
              accels: dict | None = None, starts: int = 24, seed: int = 0, trace: bool = False,
              points=(), method: str = "auto") -> PositionResult:
        """Every assembly mode for the input ``values`` (see the class).  ``points``: motion.Point
        objects whose position (and velocity, acceleration with ``rates``) each solution reports.
        ``method``: "auto" -- homotopy continuation, certified, where the closure is polynomial
        (analysis.position.certified), with ``starts`` random starts added where it is not certified
        --, "starts" (damped Newton from random starts only, as with --trace or --near), or "nearest"
        (solve's default on the command line): every mode where they come at once (a mechanism of dyads,
        in closed form; random starts where the closure is not polynomial), else only the mode damped
        Newton reaches from the file's configuration, nothing searched -- "auto" when Newton fails there,
        said in the notes.  Every joint given (nothing unknown): that configuration, the closure
        evaluated there and nothing solved (analysis.position.given), whatever the method.
        ``PositionResult.method`` says which way the solutions came."""
        mech = self.mech
        self._check_inputs(values)
        if self.unset:
            raise self.unset_error()
        typed, whole = dict(values), whole_turns(self, values)
        values = {n: v - whole.get(n, 0.0) for n, v in values.items()}  # solved within a turn, then turned on
        steps = []
        recorder = (lambda it, q, r, K, dq, ok: steps.append(
            TraceStep(it, r.copy(), K[:, self.passive].copy(), dq[self.passive].copy(), ok))) if trace else None
        near_q = None
        if near:
            ref = self.reference()
            near_q = self.set_inputs(mech.neutral() if ref is None else ref, near)
        found, best, first, lead, done = self._first_answer(values, near_q, method, trace, recorder)
        start_list = [found[0][1]] if first else ([near_q] if near_q is not None else []) + self._starts(starts, seed)
        if self.kept:  # joints of several coordinates no loop passes through: the file's values, not random ones
            neutral, start_list = mech.neutral(), [np.array(q0, float) for q0 in start_list]
            for q0 in start_list:
                q0[self._kept_q] = neutral[self._kept_q]
        if not found and done is None and near_q is None and not trace and method != "starts":
            done = certified.search(self, values, seed)  # homotopy continuation: every mode, certified
            found = list(done.found)
        settled = done is not None and done.complete  # every mode certified: none left to search for
        if settled:
            start_list = []
        if not first and not settled:
            more_found, more = self.distinct(
                mech.closure, [self.set_inputs(q0, values) for q0 in start_list], frozen=self.frozen,
                first_trace=recorder if trace and near_q is None else None)
            found, best = certified.join(self, found, more_found), min(best, more)
        count = (done.count if done is not None and done.complete else given.first_count(first, found[0][2])
                 if first and first != "newton from --near's configuration" else None if first else
                 certified.count_after_starts(done, found, len(start_list)))
        if not found:
            raise self._unreached(values, best, len(start_list), done)
        if mech.counted_turns:  # the nut on the thread (the gear's tooth) the file's configuration engages
            found = engaged(self, found, values)
        if whole:
            found = [(k, *turn_on(self, q, whole, typed)) for k, q, _ in found]
        self.generic(hint=found[0][1])  # generic ranks (from the solution when nothing else assembles)
        info = dict(enumerate(done.info)) if done is not None else {}
        sols = [self.solution(q, a, rates, accels, points, typed=typed, sets=info.get(k, (None, None))[0],
                              simple=info.get(k, (None, None))[1]) for k, (_, q, a) in enumerate(found)]
        sols = self._ordered(self._merge(sols), near_q)
        notes = lead + tuple(f"{j} keeps the file's value: no loop passes through it and its "
                             f"{mech.coordinate(j).nq} coordinates are not inputs" for j in self.kept)
        if near_q is not None:
            sols = sols[:1]
            notes += self._missed_near(near, sols[0])
        held = {link: sols[0].link_angles[link] for link in mech.closure.row_inputs
                if sols[0].link_angles and link in sols[0].link_angles} or None
        return PositionResult(dict(typed), tuple(self.inputs), tuple(sols),
                              0 if done is not None and done.complete else len(start_list), self.free_dofs,
                              tuple(steps), self.output, self._angular, self._angular_coupled(),
                              angular_loop_joints(self.mech), notes, held, count,
                              first or search_method(count))

    def _first_answer(self, values: dict, near_q: np.ndarray | None, method: str, trace: bool,
                      recorder: Callable[..., None] | None) -> tuple[list, float, str | None, tuple[str, ...], Any]:
        """How one answer comes without a search, where it does: (found, the best residual, how it came or None,
        the notes it leads with, the modes found at once or None)."""
        mech = self.mech
        found: list = []
        best, first, done = np.inf, None, None
        lead: tuple[str, ...] = ()
        if not given.unknowns(self).size:  # every joint given: the closure evaluated there, nothing solved
            q, a, line = given.given_configuration(self, self.set_inputs(self._drawn(), values))
            found, first, lead = [(None, q, a)], "every joint given", (line,)
        elif near_q is not None:  # the mode reached from the given configuration, when Newton gets there
            found, best = self.distinct(mech.closure, [self.set_inputs(near_q, values)], frozen=self.frozen,
                                        first_trace=recorder if trace else None)
            first = "newton from --near's configuration" if found else None
        elif method == "nearest" and not trace:  # the mode asked for, at once, where listing every one is not
            done = self._at_once(values)
            if done is None:
                found, best = self.distinct(mech.closure, [self.set_inputs(self._drawn(), values)], frozen=self.frozen)
                first = NEWTON_FROM_FILE if found else None
                lead = () if found else ((f"Newton from the file's configuration did not converge (residual "
                                          f"{best:.2g}): every mode searched"),)
            else:
                found = list(done.found)
        return found, best, first, lead, done

    def _unreached(self, values: dict, best: float, starts: int, done: Any) -> AssemblyError:
        """The error of inputs no start reached: certified (no real solution) said first, where it is."""
        mech = self.mech
        certain = ((f"none of the {done.count.complex} complex solutions is real" if done.count.complex != 1 else
                    "its one solution is complex") + f" (certified: {done.count.certificate})") \
            if done is not None and done.complete else None
        inputs = "the inputs " + ", ".join([self._describe(values)] * bool(values)
                                           + [f"the angle of {k}" for k in mech.closure.row_inputs])
        if certain and not starts:  # the certificate settles it: nothing was searched
            return AssemblyError(mech.path, np.inf, 0, reason=certain, message=(
                f"cannot assemble the mechanism: {inputs} cannot be reached: {certain}; nothing searched"))
        return AssemblyError(mech.path, best, mech.tolerances.max_iterations, starts=starts,
                             detail=f"{inputs} cannot be reached from {starts} starting configurations", reason=certain)

    def _ordered(self, sols: list, near_q: np.ndarray | None) -> list:
        """The solutions in order: physical first, then regular, then nearest the reference (--near's
        configuration, else the file's)."""
        ref = near_q if near_q is not None else self.reference()
        if len(sols) > 1:
            ref_sig = self.signature(ref if ref is not None else sols[0].q)
            sols.sort(key=lambda s: (not s.physical, s.singular,
                                     float(np.linalg.norm(self.signature(s.q) - ref_sig))))
        return sols

    def _drawn(self):
        """The configuration the values are set on where nothing is searched: the reference (the file's,
        assembled), else the file's own."""
        ref = self.reference()
        return self.mech.neutral() if ref is None else ref

    def _at_once(self, values: dict):
        """solve's default (method "nearest"): every mode where they come at once, as a certified.Search --
        a closure that is not polynomial or inputs that leave a continuum (an empty Search: solve's random
        starts find them, or samples of the continuum; no homotopy to spare), a mechanism of dyads (their closed form, analysis.position.certified.closed_form) -- or None
        where only the homotopy would list them (Newton then answers the mode asked for)."""
        mech = self.mech
        if algebraic_obstacle(mech.model, mech.cuts, mech.closure.extra, mech.couplings) or self.free_dofs:
            return certified.Search([], [], None, certified.obstacle(self))  # (a continuum: its samples, as before)
        got = certified.closed_form(self, values) if any(
            not isinstance(cached_plan(self, name), str) for name in self.inputs) else "no dyads"
        if isinstance(got, str):
            return None
        return certified.Search([(self.signature(q), q, a) for q, a, _, _ in got.modes],
                                [(sets, simple) for _, _, sets, simple in got.modes], got.count)

    def _missed_near(self, near: dict, sol) -> tuple:
        """A line for each --near value the mode found lies far from (Tolerances.near_far): the joints
        --near does not name are free, so the mode nearest the given ones may not be near them."""
        tol, out = self.mech.tolerances, []
        for name, want in near.items():
            got = sol.joints.get(name)
            if got is None:
                continue
            angle = name in self._angular
            miss = abs(wrap_angle(got - want)) if angle else abs(got - want)
            if miss > tol.near_far * (1.0 if angle else self.mech.length):
                shown = (lambda v: f"{np.degrees(v):.4g} deg") if angle else (lambda v: f"{v:.4g} m")
                out.append(f"--near {name}={shown(want)}: the assembly mode found has {name} = {shown(got)} "
                           f"(the nearest these inputs allow; the joints --near does not name were free)")
        return tuple(out)

    def distinct(self, system: ClosureSystem, starts: int | list, frozen=(), first_trace=None) -> tuple:
        """Solve ``system`` from every start; keep one solution per assembly mode.

        Returns ([(signature, q, Assembly)], smallest residual of the failures)."""
        found, best = [], np.inf
        for k, q0 in enumerate(starts):
            try:
                a = system.solve(q0, frozen=frozen, trace=first_trace if k == 0 else None)
            except AssemblyError as exc:
                best = min(best, exc.residual)
                continue
            p = newton.polish(system.pinocchio, a.q, frozen)  # undamped at the end: round-off, not the damped tolerance
            a = Assembly(p.q, p.residual, a.iterations + p.iterations, a.start, a.starts)
            q = self._wrap(a.q)
            if len(starts) == 1:  # nothing to tell apart
                found.append((None, q, a))
                continue
            sig = self.signature(q)
            if any(self.same_mode(sig, s) for s, *_ in found):
                continue
            found.append((sig, q, a))
        return found, best

    @staticmethod
    def _describe(values: dict) -> str:
        return ", ".join(f"{k}={v:.6g}" for k, v in values.items())

    # --------------------------------------------------------------- one answer per mode
    def _merge(self, sols):
        """Solutions that are one root merged (analysis.position.modes.merge)."""
        return modes.merge(self, sols)

    def _distance(self, q1: np.ndarray, q2: np.ndarray) -> float:
        return float(np.linalg.norm(self.signature(q1) - self.signature(q2)))

    def _labels(self, q: np.ndarray, outside) -> tuple:
        """Why a solution is not reached by moving from the reference configuration
        (analysis.position.modes.ModeLabels)."""
        if self._labelling is None:
            self._labelling = modes.ModeLabels(self)
        return self._labelling(q, outside)

    def _linkage(self, q: np.ndarray):
        """A four-bar's or slider-crank's textbook construction at q (planar.identify), or None."""
        if len(self.inputs) != 1 or self._plane_normal() is None or len(self.mech.cuts) != 1:
            return None
        info = identify(self.mech, self.mech.topology(q), q, self.inputs[0])
        return None if info is None else info.construction()

    def _plane_normal(self):
        if self._angles is False:
            self._link_angles(self.mech.neutral())
        return None if self._angles is None else self._angles.n

    def _link_angles(self, q: np.ndarray, state: KinematicState | None = None):
        if self._angles is False:
            self._angles = None
            ref = self.reference()
            if ref is not None:
                topo = self.mech.topology(ref)
                if topo.motion_space == "planar":
                    self._angles = LinkAngles(self.mech, topo)
        return self._angles(q, state) if self._angles is not None else None

    # --------------------------------------------------------------- one solution
    def solution(self, q: np.ndarray, a: Assembly, rates: dict | None = None, accels: dict | None = None, points=(), typed=None, sets=None, simple=None,
                 spelled: bool = False) -> Solution:
        """One assembly mode at the closed configuration q (a: its model.cuts.Assembly), every quantity
        read from one KinematicState; rates and accelerations when input rates are given.  ``sets``:
        the joint-angle sets that reach it; ``simple``: whether it is a simple root (None: tested here
        when its measure is below the singular tolerance, modes.simple_root); ``spelled``: q is already
        in the angle set within the limits where one exists (a closed form chose each leg's with
        model.leg_chains.best_set), not looked for again."""
        mech, tol = self.mech, self.mech.tolerances
        if not spelled:
            q = spelled_within_limits(mech, q)  # the pose's angle set within the limits, where one exists
        m = measures(mech, q, self.generic())
        sigma = min(m["actuator"], m["constraint"]) if self.generic().rank_K or self.generic().rank_Kp else 1.0
        if sigma < tol.singular and simple is None:
            simple = modes.simple_root(self, q)
        singular = sigma < tol.singular and not simple  # an ill-conditioned simple root is determined
        pose = twist = acc = qd = qdd = None
        rate_d = acc_d = None
        if rates is not None:
            K = mech.closure.jacobian(q)
            solve, _ = self.passive_solver(K)
            qd = self.rates(q, K, rates, solve)
            rate_d = self._named(qd)
            qdd = self.accelerations(q, K, qd, accels or {}, solve)
            acc_d = self._named(qdd)
        state = KinematicState(mech, q, qd, qdd)  # every quantity below is read from this one state
        if self.output_frame is not None:
            pose = state.frame_pose(self.output_frame)
            if rates is not None:
                twist, acc = state.frame_twist(self.output_frame), state.frame_acceleration(self.output_frame)
        outside = outside_limits(mech, q)
        angles = self._link_angles(q, state)
        joints = self.joint_values(q)
        for name, v in (typed or {}).items():  # an input is reported as typed: 720deg stays 720 deg, not 0
            if name in joints and abs(wrap_angle(joints[name] - v)) < tol.equal:
                joints[name] = float(v)
        return Solution(q, joints, a.residual, a.iterations, bool(singular), float(sigma), pose,
                        rate_d, acc_d, twist, acc, qd, qdd, outside, self._labels(q, outside),
                        link_angles=angles, sigmas=m, coupled=mech.coupled_values(q) or None,
                        loop_joints=state.loop_joints or None, loop_rates=state.loop_rates or None,
                        loop_accelerations=state.loop_accelerations or None,
                        links=link_motions(state, angles, self._plane_normal(),
                                           self._angles.along() if self._angles else None),
                        points=point_motions(state, points) or None, linkage=self._linkage(q),
                        leg_lengths=state.leg_lengths or None, guide_positions=state.guide_positions or None,
                        guide_angles=(self._angles.guides(state) or None) if self._angles else None,
                        angle_sets=sets, simple=simple)

    def _named(self, v) -> dict:
        return dict(zip(self.mech.coordinate_names, map(float, v)))

    def _input_vector(self, values: dict) -> np.ndarray:
        x = np.zeros(len(self.frozen))
        for k, name in enumerate(self.inputs):
            x[k] = values.get(name, 0.0)
        return x

    def passive_solver(self, K: np.ndarray) -> tuple:
        """(solve, s): one SVD of the passive columns of K, reused for rates and accelerations.
        solve(b) is the minimum-norm least-squares x of K_p x = b (as numpy.linalg.lstsq);
        s are the singular values of K_p, largest first."""
        Kp = K[:, self.passive]
        if Kp.size == 0:
            return (lambda b: np.zeros(len(self.passive))), np.zeros(0)
        U, s, Vt = np.linalg.svd(Kp, full_matrices=False)
        keep = s > np.finfo(float).eps * max(Kp.shape) * s[0] if s.size and s[0] > 0 else np.zeros(len(s), bool)
        U, inv, Vt = U[:, keep], 1.0 / s[keep], Vt[keep]
        return (lambda b: Vt.T @ (inv * (U.T @ b))), s

    def rates(self, q: np.ndarray, K: np.ndarray, values: dict, solve: Callable | None=None) -> np.ndarray:
        """Joint rates from K q' = 0 with the input rates given (minimum norm in
        the passive joints, so idle spins are zero).  A link held at an angle (link_inputs)
        turns at the rate ``values`` gives its name (0 when none): its row's K q' is that rate.
        solve: see passive_solver."""
        qd = np.zeros(self.mech.nv)
        qd[self.frozen] = self._input_vector(values)
        if K.size:
            solve = solve or self.passive_solver(K)[0]
            qd[self.passive] = solve(self.mech.closure.row_rates(values) - K[:, self.frozen] @ qd[self.frozen])
        return qd

    def accelerations(self, q: np.ndarray, K: np.ndarray, qd: np.ndarray, values: dict, solve: Callable | None=None) -> np.ndarray:
        """Joint accelerations from K q'' = -K' q' with the input accelerations given (a held link's
        angular acceleration as its row's, as in ``rates``)."""
        qdd = np.zeros(self.mech.nv)
        qdd[self.frozen] = self._input_vector(values)
        if K.size:
            bias = self.mech.closure.bias(q, qd)
            solve = solve or self.passive_solver(K)[0]
            qdd[self.passive] = solve(self.mech.closure.row_rates(values) - K[:, self.frozen] @ qdd[self.frozen] - bias)
        return qdd
