"""Loading a mechanism file into a :class:`Mechanism`.

A Mechanism is the Pinocchio model of the spanning tree (built by Pinocchio's
URDF parser), the cut joints bound to frames of that model, the actuated
joints, and the map between joint names and coordinates.  Analyses (assembly,
mobility, and later position, velocity and singularity analysis) work on it.
"""

from __future__ import annotations

import copy
import random
import threading

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import AssemblyError, MechanismFileError, UsageError, quote
from ..files.description import MechanismSpec, resolve_actuation
from ..tolerances import DEFAULT, Tolerances
from .closability import closure_gap, closure_obstacle
from .kernel.closure import ClosureSystem
from .kernel.scaling import sliding_columns
from .cuts import Assembly, bind_cut
from .geometry import wrap_angle
from .linalg import null_space, rank
from .manifold import continuous_angle, set_continuous_angle
from .topology import build_topology
from .lengths import characteristic_length
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.topology import Topology

__all__ = ["Mechanism", "Coordinate"]


@dataclass(frozen=True)
class Coordinate:
    """Where a tree joint's coordinates live in q (nq entries) and in velocities (nv)."""

    joint: str
    joint_id: int
    idx_q: int
    nq: int
    idx_v: int
    nv: int


#: Models with more velocity coordinates than this share one pinocchio.Data (Mechanism.scratch_data, and every
#: KinematicState of them: model.state).
SHARED_DATA_NV = 120


def _std_normal(seed: int):
    """size -> that many standard normal deviates, from the standard library's generator seeded with ``seed``."""
    r = random.Random(seed)
    return lambda size: np.array([r.gauss(0.0, 1.0) for _ in range(size)])


