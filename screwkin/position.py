"""Position, velocity and acceleration analysis of closed-loop mechanisms.

Given values of input joints (by default the actuated ones; any joints may be
chosen instead), the other coordinates follow from the loop-closure equations
r(q) = 0, solved by damped Newton with the inputs held.  Every assembly mode
the solver reaches from a deterministic set of starts is reported; two
solutions are the same mode when every joint centre and the output frame are
in the same place (idle spins, which move no joint, do not make new modes).

Rates and accelerations come from the differentiated closure equations
    K q' = 0,        K q'' + K' q' = 0,
split into input and passive columns, with K' q' from Pinocchio's classical
frame accelerations.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from .closure import Assembly
from .errors import AssemblyError, UsageError
from .mobility import null_space, rank

__all__ = ["Solution", "PositionResult", "PositionSolver", "TraceStep"]

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class TraceStep:
    """One Newton iteration: residual r (solver rows), Jacobian K (free columns), step dq."""

    iteration: int
    residual: np.ndarray
    jacobian: np.ndarray
    step: np.ndarray
    accepted: bool


@dataclass(frozen=True)
class Solution:
    """One assembly mode for the given inputs.

    joints:   every joint coordinate name -> value [rad or m] (continuous and
              revolute angles in (-pi, pi]);
    residual: closure residual norm [m, rad]; iterations: Newton iterations;
    singular: the passive joints are not determined to first order (a double
              root, e.g. a limit position; or a constraint singularity);
    sigma_min: smallest relevant singular value of the passive constraint
              Jacobian, relative to the largest;
    output_pose: 4x4 world pose of the output link, or None;
    rates / accelerations: coordinate name -> rate [rad/s, m/s] /
              acceleration [rad/s^2, m/s^2], or None;
    output_twist / output_acceleration: (v, w) of the output frame origin in
              world axes; classical acceleration (a, alpha).
    """

    q: np.ndarray = field(repr=False)
    joints: dict
    residual: float
    iterations: int
    singular: bool
    sigma_min: float
    output_pose: np.ndarray | None = None
    rates: dict | None = None
    accelerations: dict | None = None
    output_twist: np.ndarray | None = None
    output_acceleration: np.ndarray | None = None
    qdot: np.ndarray | None = field(default=None, repr=False)
    qddot: np.ndarray | None = field(default=None, repr=False)
    outside_limits: tuple = ()  # joints whose value is outside the file's <limit> (angles compared modulo 2 pi)


@dataclass(frozen=True)
class PositionResult:
    inputs: dict
    input_joints: tuple
    solutions: tuple
    starts: int
    free_dofs: int  # DOFs the inputs leave undetermined (0 when the inputs fix the mechanism)
    trace: tuple = ()
    output: str | None = None
    angular: tuple = ()  # names of the coordinates that are angles (the others are lengths)

    def to_dict(self) -> dict:
        from .report import position_dict

        return position_dict(self)


def outside_limits(mech, q) -> tuple:
    """Joints whose value lies outside the position limits of the file."""
    table = mech.limited_coordinates()
    names, idx, lo, hi, angle = table
    if not names:
        return ()
    v = np.asarray(q)[idx]
    out = (v < lo) | (v > hi)
    if out.any():  # an angle may sit in the range modulo a turn
        k = np.ceil((lo - v) / (2 * np.pi))
        shifted = v + 2 * np.pi * k
        out &= ~(angle & (lo <= shifted) & (shifted <= hi))
    return tuple(n for n, o in zip(names, out) if o)


class PositionSolver:
    """Solves a mechanism for given input joints; reuses the model and data
    between calls (build once, solve many times)."""

    def __init__(self, mech, input_joints=None, output=None, compiled: bool | None = None):
        """compiled: True to solve the closure equations with the compiled kernels of
        screwkin.compiled (numba, ``pip install -e '.[fast]'``) when the mechanism's cut
        joints are all fixed or spherical, False for numpy, None to leave the mechanism's
        setting; ``self.compiled`` says which is used."""
        self.mech = mech
        if compiled is not None:
            mech.closure.accelerate(compiled)
        self.model = mech.model
        self.data = mech.model.createData()
        names = list(input_joints) if input_joints else list(mech.actuated)
        if not names:
            raise UsageError(f"{mech.path}: no input joints: declare actuated joints or give --set NAME=VALUE")
        for n in names:
            c = mech.coordinate(n)
            if c.nv != 1:
                raise UsageError(f"{mech.path}: joint '{n}' has {c.nv} coordinates; inputs must be 1-DOF joints")
        self.inputs = names
        self.frozen = mech.velocity_indices(names)
        self.passive = np.setdiff1d(np.arange(mech.nv), self.frozen)
        self.output = output
        self.output_frame = mech.link_frame(output) if output else None
        mob = mech.mobility()
        self.expected_rank = mob.rank
        self.idle_dofs = mob.idle_dofs
        self.mobility = mob.mobility
        # DOFs left free with the inputs held, beyond the idle ones (0 = inputs determine the mechanism)
        V = null_space(mech.closure.jacobian(mob.q), mech.tolerances, mech.nv)
        held = null_space(V[self.frozen], mech.tolerances, V.shape[1]) if V.shape[1] else np.zeros((0, 0))
        self.free_dofs = max(held.shape[1] - self.idle_dofs, 0) if V.shape[1] else 0
        self._reference = mob.q
        self._points = [f for f in range(len(self.model.frames))
                        if self.model.frames[f].type == pin.FrameType.JOINT]
        self._points += [c.frame1 for c in mech.cuts]
        self._revolute = self._angle_coordinates()
        self._angular = self.angular_names()
        # joint_values in a few array operations: (name, q index) of 1-coordinate joints, of
        # continuous joints (cos, sin), and the names of the coordinates of multi-DOF joints
        single, continuous, multi, self._order = [], [], [], []
        for c in mech.coordinates:
            if c.nq == 1:
                single.append((c.joint, c.idx_q))
                self._order.append(c.joint)
            elif c.nq == 2 and c.nv == 1:
                continuous.append((c.joint, c.idx_q))
                self._order.append(c.joint)
            else:
                multi += [(f"{c.joint}[q{k}]", c.idx_q + k) for k in range(c.nq)]
                self._order += [n for n, _ in multi[-c.nq:]]
        self._value_layout = (single, continuous, multi)
        self._single_idx = np.array([i for _, i in single], int)
        self._single_wrap = np.isin(self._single_idx, self._revolute)

    @property
    def compiled(self) -> bool:
        """Whether the closure equations are solved by the compiled kernels."""
        return self.mech.closure.accelerated

    # --------------------------------------------------------------- coordinates
    def _angle_coordinates(self):
        """q indices of bounded revolute joints (angles to wrap) and continuous joints."""
        wrap = []
        for c in self.mech.coordinates:
            short = self.model.joints[c.joint_id].shortname()
            if short.startswith("JointModelR") and "UB" not in short and c.nq == 1:
                wrap.append(c.idx_q)
        return np.asarray(wrap, int)

    def angular_names(self) -> tuple:
        """Coordinate names that are angles (revolute and continuous joints)."""
        names = []
        for c in self.mech.coordinates:
            if self.model.joints[c.joint_id].shortname().startswith("JointModelR") and c.nv == 1:
                names.append(c.joint)
        return tuple(names)

    def set_inputs(self, q, values: dict):
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
                q[c.idx_q:c.idx_q + 2] = (np.cos(v), np.sin(v))
            elif c.nq == 1:
                q[c.idx_q] = v
            else:
                raise UsageError(f"{self.mech.path}: joint '{name}' has {c.nq} coordinates: give them as "
                                 f"{name}[q0] ... {name}[q{c.nq - 1}]")
        return pin.normalize(self.model, q) if multi else q

    def joint_values(self, q) -> dict:
        """Every joint coordinate name -> value [rad or m]; angles of bounded revolute joints
        in [-pi, pi), continuous joints as atan2(sin, cos)."""
        q = np.asarray(q, float)
        single, continuous, multi = self._value_layout
        v = q[self._single_idx]
        v[self._single_wrap] = np.mod(v[self._single_wrap] + np.pi, 2 * np.pi) - np.pi
        out = dict(zip((n for n, _ in single), v.tolist()))
        for name, i in continuous:
            out[name] = float(np.arctan2(q[i + 1], q[i]))
        for name, i in multi:
            out[name] = float(q[i])
        return {n: out[n] for n in self._order}  # in the order of mech.coordinates, as reports list them

    def _wrap(self, q):
        q = np.array(q, float)
        if len(self._revolute):
            q[self._revolute] = np.mod(q[self._revolute] + np.pi, 2 * np.pi) - np.pi
        return q

    def _signature(self, q):
        """World positions of every joint centre (and the output pose): equal for
        configurations that differ only by idle spins."""
        pin.framesForwardKinematics(self.model, self.data, q)
        parts = [self.data.oMf[f].translation for f in self._points]
        if self.output_frame is not None:
            parts.append(self.data.oMf[self.output_frame].homogeneous[:3].ravel() * 0.1)
        return np.concatenate(parts) if parts else np.zeros(0)

    def _starts(self, count, seed):
        model = self.model
        rng = np.random.default_rng(seed)
        base = pin.neutral(model)
        starts = [self._reference, base]
        lo, hi = model.lowerPositionLimit, model.upperPositionLimit
        for _ in range(count):
            dq = np.zeros(model.nv)
            for c in self.mech.coordinates:
                short = model.joints[c.joint_id].shortname()
                for k in range(c.nv):
                    if "JointModelP" in short:
                        a, b = lo[c.idx_q + k], hi[c.idx_q + k]
                        a, b = (a, b) if np.isfinite(a) and np.isfinite(b) and b - a < 20 else (-0.5, 0.5)
                        dq[c.idx_v + k] = rng.uniform(a, b)
                    else:
                        dq[c.idx_v + k] = rng.uniform(-np.pi, np.pi)
            starts.append(pin.integrate(model, base, dq))
        return starts

    # --------------------------------------------------------------- solving
    def _check_inputs(self, values: dict, every: bool = True):
        unknown = [n for n in values if n not in self.inputs]
        missing = [n for n in self.inputs if n not in values] if every else []
        if unknown or missing:
            raise UsageError(f"{self.mech.path}: give a value for each input joint ({', '.join(self.inputs)})"
                             + (f"; not inputs: {', '.join(unknown)}" if unknown else ""))

    def track(self, values: dict, q) -> Assembly:
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
              accels: dict | None = None, starts: int = 24, seed: int = 0, trace: bool = False) -> PositionResult:
        mech = self.mech
        self._check_inputs(values)
        steps = []
        recorder = (lambda it, q, r, K, dq, ok: steps.append(
            TraceStep(it, r.copy(), K[:, self.passive].copy(), dq[self.passive].copy(), ok))) if trace else None
        near_q = None
        if near:
            near_q = self.set_inputs(self._reference, near)
        found, best = [], np.inf
        if near_q is not None:  # the mode reached from the given configuration, when Newton gets there
            found, best = self.distinct(mech.closure, [self.set_inputs(near_q, values)], frozen=self.frozen,
                                        first_trace=recorder if trace else None)
        start_list = [near_q] if found else ([near_q] if near_q is not None else []) + self._starts(starts, seed)
        if not found:
            found, more = self.distinct(
                mech.closure, [self.set_inputs(q0, values) for q0 in start_list], frozen=self.frozen,
                first_trace=recorder if trace and near_q is None else None)
            best = min(best, more)
        if not found:
            raise AssemblyError(mech.path, best, mech.tolerances.max_iterations,
                                detail=f"the inputs {self._describe(values)} cannot be reached from "
                                       f"{len(start_list)} starting configurations")
        if len(found) > 1:
            ref = near_q if near_q is not None else self._reference
            ref_sig = self._signature(ref)
            found = [(self._signature(q) if sig is None else sig, q, a) for sig, q, a in found]
            found.sort(key=lambda f: (len(outside_limits(mech, f[1])) > 0, float(np.linalg.norm(f[0] - ref_sig))))
        if near_q is not None:
            found = found[:1]
        sols = tuple(self._solution(q, a, rates, accels) for _, q, a in found)
        return PositionResult(dict(values), tuple(self.inputs), sols, len(start_list), self.free_dofs,
                              tuple(steps), self.output, self._angular)

    def distinct(self, system, starts, frozen=(), first_trace=None):
        """Solve ``system`` from every start; keep one solution per assembly mode.

        Returns ([(signature, q, Assembly)], smallest residual of the failures)."""
        found, best = [], np.inf
        for k, q0 in enumerate(starts):
            try:
                a = system.solve(q0, frozen=frozen, trace=first_trace if k == 0 else None)
            except AssemblyError as exc:
                best = min(best, exc.residual)
                continue
            q = self._wrap(a.q)
            if len(starts) == 1:  # nothing to tell apart
                found.append((None, q, a))
                continue
            sig = self._signature(q)
            if any(np.max(np.abs(sig - s)) < 1e-6 for s, *_ in found):
                continue
            found.append((sig, q, a))
        return found, best

    @staticmethod
    def _describe(values):
        return ", ".join(f"{k}={v:.6g}" for k, v in values.items())

    def _solution(self, q, a, rates, accels) -> Solution:
        mech, tol = self.mech, self.mech.tolerances
        K = mech.closure.jacobian(q)
        solve, s = self.passive_solver(K)
        r_star = self.expected_rank
        if r_star == 0 or s.size == 0:
            sigma, singular = 1.0, False
        else:
            sigma = float(s[r_star - 1] / s[0]) if len(s) >= r_star else 0.0
            # s_r(K) >= s_r(K_p) = sigma s_1(K_p): when that clears the rank tolerance of K
            # (bounded through the Frobenius norm), rank K >= r and no second SVD is needed
            clear = sigma * s[0] > max(tol.rank_rtol * float(np.linalg.norm(K)), tol.rank_atol)
            singular = sigma < tol.singular or (not clear and rank(K, tol) < r_star)
        pose = twist = acc = qd = qdd = None
        rate_d = acc_d = None
        if self.output_frame is not None:
            pin.framesForwardKinematics(self.model, self.data, q)
            pose = self.data.oMf[self.output_frame].homogeneous.copy()
        if rates is not None:
            qd = self.rates(q, K, rates, solve)
            rate_d = self._named(qd)
            qdd = self.accelerations(q, K, qd, accels or {}, solve)
            acc_d = self._named(qdd)
            if self.output_frame is not None:
                pin.forwardKinematics(self.model, self.data, q, qd, qdd)
                pin.updateFramePlacements(self.model, self.data)
                twist = pin.getFrameVelocity(self.model, self.data, self.output_frame, LWA).vector.copy()
                acc = pin.getFrameClassicalAcceleration(self.model, self.data, self.output_frame, LWA).vector.copy()
        return Solution(q, self.joint_values(q), a.residual, a.iterations, bool(singular), sigma, pose,
                        rate_d, acc_d, twist, acc, qd, qdd, outside_limits(mech, q))

    def _named(self, v) -> dict:
        return dict(zip(self.mech.coordinate_names, map(float, v)))

    def _input_vector(self, values: dict):
        x = np.zeros(len(self.frozen))
        for k, name in enumerate(self.inputs):
            x[k] = values.get(name, 0.0)
        return x

    def passive_solver(self, K):
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

    def rates(self, q, K, values: dict, solve=None):
        """Joint rates from K q' = 0 with the input rates given (minimum norm in
        the passive joints, so idle spins are zero).  solve: see passive_solver."""
        qd = np.zeros(self.mech.nv)
        qd[self.frozen] = self._input_vector(values)
        if K.size:
            solve = solve or self.passive_solver(K)[0]
            qd[self.passive] = -solve(K[:, self.frozen] @ qd[self.frozen])
        return qd

    def accelerations(self, q, K, qd, values: dict, solve=None):
        """Joint accelerations from K q'' = -K' q' with the input accelerations given."""
        qdd = np.zeros(self.mech.nv)
        qdd[self.frozen] = self._input_vector(values)
        if K.size:
            bias = self.mech.closure.bias(q, qd)
            solve = solve or self.passive_solver(K)[0]
            qdd[self.passive] = solve(-(K[:, self.frozen] @ qdd[self.frozen] + bias))
        return qdd


def inverse_kinematics(mech, output: str, pose, starts: int = 16, seed: int = 0) -> PositionResult:
    """Joint values (actuated and passive) that place link ``output`` at ``pose``
    (a pinocchio.SE3 in the world), for every distinct assembly found.

    The target is one more cut joint, a weld between a ground frame at ``pose``
    and the output link, solved together with the loop closures.  Raises
    AssemblyError (saying how close it got) when the pose is unreachable.
    """
    from .closure import ClosureSystem, CutJoint

    model = mech.model
    out_frame = mech.link_frame(output)
    fid = mech.target_frame  # created with the model: adding frames later would outgrow existing Data
    frame = model.frames[fid]
    frame.placement = pose
    model.frames[fid] = frame
    target = CutJoint("target", "fixed", 0, fid, out_frame, "world", output, (1.0, 0.0, 0.0))
    system = ClosureSystem(model, list(mech.cuts) + [target], mech.tolerances, mech.path)
    solver = PositionSolver(mech, mech.actuated or [mech.coordinates[0].joint], output=output)
    start_list = solver._starts(starts, seed)
    found, best = solver.distinct(system, start_list)
    found = [(sig, q, a, system.jacobian(q)) for sig, q, a in found]
    if not found:
        xyz = ", ".join(f"{x:.6g}" for x in pose.translation)
        raise AssemblyError(mech.path, best, mech.tolerances.max_iterations,
                            detail=f"the pose of '{output}' at ({xyz}) is unreachable from "
                                   f"{len(start_list)} starting configurations")
    ref = solver._signature(solver._reference)
    found.sort(key=lambda f: (len(outside_limits(mech, f[1])) > 0, float(np.linalg.norm(f[0] - ref))))
    sols = []
    for _, q, a, J in found:
        s = np.linalg.svd(J, compute_uv=False)
        needed = mech.nv - solver.idle_dofs
        sigma = float(s[needed - 1] / s[0]) if 0 < needed <= len(s) else 1.0
        pin.framesForwardKinematics(model, mech.data, q)
        sols.append(Solution(q, solver.joint_values(q), a.residual, a.iterations,
                             sigma < mech.tolerances.singular, sigma, mech.data.oMf[out_frame].homogeneous.copy(),
                             outside_limits=outside_limits(mech, q)))
    return PositionResult({"pose": pose.homogeneous.tolist()}, tuple(mech.actuated), tuple(sols), len(start_list),
                          0, (), output, solver.angular_names())
