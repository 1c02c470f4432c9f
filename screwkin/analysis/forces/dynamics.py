"""Inverse dynamics of mechanisms driven at constant input speed: what the actuators must exert
along a motion, what every joint carries, what the ground feels, and the flywheel it takes.

The motion is screwkin's sweep (analysis/motion/sweep.py) with the input rate set to the speed: the
rates are those of that speed and the accelerations those of a constant speed (the input's
acceleration is zero).  At each step, with q, v = q' and a = q'':

    E tau_a + K^T lambda = RNEA(q, v, a) - sum_k J_k^T w_k

the tree's inverse dynamics by Pinocchio's RNEA (gravity in model.gravity, the links' inertias
from the file's <inertial>) plus each joint's own dynamics as MuJoCo defines them (an MJCF joint's
armature, damping and frictionloss, per degree of freedom: armature * a, the reflected inertia of a
motor added to the mass matrix's diagonal; damping * v, the force that overcomes the viscous
passive force; frictionloss * sign(v), the dry friction overcome while the joint moves -- at rest
it lies anywhere in +-frictionloss, which the notes say), the loads w_k (force, moment at their link frame's origin, world
axes; J_k that origin's frame Jacobian, LOCAL_WORLD_ALIGNED), the loop constraint forces lambda
of the closure rows K (model/kernel/closure.py) and the actuator efforts tau_a (torques of revolute,
forces of prismatic inputs).  It is solved as statics solves it (analysis.forces.statics.balance):
least squares, minimum norm; where the constraint rows are redundant (an overconstrained
linkage, a planar loop's out-of-plane rows) the null space of [E, K^T] holds self-stresses of
the loops: the efforts stay unique, the reactions given are the minimum-norm ones, and the
components that change along that null space are named.

Reactions: the wrench each joint carries, what the parent side (link1 of a cut joint) exerts on
the child side (link2), (force, moment) at the joint's origin (F2's origin for a cut joint),
world axes (analysis.forces.statics.joint_wrenches with the motion's inertial forces).  The shaking
wrench is what the moving links exert on the ground: minus the sum of the reactions of the
joints the ground is the parent (or link1) of, plus those it is the child (link2) of, with the
moments taken about the world origin.  The flywheel: with the input effort tau(theta) over one
whole turn at mean speed omega, the energy fluctuation is
dE = max - min of the integral of (tau - tau_mean) d theta, and the flywheel inertia that keeps
the coefficient of speed fluctuation Cs = (omega_max - omega_min) / omega_mean is
I = dE / (Cs omega^2).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ...errors import MechanismFileError, UsageError, quote
from ...model.geometry import cross3
from ...model.state import KinematicState
from ...tolerances import DEFAULT
from ..position.position import PositionSolver
from .joint_dynamics import JointDynamics, joint_dynamics, left_out_note, names_text as _names
from .statics import (actuator_efforts, balance, compound_joints, coupled_efforts, coupled_units,
                      reaction_joint_id, reaction_table)
from ..motion.sweep import sweep, sweep_inputs

if TYPE_CHECKING:
    from ...model.mechanism import Mechanism
    from ..motion.sweep import SweepResult

__all__ = ["CS_RANGE", "Load", "Flywheel", "DynamicsResult", "dynamics", "check_inertias"]

#: The coefficients of speed fluctuation Cs = (omega_max - omega_min) / omega_mean the flywheel figure takes.
#: Machines ask for 0.002 (generators) to 0.2 (crushers, punches); below 1e-4 the flywheel grows past ten
#: thousand times dE / omega^2 and at --cs 1e-320 it is infinite; above 0.5 the speed swings by half its
#: mean, and efforts computed at a constant speed no longer describe the motion they would drive.
CS_RANGE = (1e-4, 0.5)

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
COMPONENTS = ("fx", "fy", "fz", "mx", "my", "mz")


@dataclass(frozen=True)
class Load:
    """A constant wrench on a link: (fx, fy, fz, mx, my, mz) [N, N m] in world axes, the force
    applied at ``point`` (in the link's frame [m]; the frame's origin when None)."""

    link: str
    wrench: tuple
    point: tuple | None = None
    name: str | None = None  # the named point it acts at, as typed


@dataclass(frozen=True)
class Flywheel:
    """The flywheel a cycle needs: energy fluctuation [J] of the input effort over one turn and
    the inertia [kg m^2] for the coefficient of speed fluctuation ``cs`` at mean speed ``omega``
    [rad/s]; inertia None (with ``reason``) where it is not defined."""

    cs: float
    omega: float
    energy_fluctuation: float | None
    inertia: float | None
    reason: str | None = None


@dataclass(frozen=True)
class DynamicsResult:
    input: str
    unit: str  # "rad" or "m": the input's unit
    speed: float  # the input's constant speed [rad/s or m/s]
    values: np.ndarray  # (n,) input values [rad or m]
    q: np.ndarray  # (n, nq)
    rates: np.ndarray  # (n, nv)
    accelerations: np.ndarray  # (n, nv)
    inputs: tuple  # the actuated joints whose efforts are given
    efforts: dict  # joint -> (n,) [N m or N]; nan where redundant actuation leaves it open
    effort_units: dict  # joint -> "N m" or "N"
    reactions: dict  # joint -> (n, 6) (force [N], moment [N m]) at the joint's origin, world axes
    reaction_kinds: dict  # joint -> "tree" or "cut"
    open_components: dict  # joint -> components ("fx", ...) not determined (minimum-norm values given)
    indeterminate: int  # dimension of the null space of [E, K^T] (largest along the motion)
    shaking_force: np.ndarray  # (n, 3) what the moving links exert on the ground [N]
    shaking_moment: np.ndarray  # (n, 3) its moment about the world origin [N m]
    kinetic_energy: np.ndarray  # (n,) [J]
    potential_energy: np.ndarray  # (n,) of gravity (zero reference at the world origin) and of the joints' springs [J]
    input_power: np.ndarray  # (n,) sum of actuator effort x rate [W]
    load_power: np.ndarray  # (n,) power of the loads [W]
    unbalanced: np.ndarray  # (n,) |E tau + K^T lambda - b|: what the inputs cannot drive
    peak: dict  # joint -> max |effort|
    mean: dict  # joint -> mean effort over the input range
    rms: dict  # joint -> root mean square effort over the input range
    flywheel: Flywheel
    gravity: tuple  # [m/s^2]
    loads: tuple  # Load
    completed: bool  # the motion covered the whole range
    notes: tuple  # one line each: what was chosen, what is left open
    actuator_efforts: dict = field(default_factory=dict)  # actuator -> (n,) through its tendon, coupling, gear
    coupled_efforts: dict = field(default_factory=dict)  # coupled joint -> (n,) the effort its coupling exerts
    transmissions: tuple = ()  # files.description.Transmission of those actuators


def check_inertias(mech: Mechanism) -> tuple:
    """Each moving body needs a mass and an inertia a rigid body can have (files/inertia.py: a link
    breaking it is a MechanismFileError naming it), and an SDF file's inertias are not read (refused): a moving
    link without <inertial> on a body none of whose links has one is a MechanismFileError naming
    it, except a link with no geometry either (the inside of a compound joint), taken as massless
    and returned, named, in a note."""
    if mech.spec.format == "sdf":  # files/sdf.py keeps each link's mass only, at its origin
        raise MechanismFileError(mech.path, "dynamics needs the links' inertias, and screwkin reads only the masses of "
                                            "an SDF file (not their <pose> and <inertia>): write it as URDF")
    model = mech.model
    bodies = {}
    for name, link in mech.spec.links.items():
        try:
            fid = mech.link_frame(name)
        except UsageError:
            continue
        bodies.setdefault(model.frames[fid].parentJoint, []).append(link)
    virtual = {n for names in mech.virtual_joints.values() for n in names}
    massless = []
    for joint, links in bodies.items():
        if joint == 0 or model.names[joint] in virtual:
            continue
        impossible = [x for x in links if x.inertia_problem]
        if impossible:  # (the file loads for kinematics with a warning; a dynamics computed with it is no body's)
            raise MechanismFileError(mech.path, f"link {quote(impossible[0].name)} moves and has "
                                                f"{impossible[0].inertia_problem}, which no rigid body has: dynamics needs a body's")
        if any(x.mass is not None for x in links):
            continue
        with_geometry = [x.name for x in links if x.has_geometry]
        if with_geometry:
            raise MechanismFileError(mech.path, f"link {quote(with_geometry[0])} moves but has no <inertial> "
                                                "(mass and inertia): dynamics needs one on every moving link")
        massless += [x.name for x in links]
    if massless:
        return (f"taken as massless (no <inertial>, no geometry: the inside of a compound joint): "
                f"{', '.join(massless)}",)
    return ()


def _load_wrenches(mech: Mechanism, loads, state: KinematicState) -> list:
    """(frame id, wrench at the frame's origin, world axes) of each load at the configuration of
    ``state`` (a KinematicState; the force at a point moved to the frame's origin: m_o = m + (p - o) x f)."""
    out = []
    for ld in loads:
        fid = mech.link_frame(ld.link)
        w = np.asarray(ld.wrench, float)
        if ld.point is not None:
            arm = state.frame_placement(fid).rotation @ np.asarray(ld.point, float)
            w = np.r_[w[:3], w[3:] + np.cross(arm, w[:3])]
        out.append((fid, w))
    return out


def _ground_sides(mech: Mechanism) -> tuple:
    """(tree joints whose parent is the ground, {cut joint: +1 when its link2 is on the ground,
    -1 when its link1 is})."""
    model = mech.model
    compounds = compound_joints(mech)
    inside = {m: name for name, members in compounds.items() for m in members}
    # (a compound joint's row is named as mobility names it; its member next to the parent is the one on the ground)
    tree = {inside.get(c.joint, c.joint) for c in mech.coordinates if model.parents[c.joint_id] == 0}
    tree |= {c.joint for c in mech.couplings if model.parents[model.getJointId(c.joint)] == 0}
    cuts = {}
    for cut in mech.cuts:
        on1 = model.frames[cut.frame1].parentJoint == 0
        on2 = model.frames[cut.frame2].parentJoint == 0
        if on2 and not on1:
            cuts[cut.name] = 1.0
        elif on1 and not on2:
            cuts[cut.name] = -1.0
    return tree, cuts


def _energies(mech: Mechanism, gmodel: pin.Model, data: pin.Data, q: np.ndarray, v: np.ndarray) -> tuple:
    """(kinetic, potential) energy [J] at (q, v): Pinocchio's; with couplings (mimic joints, which its
    energy algorithms refuse) 1/2 v^T M v from its CRBA and -sum m g . c over the bodies."""
    model = mech.model
    if not mech.couplings:
        return pin.computeKineticEnergy(model, data, q, v), pin.computePotentialEnergy(gmodel, data, q)
    M = pin.crba(model, data, q)  # the upper triangle
    M = np.triu(M) + np.triu(M, 1).T
    pin.forwardKinematics(model, data, q)
    g = gmodel.gravity.linear
    V = -sum(model.inertias[j].mass * float(g @ data.oMi[j].act(model.inertias[j].lever)) for j in range(1, model.njoints))
    return 0.5 * float(v @ M @ v), float(V)


def _flywheel(values: np.ndarray, tau: np.ndarray, speed: float, unit: str, cs: float, completed: bool) -> Flywheel:
    """The flywheel figure from the input effort tau over the input values (see the module)."""
    omega = abs(speed)
    span = abs(values[-1] - values[0]) if len(values) > 1 else 0.0
    if unit != "rad":
        return Flywheel(cs, omega, None, None, "a flywheel needs a turning input (this one slides)")
    if not completed or span < 2 * np.pi * (1 - DEFAULT.equal):
        return Flywheel(cs, omega, None, None, "a flywheel needs the input over a whole turn (--from 0 --to 360deg)")
    if tau is None or not np.all(np.isfinite(tau)):
        return Flywheel(cs, omega, None, None, "the input effort is not determined")
    x = values - values[0]
    work = np.r_[0.0, np.cumsum(0.5 * (tau[1:] + tau[:-1]) * np.diff(x))]  # integral of tau d theta
    mean = work[-1] / x[-1]
    excess = work - mean * x
    de = float(excess.max() - excess.min())
    if omega * omega == 0:  # (a speed below 1e-154 rad/s squares to zero in double precision)
        return Flywheel(cs, omega, de, None, "at zero speed no flywheel smooths anything")
    return Flywheel(cs, omega, de, de / (cs * omega**2))


def _range_mean(values: np.ndarray, y: np.ndarray) -> float:
    """The mean of y over the input range (trapezoid rule: a sample at each end of a whole
    turn counts once); the plain mean for a single value."""
    if len(values) < 2 or values[-1] == values[0]:
        return float(np.mean(y))
    return float(np.trapezoid(y, values) / (values[-1] - values[0]))


def _joint_notes(mech: Mechanism) -> tuple[list[str], JointDynamics]:
    """(the notes on the inertias and on the joints' own dynamics, those dynamics or None)."""
    notes = list(check_inertias(mech))
    own, left = joint_dynamics(mech)
    if own:
        notes.append(f"the armature, damping and friction loss the file gives {len(own)} joints ("
                     f"{_names(list(own))}) are in these efforts, as MuJoCo applies them (per degree of freedom: "
                     "armature * a + damping * v + frictionloss * sign(v)"
                     + (f"; the springs of {_names(list(own.springs))}: stiffness * (x - springref), their energy in "
                        "the potential energy" if own.springs else "") + ")")
    if left:
        notes.append(left_out_note(left))
    return notes, own


class _Series:
    """The balance at every step of a motion, gathered step by step (:meth:`step`)."""

    def __init__(self, mech: Mechanism, inputs: list[str], own: JointDynamics, loads: Iterable[Load],
                 g: np.ndarray, n: int) -> None:
        self.mech, self.own, self.loads, self.g = mech, own, loads, g
        self.data = mech.scratch_data()
        self.a_idx = mech.velocity_indices(inputs)
        m = self.m = len(self.a_idx)
        self.n = n
        self.efforts = np.full((n, m), np.nan)
        self.reactions: dict[str, np.ndarray] = {}
        self.kinds: dict[str, str] = {}
        self.open_: dict[str, np.ndarray] = {}
        self.coupled: dict[str, np.ndarray] = {}
        self.shaking_f, self.shaking_m = np.zeros((n, 3)), np.zeros((n, 3))
        self.T, self.V, self.P_in, self.P_load, self.unbalanced, self.scale = (np.zeros(n) for _ in range(6))
        self.indeterminate = 0
        self.friction_at_rest: set[str] = set()
        self.ground_tree, self.ground_cuts = _ground_sides(mech)
        self.gmodel = mech.model_with_gravity(g)  # the model with this gravity (RNEA and the potential energy read it)

    def step(self, k: int, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        """Step ``k``'s balance at (q, v, a): the efforts, the reactions, the shaking wrench, energies and powers."""
        mech, own, m, n = self.mech, self.own, self.m, self.n
        b = pin.rnea(self.gmodel, self.data, q, v, a).copy()
        own_coupled = {}
        if own:
            joint_force, own_coupled = own.forces(q, v, a)
            b += joint_force
            self.friction_at_rest |= own.friction_at_rest(v)
        state = KinematicState(mech, q)
        frames = _load_wrenches(mech, self.loads, state)
        for fid, w in frames:
            J = state.frame_jacobian(fid, LWA)
            b -= J.T @ w
            self.P_load[k] += float(w @ (J @ v))
        K = mech.closure.jacobian(q)
        tau, lam, N, self.unbalanced[k], self.scale[k] = balance(mech, K, self.a_idx, b)
        free_tau = np.linalg.norm(N[:m], axis=1) if N.size else np.zeros(m)
        self.efforts[k] = np.where(free_tau > mech.tolerances.indeterminate, np.nan, tau)
        self.indeterminate = max(self.indeterminate, int(N.shape[1]) if N.size else 0)
        table = reaction_table(mech, q, lam, frames, self.g, N[m:] if N.size else None, v, a)
        for name, value in coupled_efforts(mech, q, {k: x[1] for k, x in table.items() if x[0] == "coupled"}).items():
            self.coupled.setdefault(name, np.zeros(n))[k] = value + own_coupled.get(name, 0.0)
        for name, (kind, wrench, is_open) in table.items():
            self.reactions.setdefault(name, np.zeros((n, 6)))[k] = wrench
            self.kinds[name] = kind
            self.open_[name] = self.open_.get(name, np.zeros(6, bool)) | is_open
        self._shaking(k, table, state)
        self.T[k], self.V[k] = _energies(mech, self.gmodel, self.data, q, v)
        if own:
            self.T[k] += own.kinetic(v)
            self.V[k] += own.potential(q)
        self.P_in[k] = float(np.nan_to_num(self.efforts[k]) @ v[self.a_idx])

    def _shaking(self, k: int, table: dict, state: KinematicState) -> None:
        """Step ``k``'s shaking wrench: the reactions of the joints at the ground, moments about the world origin."""
        for name, (kind, wrench, _) in table.items():
            if kind in ("tree", "coupled") and name in self.ground_tree:
                jid = self.mech.model.getJointId(name) if kind == "coupled" else reaction_joint_id(self.mech, name)
                sign, origin = -1.0, state.centre(("joint", jid))
            elif kind == "cut" and name in self.ground_cuts:
                cut = next(c for c in self.mech.cuts if c.name == name)
                sign, origin = self.ground_cuts[name], state.centre(("frame", cut.frame2))
            else:
                continue
            self.shaking_f[k] += sign * wrench[:3]
            self.shaking_m[k] += sign * (wrench[3:] + cross3(origin, wrench[:3]))


def _motion_notes(s: _Series, input: str, res: SweepResult, peak: dict[str, float | None],
                  open_names: dict[str, tuple[str, ...]]) -> list[str]:
    """What the figures along the motion leave undetermined or out, and where the inputs cannot drive it."""
    notes = []
    if s.friction_at_rest:
        notes.append(f"where {_names(sorted(s.friction_at_rest))} stand still the dry friction lies anywhere in "
                     "+-frictionloss: the efforts there take it as 0")
    if not np.any(s.g):
        notes.append("gravity: none (give --gravity 0,0,-9.81 for the links' weights)")
    if s.indeterminate:
        varying = "; ".join(f"{name} {' '.join(c)}" for name, c in open_names.items() if c)
        notes.append(f"the loop constraints are redundant: the balance has a null space of dimension "
                     f"{s.indeterminate} (self-stresses of the loops); the efforts are unique where given, the "
                     f"reactions are the minimum-norm ones" + (f", these components are not determined: {varying}"
                                                                if varying else ""))
    if any(v is None for v in peak.values()):
        notes.append("redundant actuation: the efforts marked nan are not determined (minimum-norm split not given)")
    if res.stopped_at is not None:
        notes.append(f"the motion stopped at {input} = {res.stopped_at:.6g} {res.unit}: {res.stop_reason}")
    if res.skipped:
        notes.append(f"{len(res.skipped)} input value(s) of the grid could not be solved and are left out")
    stuck = s.unbalanced > s.mech.tolerances.balanced * s.scale
    if np.any(stuck):
        notes.append(f"at {int(np.sum(stuck))} step(s) the inputs cannot drive the motion "
                     f"(largest unbalanced generalized force {s.unbalanced.max():.3g}): near a singularity")
    return notes


def dynamics(mech: Mechanism, input: str, speed: float, start: float, stop: float, steps: int,
             inputs: Iterable[str] | None = None, fixed: dict | None = None, near: dict | None = None,
             gravity: Iterable[float] = (0.0, 0.0, 0.0), loads: Iterable[Load] = (), cs: float = 0.05,
             progress: Callable[[int, int], object] | None = None, q_start: Callable | None=None,
             branch: str = "continue") -> DynamicsResult:
    """Inverse dynamics along the motion of input ``input`` from ``start`` to ``stop`` [rad or m]
    in ``steps`` steps at the constant ``speed`` [rad/s or m/s] (see the module docstring).

    inputs: the actuated joints (default: the mechanism's actuated joints when ``input`` is one
    of them, else ``input`` and the joints of ``fixed``); fixed: the other inputs' values;
    gravity: (gx, gy, gz) [m/s^2]; loads: Load; cs: the coefficient of speed fluctuation of the
    flywheel figure (within CS_RANGE); progress: a callable ``progress(done, total)`` told of the
    configurations analysed (None: not told); q_start: a configuration of the assembly mode to follow (as sweep's;
    without it the mode is solve's first at ``start``, near ``near``)."""
    lo, hi = CS_RANGE
    if not lo <= cs <= hi:  # nan fails both
        raise UsageError(f"the coefficient of speed fluctuation must lie between {lo:g} and {hi:g}, got {cs:g}")
    g = np.asarray(gravity, float)
    if g.shape != (3,) or not np.all(np.isfinite(g)):
        raise UsageError("gravity must be 3 finite numbers gx, gy, gz [m/s^2]")
    notes, own = _joint_notes(mech)
    fixed = dict(fixed or {})
    inputs = sweep_inputs(mech, input, fixed) if inputs is None else list(inputs)
    for ld in loads:
        mech.link_frame(ld.link)  # a clear error for an unknown link
    solver = PositionSolver(mech, inputs)
    res = sweep(solver, input, start, stop, steps, fixed={k: v for k, v in fixed.items() if k != input},
                near=None if q_start is not None else near, rate=speed, q_start=q_start, branch=branch)
    notes += res.change_point_notes  # the change points passed, and the branch taken at each
    n = len(res.values)
    s = _Series(mech, inputs, own, loads, g, n)
    for k in range(n):
        if progress is not None:
            progress(k, n)
        s.step(k, res.q[k], res.rates[k], res.accelerations[k])
    units = {name: "N" if mech.translational[iv] else "N m" for name, iv in zip(inputs, s.a_idx)}
    units.update(coupled_units(mech))
    eff = {name: s.efforts[:, j] for j, name in enumerate(inputs)}
    peak = {name: float(np.max(np.abs(y))) if np.all(np.isfinite(y)) else None for name, y in eff.items()}
    rms = {name: float(np.sqrt(_range_mean(res.values, y**2))) if np.all(np.isfinite(y)) else None
           for name, y in eff.items()}
    mean = {name: _range_mean(res.values, y) if np.all(np.isfinite(y)) else None for name, y in eff.items()}
    completed = res.completed
    fly = _flywheel(res.values, eff.get(input), speed, res.unit, cs, completed)
    open_names = {name: tuple(c for c, o in zip(COMPONENTS, mask) if o) for name, mask in s.open_.items()}
    notes += _motion_notes(s, input, res, peak, open_names)
    return DynamicsResult(input, res.unit, float(speed), res.values, res.q, res.rates, res.accelerations,
                          tuple(inputs), eff, units, s.reactions, s.kinds, open_names, s.indeterminate, s.shaking_f,
                          s.shaking_m, s.T, s.V, s.P_in, s.P_load, s.unbalanced, peak, mean, rms, fly,
                          tuple(map(float, g)), tuple(loads), completed, tuple(notes),
                          {k: np.asarray(v, float) for k, v in actuator_efforts(mech, inputs, eff).items()},
                          s.coupled, mech.transmissions(inputs))