class Mechanism:
    """A mechanism: Pinocchio model of the spanning tree, cut joints, actuation.

    Attributes
    ----------
    path:       the file it was read from.
    spec:       the :class:`~screwkin.files.description.MechanismSpec` read from the file.
    model:      ``pinocchio.Model`` of the spanning tree (with frames F1, F2 of every cut joint).
    cuts:       list of :class:`~screwkin.model.cuts.CutJoint`.
    closure:    the :class:`~screwkin.model.kernel.closure.ClosureSystem` r(q) = 0.
    coordinates: list of :class:`Coordinate`, one per tree joint with coordinates.
    actuated:   actuated joint names; ``actuation_source`` says where they came from.
    """

    def __init__(self, spec: MechanismSpec, model: pin.Model, actuated: list | None=None, tolerances: Tolerances = DEFAULT) -> None:
        self.spec = spec
        self.path = spec.path
        self.tolerances = tolerances
        self.model = model
        self.coordinates = [
            Coordinate(model.names[j], j, model.idx_qs[j], model.nqs[j], model.idx_vs[j], model.nvs[j])
            for j in range(1, model.njoints)
            if model.nvs[j] > 0
        ]
        self._coord = {c.joint: c for c in self.coordinates}
        self.couplings = tuple(spec.couplings)  # <mimic> joints: no coordinate of their own
        self._coupled = {c.joint: c for c in self.couplings}
        self.extra_rows = []  # rows of higher pairs (model.cuts.CouplingRow / ContactRow)
        self.virtual_joints = {}  # higher pair -> the coordinates of its virtual chain
        self.cuts = []
        for c in spec.cut_joints:
            cut, row, virtual = bind_cut(model, c, self._coord, self.path)
            self.cuts.append(cut)
            if row is not None:
                self.extra_rows.append(row)
            if virtual:
                self.virtual_joints[c.name] = virtual
        # a ground frame for targets (inverse kinematics); every frame must exist
        # before the pinocchio.Data is made from the model
        self.target_frame = model.addFrame(
            pin.Frame("screwkin@target", 0, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME), False)
        # the id of the output frame a command may put on a link (--tool, a named --point): its placement is
        # mech.tool's (model.state.place_tool), read by KinematicState and model.state.frame_parent; in this
        # model the frame stays where it is made, a reserved slot a copy may place (model.state.model_with_output)
        self.tool_frame = model.addFrame(
            pin.Frame("screwkin@tool", 0, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME), False)
        self.tool = None  # model.state.OutputFrame (name, link, placement on the link) once placed
        # The mechanism's own Data: Pinocchio 4.1 allocates nv^3-sized tensors in one (a Data of a
        # 500-joint chain: 17 s and 7.9 GB here, 0.2 s at 200 joints, 1 ms at 30).  Computations
        # take a Data of their own from scratch_data(); only models past SHARED_DATA_NV
        # coordinates hand this one out (each user then runs Pinocchio's pass first).
        self.data = model.createData()
        self.state_data = threading.local()  # each thread's Data for KinematicState (model.state)
        self._gravity_models = {}  # (gx, gy, gz) -> a copy of the model with that gravity
        self._models_lock = threading.Lock()
        self.closure = ClosureSystem(model, self.cuts, tolerances, self.path, data=self.scratch_data(),
                                     extra=self.extra_rows)
        self.set_actuated(actuated)
        self._assembly = None
        self._limits = None
        self._generic = None
        self._generic_cache = {}  # (hint, seed, starts) -> generic_configurations' result
        self._length = None
        self._layout = None
        self.cache = {}  # results analyses derive from this mechanism (cleared when actuation or length change)
        self._rule_length = characteristic_length(model, self.cuts)
        self._translational = self._translational_coordinates()

    # ------------------------------------------------------------------ binding
    @property
    def shares_data(self) -> bool:
        """Whether the model is too large for a Data per computation (see scratch_data)."""
        return self.model.nv > SHARED_DATA_NV

    def scratch_data(self) -> pin.Data:
        """A pinocchio.Data for one computation, so that no result depends on what another left
        in a Data it shares: a new one, except past SHARED_DATA_NV coordinates, where a Data costs
        seconds and gigabytes and the mechanism's own is handed out (its user runs its pass first)."""
        return self.data if self.shares_data else self.model.createData()

    def model_with_gravity(self, g: np.ndarray) -> pin.Model:
        """The Pinocchio model with gravity ``g`` (gx, gy, gz) [m/s^2] (RNEA, gravity terms and
        potential energy read model.gravity): a copy made once per g, so that no computation
        changes the model another is reading (threads may share a mechanism)."""
        key = tuple(float(x) for x in np.asarray(g, float).ravel())
        with self._models_lock:
            model = self._gravity_models.get(key)
            if model is None:
                model = pin.Model(self.model)
                model.gravity = pin.Motion(np.array(key), np.zeros(3))
                self._gravity_models[key] = model
        return model

    def set_actuated(self, actuated: list | None=None) -> None:
        """Choose the actuated joints (None: the file's declaration)."""
        names, source = resolve_actuation(self.spec, actuated)
        unknown = [n for n in names if n not in self._coord]
        if unknown and unknown[0] in self._coupled:
            c = self._coupled[unknown[0]]
            msg = (f"actuated joint {quote(unknown[0])} mimics {quote(c.mimics)}: it moves with it and cannot be "
                   "an input of its own")
            raise (UsageError(f"{self.path}: {msg}") if source == "command line" else MechanismFileError(self.path, msg))
        if unknown:
            known = ", ".join(c.joint for c in self.coordinates)
            msg = f"actuated joint '{unknown[0]}' is not a moving joint of the mechanism (joints: {known})"
            if source == "command line":
                raise UsageError(f"{self.path}: {msg}")
            raise MechanismFileError(self.path, msg)
        if len(set(names)) != len(names):
            raise UsageError(f"{self.path}: an actuated joint is named twice: {', '.join(names)}")
        self.actuated = names
        self.actuation_source = source
        if hasattr(self, "cache"):
            self.cache.clear()

    # ------------------------------------------------------------------ coordinates
    @property
    def nq(self) -> int:
        return self.model.nq

    @property
    def nv(self) -> int:
        return self.model.nv

    def coordinate(self, joint: str) -> Coordinate:
        try:
            return self._coord[joint]
        except KeyError:
            if joint in self._coupled:
                c = self._coupled[joint]
                raise UsageError(f"{self.path}: joint {quote(joint)} mimics {quote(c.mimics)} ({joint} = "
                                 f"{c.multiplier:g} {c.mimics} + {c.offset:g}): it has no value of its own; "
                                 f"give {quote(c.mimics)}") from None
            known = ", ".join(c.joint for c in self.coordinates)
            raise UsageError(f"{self.path}: no moving joint named '{joint}' (joints: {known})") from None

    def velocity_indices(self, joints: tuple | list) -> np.ndarray:
        """Velocity (tangent) indices of the named joints, in order."""
        idx = []
        for j in joints:
            c = self.coordinate(j)
            idx.extend(range(c.idx_v, c.idx_v + c.nv))
        return np.asarray(idx, int)

    def _value_layout(self):
        """(1-coordinate joints (name, q index, wrap), continuous joints (name, q index), the
        coordinates of multi-DOF joints (name, q index), order of the names)."""
        if self._layout is None:
            single, continuous, multi, order = [], [], [], []
            for c in self.coordinates:
                short = self.model.joints[c.joint_id].shortname()
                if c.nq == 1:
                    # a higher pair's virtual angle (a screw's turn, a gear's roll) counts turns: never wrapped
                    wrap = short.startswith("JointModelR") and c.idx_q not in self.counted_turns
                    single.append((c.joint, c.idx_q, wrap))
                    order.append(c.joint)
                elif c.nq == 2 and c.nv == 1:
                    continuous.append((c.joint, c.idx_q))
                    order.append(c.joint)
                else:
                    names = [(f"{c.joint}[q{k}]", c.idx_q + k) for k in range(c.nq)]
                    multi += names
                    order += [n for n, _ in names]
            idx = np.array([i for _, i, _ in single], int)
            wrap = np.array([w for _, _, w in single], bool)
            self._angle_v = np.array([self.coordinate(n).idx_v for n, _, w in single if w], int)
            self._layout = (single, continuous, multi, order, idx, wrap)
        return self._layout

    @property
    def counted_turns(self) -> frozenset:
        """q indices of the higher pairs' virtual revolute joints (a helical pair's turn, a rolling pair's
        angles): their coupling rows are linear in the unwrapped angle, so a value is never taken modulo
        a turn (two turns of a 5 mm lead screw lift 10 mm, not 0)."""
        out = set()
        for row in self.extra_rows:
            if getattr(row, "kind", None) == "angle":  # a link's angle held as an input: modulo a turn
                continue
            for iq, _, _ in getattr(row, "terms", ()):
                jid = next(c.joint_id for c in self.coordinates if c.idx_q == iq)
                if self.model.joints[jid].shortname().startswith("JointModelR"):
                    out.add(iq)
        return frozenset(out)

    def coupled_values(self, q: np.ndarray) -> dict:
        """The value of every coupled (<mimic>) joint: multiplier * its primary's + offset
        [rad or m]; angles in [-pi, pi)."""
        out = {}
        for c in self.couplings:
            p = self.coordinate(c.mimics)
            v = c.multiplier * float(q[p.idx_q]) + c.offset
            if self._revolute_like(c.joint):
                v = wrap_angle(v)
            out[c.joint] = v
        return out

    def _revolute_like(self, joint: str) -> bool:
        return next((j.type for j in self.spec.joints if j.name == joint), "") in ("revolute", "continuous")

    def difference(self, q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
        """The velocity-space step from q0 to q1 (pinocchio.difference), with the angles of
        bounded revolute joints taken the short way round [-pi, pi).  Stacks (N, nq) give (N, nv)."""
        if np.ndim(q0) == 2 or np.ndim(q1) == 2:  # (nq == nv: every joint a vector space, the plain difference)
            d = (np.asarray(q1, float) - np.asarray(q0, float) if self.model.nq == self.model.nv else
                 np.array([pin.difference(self.model, a, b) for a, b in zip(*np.broadcast_arrays(q0, q1))]))
        else:
            d = pin.difference(self.model, q0, q1)
        _, _, _, _, idx, wrap = self._value_layout()
        if wrap.any():
            v = self._angle_v
            d[..., v] = wrap_angle(d[..., v])
        return d

    def joint_values(self, q: np.ndarray) -> dict:
        """Every joint coordinate name -> value [rad or m], in the order of the joints:
        revolute angles in [-pi, pi), continuous joints as atan2(sin, cos), the coordinates
        of multi-DOF joints as ``joint[qk]``."""
        return dict(zip(self._value_layout()[3], self.joint_value_rows(q)[0].tolist()))

    def joint_value_rows(self, Q: np.ndarray) -> np.ndarray:
        """joint_values of each configuration of Q (N, nq), as the rows of an (N, joints) array in the
        order of joint_values' names: the same numbers, for many configurations at once (a sweep's)."""
        Q = np.atleast_2d(np.asarray(Q, float))
        single, continuous, multi, order, idx, wrap = self._value_layout()
        V = Q[:, idx]
        V[:, wrap] = wrap_angle(V[:, wrap])
        cols = {n: V[:, k] for k, (n, _, _) in enumerate(single)}
        for name, i in continuous:
            cols[name] = continuous_angle(Q, i)
        for name, i in multi:
            cols[name] = Q[:, i]
        return np.column_stack([cols[n] for n in order]) if order else np.zeros((len(Q), 0))

    @property
    def coordinate_names(self) -> list:
        names = []
        for c in self.coordinates:
            names += [c.joint] if c.nv == 1 else [f"{c.joint}[{k}]" for k in range(c.nv)]
        return names

    def limited_coordinates(self):
        """(names, q indices, lower, upper, is an angle) of the one-coordinate joints with a
        finite <limit> range, as arrays (for checking many configurations quickly)."""
        if self._limits is None:
            model, rows = self.model, []
            for c in self.coordinates:
                if c.nq != 1:
                    continue
                lo, hi = model.lowerPositionLimit[c.idx_q], model.upperPositionLimit[c.idx_q]
                if np.isfinite(lo) and np.isfinite(hi) and hi - lo > 0:
                    angle = model.joints[c.joint_id].shortname().startswith("JointModelR")
                    rows.append((c.joint, c.idx_q, lo, hi, angle))
            names = tuple(r[0] for r in rows)
            self._limits = (names,) + tuple(np.array([r[k] for r in rows]) for k in range(1, 5))
        return self._limits

    def link_frame(self, link: str) -> int:
        """Frame id of a link (its body frame), or of the output frame placed under its name (model.state.place_tool:
        read it through KinematicState or model.state.frame_parent, not from this model's frames)."""
        if self.tool is not None and link == self.tool[0]:
            return self.tool_frame
        ids = self.__dict__.setdefault("_body_frames", {})  # read once: a scan of Pinocchio's frames is slow
        if link in ids:
            return ids[link]
        for fid, f in enumerate(self.model.frames):
            if f.name == link and f.type == pin.FrameType.BODY:
                ids[link] = fid
                return fid
        links = ", ".join(self.spec.links)
        raise UsageError(f"{self.path}: no link named '{link}' (links: {links})")

    def neutral(self) -> np.ndarray:
        """The configuration written in the file: every joint at zero, or at the value the file
        draws it at (an MJCF joint's ``ref``: MuJoCo's qpos0)."""
        q = pin.neutral(self.model)
        for joint, value in self.spec.reference.items():
            c = self._coord.get(joint)
            if c is not None and c.nq == 1:
                q[c.idx_q] = value
        return q

    def input_alias(self, name: str):
        """The Transmission of an input the file names otherwise than by a coordinate's joint (a
        fixed tendon, a coupled joint an actuator drives), or None."""
        if name in self._coord:
            return None
        return next((t for t in self.spec.inputs if t.name == name and t.joint in self._coord), None)

    def transmissions(self, inputs: list | None=None) -> tuple:
        """The Transmission of each of ``inputs`` (default: the actuated joints) that the file drives
        through a tendon, a coupling or a gear."""
        inputs = set(self.actuated if inputs is None else inputs)
        return tuple(t for t in self.spec.inputs if t.joint in inputs)

    # ------------------------------------------------------------------ length
    @property
    def length(self) -> float:
        """The characteristic length L [m] that makes mixed translation/rotation measures
        dimensionless: the mean link length (:func:`characteristic_length`) unless set."""
        return self._length if self._length is not None else self._rule_length

    @length.setter
    def length(self, value) -> None:
        if value is not None and not (np.isfinite(value) and value > 0):
            raise UsageError(f"{self.path}: the characteristic length must be a positive length, got {value!r}")
        self._length = None if value is None else float(value)
        self.cache.clear()

    def _translational_coordinates(self) -> np.ndarray:
        """Mask of the velocity coordinates that are lengths (model.kernel.scaling.sliding_columns)."""
        return sliding_columns(self.model)

    @property
    def translational(self) -> np.ndarray:
        """Mask (nv,) of the velocity coordinates that are lengths [m]; the others are angles."""
        return self._translational

    # ------------------------------------------------------------------ configurations
    def random_configuration(self, rng: np.random.Generator, around: np.ndarray | None=None, spread: float = 0.3) -> np.ndarray:
        """A random configuration.

        Without ``around``: every joint uniform within its limits -- angles over their
        <limit> range when it is finite and at most a turn, else over a full turn; lengths
        over their range when finite and at most 100 L, else over [-L, L] (L = :attr:`length`);
        ball and free joints uniform over the rotations.  With ``around``: that configuration
        moved by a normal random step of ``spread`` rad (``spread * L`` for lengths)."""
        model = self.model
        if around is not None:
            dq = rng.normal(size=model.nv) * spread
            dq[self._translational] *= self.length
            return pin.integrate(model, np.asarray(around, float), dq)
        L = self.length
        q = pin.neutral(model)
        lo_all, hi_all = model.lowerPositionLimit, model.upperPositionLimit
        for c in self.coordinates:
            short = model.joints[c.joint_id].shortname()
            i = c.idx_q
            if c.nq == 1:
                lo, hi = float(lo_all[i]), float(hi_all[i])  # Python floats: no overflow warning at +-1.8e308
                length = bool(self._translational[c.idx_v])
                wide = 100 * L if length else 2 * np.pi
                if np.isfinite(lo) and np.isfinite(hi) and 0 < hi - lo <= wide:
                    q[i] = rng.uniform(lo, hi)
                elif length:
                    q[i] = rng.uniform(max(lo, -L), min(hi, L)) if max(lo, -L) < min(hi, L) else rng.uniform(-L, L)
                else:
                    q[i] = rng.uniform(-np.pi, np.pi)
            elif c.nq == 2 and c.nv == 1:  # continuous: (cos, sin)
                a = rng.uniform(-np.pi, np.pi)
                set_continuous_angle(q, i, a)
            elif short == "JointModelSpherical":
                v = rng.normal(size=4)
                q[i:i + 4] = v / np.linalg.norm(v)
            elif short == "JointModelFreeFlyer":
                q[i:i + 3] = rng.uniform(-L, L, 3)
                v = rng.normal(size=4)
                q[i + 3:i + 7] = v / np.linalg.norm(v)
            elif short == "JointModelPlanar":
                a = rng.uniform(-np.pi, np.pi)
                q[i:i + 4] = (*rng.uniform(-L, L, 2), np.cos(a), np.sin(a))
            elif short == "JointModelTranslation":
                q[i:i + 3] = rng.uniform(-L, L, 3)
            else:  # universal, spherical ZYX, ...: angles over a full turn
                dq = np.zeros(model.nv)
                dq[c.idx_v:c.idx_v + c.nv] = rng.uniform(-np.pi, np.pi, c.nv)
                q[i:i + c.nq] = pin.integrate(model, pin.neutral(model), dq)[i:i + c.nq]
        return q

    def _keep(self, q: np.ndarray, hint: np.ndarray, frozen: tuple) -> np.ndarray:
        """q with the coordinates of the joints whose velocity indices are frozen taken from hint."""
        if not len(frozen):
            return q
        frozen = set(int(f) for f in frozen)
        q = np.array(q, float)
        for c in self.coordinates:
            if any(c.idx_v + k in frozen for k in range(c.nv)):
                q[c.idx_q:c.idx_q + c.nq] = hint[c.idx_q:c.idx_q + c.nq]
        return q

    # ------------------------------------------------------------------ analyses
    def assemble(self, q0: np.ndarray | None = None, frozen: tuple=(), seed: int = 0) -> Assembly:
        """Close the loops: a seeded search, not a single descent.

        The hint ``q0`` (default: the file's configuration, ``neutral()``: every joint at zero, an MJCF
        joint at its ``ref``) is tried
        first; when damped Newton does not close the loops from it (a file drawn with every
        link along one line has a residual whose gradient vanishes there), perturbations of
        it and then random configurations within the joint limits are tried, in a fixed
        order (``seed``), and the first that closes is returned: ``Assembly.start`` says
        which.  ``frozen`` velocity indices (inputs) keep the hint's values in every start.
        Raises AssemblyError with the smallest residual reached and the number of starts, or at once,
        without a search, when the lengths prove a loop cannot close (model.closability)."""
        cache = q0 is None and not len(frozen)
        if cache and self._assembly is not None:
            return self._assembly
        if "closure_gap" not in self.cache:  # the lengths may prove it cannot close: then no search
            self.cache["closure_gap"] = closure_gap(self)
        if self.cache["closure_gap"] is not None:
            reason, gap = self.cache["closure_gap"]
            raise AssemblyError(self.path, gap, 0, starts=0, reason=reason, proved=True)
        tol = self.tolerances
        hint = self.neutral() if q0 is None else np.array(q0, float)
        given = "the file's configuration" if q0 is None else "the given configuration"
        rng = None  # (numpy.random made when a start needs it: its first import takes 10 ms)
        total = max(int(tol.assembly_starts), 1) if self.closure.nrows else 1
        best, best_it = np.inf, 0
        for k in range(total):
            if k and rng is None:
                rng = np.random.default_rng(seed)
            if k == 0:
                q, what = hint, given
            elif k <= tol.perturbations:
                q = self.random_configuration(rng, around=hint, spread=0.1 * k)
                what = f"a perturbation of {given} (start {k + 1} of {total})"
            else:
                q = self.random_configuration(rng)
                what = f"a random configuration within the joint limits (start {k + 1} of {total})"
            q = self._keep(q, hint, frozen) if k else q
            try:
                a = self.closure.solve(q, frozen=frozen)
            except AssemblyError as exc:
                if exc.residual < best:
                    best, best_it = exc.residual, exc.iterations
                continue
            result = Assembly(a.q, a.residual, a.iterations, what, k + 1)
            if cache:
                self._assembly = result
            return result
        starts = (f"{given}, {min(tol.perturbations, total - 1)} perturbations of it and "
                  f"{max(total - 1 - tol.perturbations, 0)} random configurations within the joint limits"
                  if total > 1 else given)
        raise AssemblyError(self.path, best, best_it, detail=starts, starts=total)  # (a proved gap raised above)

    def with_rows(self, rows) -> Mechanism:
        """This mechanism with more closure rows (model.cuts.CouplingRow: a link's absolute angle
        held as an input), for the solves of one command: a shallow copy that shares the model, the
        coordinates and the assembly search (made first, on the mechanism's own loops) and has a
        closure system of its own; the mechanism itself is not changed."""
        try:
            self.generic_configurations()  # the reference configurations: the loops' own, not the rows'
        except AssemblyError:
            pass  # the copy searches with the rows (its configurations close the loops too)
        view = copy.copy(self)
        view.extra_rows = [*self.extra_rows, *rows]
        view.closure = ClosureSystem(self.model, self.cuts, self.tolerances, self.path, data=self.scratch_data(),
                                     extra=view.extra_rows)
        view.cache = {}
        return view

    def closure_obstacle(self) -> str | None:
        """Why a loop of parallel revolutes cannot close, in its links' lengths (model.closability)."""
        return closure_obstacle(self)

    @property
    def generic_known(self) -> bool:
        """Whether generic_configurations() has been computed (with any hint or seed)."""
        return self._generic is not None

    def generic_configurations(self, hint=None, seed: int = 0, starts: int | None = None) -> tuple:
        """(assembly, configurations): assembled configurations where generic ranks are taken.

        The first configuration the assembly search closes (:meth:`assemble`, from ``hint``
        when given) may be singular -- a file drawn straight, at a limit position, or on a
        degenerate branch where links fold onto each other.  So the rank of the constraint
        Jacobian is taken at it, at ``tolerances.samples`` nearby ones (a random step of
        ``sample_step`` along the motion the loops allow, closed again) and at the
        configurations that ``tolerances.generic_starts`` further random starts close; the
        configurations of the largest rank are returned, the one nearest the first assembly
        first (``assembly`` is that first one, with where it came from).  ``starts``: how many
        further random starts (default ``tolerances.generic_starts``; 0 where a closed form has
        every branch already, analysis.position.closed_ik: then the samples' steps are drawn from the
        standard library's generator, numpy.random's first import taking 10 ms).  Cached."""
        starts = self.tolerances.generic_starts if starts is None else int(starts)
        key = (None if hint is None else np.asarray(hint, float).tobytes(), int(seed), starts)
        if key in self._generic_cache:  # keyed on its arguments: another hint or seed is another search
            return self._generic_cache[key][:2]
        a = self.assemble() if hint is None else self.assemble(hint)
        tol, closure = self.tolerances, self.closure
        rng = np.random.default_rng(seed) if starts else None
        normal = rng.normal if starts else _std_normal(seed)
        configs = [a.q]
        if self.nv:  # a serial chain too: its file configuration may be singular for an output
            V = null_space(closure.jacobian(a.q), tol, self.nv)  # the motion the loops allow at the first one
            for _ in range(tol.samples if V.shape[1] else 0):
                step = V @ normal(size=V.shape[1])
                step *= tol.sample_step / max(np.linalg.norm(step), 1e-300)
                try:
                    configs.append(closure.solve(pin.integrate(self.model, a.q, step)).q)
                except AssemblyError:
                    continue
            for _ in range(starts if closure.nrows else 0):  # (for the branches of loops)
                try:
                    configs.append(closure.solve(self.random_configuration(rng)).q)
                except AssemblyError:
                    continue
        ranks = [rank(closure.jacobian(q), tol) if closure.nrows else 0 for q in configs]
        top = max(ranks)
        found = (a, tuple(q for q, r in zip(configs, ranks) if r == top), ranks[0] < top, ranks[0], top)
        self._generic_cache[key] = found
        if self._generic is None:
            self._generic = found  # the first one computed: what first_assembly_singular reports on
        return found[:2]

    @property
    def first_assembly_singular(self) -> tuple:
        """(True, its rank, the generic rank) when the first configuration the assembly search
        closed is less constrained than the generic ones (singular or on a degenerate branch);
        (False, r, r) otherwise.  Needs generic_configurations() first."""
        if self._generic is None:
            self.generic_configurations()
        return self._generic[2:]

    def topology(self, q: np.ndarray | None = None) -> Topology:
        """The :class:`~screwkin.model.topology.Topology` (links, joints, compound joints, loops)
        at q (default: a generic assembled configuration).  The last one is kept: a solver's labels and
        link angles both read it at the reference configuration."""
        q = np.asarray(self.generic_configurations()[1][0] if q is None else q, float)
        key, last = q.tobytes(), self.cache.get("topology")
        if last is None or last[0] != key or last[1] is not self.tolerances:
            last = self.cache["topology"] = (key, self.tolerances, build_topology(self, q))
        return last[2]

    def __repr__(self) -> str:
        return (f"Mechanism({Path(self.path).name!r}: {len(self.spec.links)} links, "
                f"{len(self.coordinates)} moving tree joints, {len(self.cuts)} cut joints)")


