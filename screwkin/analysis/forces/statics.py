"""Statics of mechanisms: what the actuators must exert to hold a load, what the joints carry,
and the wrenches that legs transmit and impose.

Equilibrium at an assembled configuration q (virtual work through the closure equations):

    E_a tau_a + K^T lambda = g(q) - J_o^T w

with tau_a the actuator efforts (torques of revolute, forces of prismatic actuators), lambda
the constraint forces of the loop-closure rows, g(q) Pinocchio's generalized gravity (with
``gravity``), w the wrench (force, moment) applied to the output link at its frame's origin,
world axes, and J_o that origin's frame Jacobian (LOCAL_WORLD_ALIGNED).  The system is solved
in the least-squares sense by SVD; a residual means the inputs cannot hold the load.  Where
the system has a null space (redundant constraints of an overconstrained linkage, redundant
actuation), the quantities that change along it are statically indeterminate: they are
reported as such, not as a number.

Joint reactions: the wrench each tree joint transmits comes from Pinocchio's RNEA with the
load and the constraint forces applied as external forces (its joint torques must then be the
actuator efforts and zero elsewhere: checked); a cut joint carries its rows' constraint
wrenches (ClosureSystem.row_wrenches).

Legs of a parallel mechanism: the constraint wrenches of a leg are the wrenches reciprocal to
every platform twist the leg alone allows; its transmission wrenches are those reciprocal to
the twists it allows with its actuated joints free but not to the ones with them locked,
i.e. what a locked actuator transmits.  The platform's twist space is reciprocal to all legs'
constraint wrenches together.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ...errors import UsageError
from ...model.geometry import cross3
from ...model.linalg import null_space, rank
from ...model.state import KinematicState, frame_parent
from ..screws import Screw, cut_twists, screw_of
from ..singular import Generic, measures
from .joint_dynamics import joint_dynamics, left_out_note, names_text
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.model.cuts import CutJoint

__all__ = ["Reaction", "StaticsResult", "Leg", "statics", "legs", "wrench_screw", "balance", "joint_wrenches",
           "reaction_table", "coupled_efforts", "coupled_units", "actuator_efforts", "compound_joints",
           "reaction_joint_id", "no_legs_reason"]

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class Reaction:
    """The wrench a joint carries: what the parent side (link1 of a cut joint) exerts on the
    child side (link2), (fx, fy, fz, mx, my, mz) [N, N m] at the joint's origin in world axes;
    each component that statics does not determine is None (a planar linkage's out-of-plane
    components, the redundant ones of an overconstrained linkage)."""

    joint: str
    kind: str  # "tree" or "cut"
    wrench: tuple
    determinate: bool  # every component determined


@dataclass(frozen=True)
class StaticsResult:
    inputs: tuple  # the actuated joints, in order
    efforts: dict  # actuated joint -> effort [N m or N], None where indeterminate
    units: dict  # actuated joint -> "N m" or "N"
    wrench: tuple  # the applied wrench (force, moment) at the output frame's origin, world axes
    output: str | None
    gravity: bool
    equilibrium: bool  # the inputs can hold the load
    unbalanced: float  # |A x - b|, the generalized force the inputs cannot balance [N, N m]
    reactions: tuple  # Reaction
    indeterminate: int  # dimension of the statically indeterminate part (redundant constraints and inputs)
    singular: bool  # near an actuator singularity: efforts grow without bound
    sigma_actuator: float  # the actuator measure (screwkin.analysis.singular.measures)
    amplification: float | None  # |efforts| / |load| with lengths made dimensionless by L (N m both)
    length: float  # the characteristic length L [m]
    constraint_forces: tuple  # (row label, lambda) of the closure rows
    actuator_efforts: dict = field(default_factory=dict)  # actuator -> effort through its tendon, coupling, gear
    coupled_efforts: dict = field(default_factory=dict)  # coupled joint -> the effort its coupling exerts
    transmissions: tuple = ()  # files.description.Transmission of those actuators
    springs: dict = field(default_factory=dict)  # spring joint -> the force it exerts at q [N m or N] (-k (x - ref))
    notes: tuple = ()  # one line each: what the balance holds and what it takes as 0


def _load_norm(w: np.ndarray, L: float) -> float:
    return float(np.linalg.norm(np.r_[np.asarray(w[:3]) * L, w[3:]]))


def balance(mech: Mechanism, K: np.ndarray, a_idx: np.ndarray, b: np.ndarray) -> tuple:
    """The balance of generalized forces E tau + K^T lambda = b (E: the columns of the actuated
    velocity indices ``a_idx``; K: the closure Jacobian, rows as ClosureSystem writes them; b:
    the generalized force the tree needs [N, N m]), solved in the least-squares, minimum-norm
    sense by SVD with screwkin's rank tolerance.  Returns (tau, lambda, N, unbalanced, scale):
    N (unknowns x dim) spans the null space of [E, K^T] (what the balance leaves open: redundant
    constraint rows, redundant actuation), unbalanced = |[E, K^T] x - b|, scale the size of the
    system (for a relative test of unbalanced)."""
    tol = mech.tolerances
    nv = mech.nv
    E = np.zeros((nv, len(a_idx)))
    E[a_idx, np.arange(len(a_idx))] = 1.0
    A = np.hstack([E, K.T]) if K.size else E
    U, s, Vt = np.linalg.svd(A, full_matrices=True) if A.size else (np.eye(nv), np.zeros(0), np.eye(0))
    r = int(np.sum(s > max(tol.rank_rtol * (s[0] if s.size else 0), tol.rank_atol))) if s.size else 0
    x = Vt[:r].T @ ((U[:, :r].T @ b) / s[:r]) if r else np.zeros(A.shape[1])
    N = Vt[r:].T  # (unknowns, dim null)
    unbalanced = float(np.linalg.norm(A @ x - b))
    scale = max(float(np.linalg.norm(b)), float(np.abs(A).max()) if A.size else 1.0, 1e-12)
    m = len(a_idx)
    return x[:m], x[m:], N, unbalanced, scale


def statics(mech: Mechanism, q: np.ndarray, inputs: list | None=None, output: str | None=None, wrench: list | np.ndarray | None=None, gravity: bool = False) -> StaticsResult:
    """Actuator efforts and joint reactions holding ``wrench`` (force, moment) [N, N m] applied to
    ``output`` at its frame's origin (world axes) and, with ``gravity``, the links' weights,
    at the assembled configuration q.  See the module docstring."""
    model, tol = mech.model, mech.tolerances
    data = mech.scratch_data()
    inputs = list(mech.actuated if inputs is None else inputs)
    if wrench is not None and output is None:
        raise UsageError(f"{mech.path}: a wrench needs the output link it is applied to (--output)")
    w = np.zeros(6) if wrench is None else np.asarray(wrench, float)
    if w.shape != (6,) or not np.all(np.isfinite(w)):
        raise UsageError("the wrench must be 6 finite numbers: fx fy fz mx my mz")
    a_idx = mech.velocity_indices(inputs)
    nv = mech.nv
    K = mech.closure.jacobian(q)
    b = np.zeros(nv)
    if gravity:
        b += pin.computeGeneralizedGravity(model, data, q)
    own, left = joint_dynamics(mech)
    notes = [left_out_note(left)] if left else []
    springs, own_coupled = {}, {}
    if own.springs:  # at rest: only the springs of the joints' own dynamics act (v = a = 0)
        joint_force, own_coupled = own.forces(q, np.zeros(nv), np.zeros(nv))
        b += joint_force
        springs = {n: -own.springs[n][1] * x for n, x in own.spring_stretch(q).items()}
        notes.append(f"the springs of {names_text(list(springs))} (the file's stiffness and springref) are in the balance")
    if any(own.frictionloss) or any(j.frictionloss for _, _, j in own.coupled.values()):
        notes.append("the joints' dry friction (frictionloss) is taken as 0: at rest it lies anywhere within "
                     "+-frictionloss, so these efforts hold the load with no help from friction")
    J_o = None
    if output is not None:
        J_o = KinematicState(mech, q).link_jacobian(output, LWA)
        b -= J_o.T @ w
    tau, lam, N, unbalanced, scale = balance(mech, K, a_idx, b)
    m = len(a_idx)
    free_tau = np.linalg.norm(N[:m], axis=1) if N.size else np.zeros(m)
    efforts, units = {}, {}
    for k, (name, iv) in enumerate(zip(inputs, a_idx)):
        efforts[name] = None if free_tau[k] > tol.indeterminate else float(tau[k])
        units[name] = "N" if mech.translational[iv] else "N m"
    units.update(coupled_units(mech))
    units.update({n: "N" if mech.translational[own.springs[n][0]] else "N m" for n in springs})
    reactions = _reactions(mech, q, lam, w if output is not None else None, output, gravity, N[m:] if N.size else None)
    L = mech.length
    g = Generic(mech, inputs, None, configurations=mech.generic_configurations()[1])
    sig = measures(mech, q, g)["actuator"] if inputs else 1.0
    load = _load_norm(w, L) + (float(np.linalg.norm(pin.computeGeneralizedGravity(model, data, q))) if gravity else 0.0)
    scaled_tau = [abs(t) * (L if mech.translational[iv] else 1.0) for t, iv in zip(tau, a_idx)]
    amp = float(np.linalg.norm(scaled_tau) / load) if load > 0 and m else None
    labels = mech.closure.row_labels()
    coupled = coupled_efforts(mech, q, {x.joint: [v or 0.0 for v in x.wrench] for x in reactions
                                        if x.kind == "coupled"})
    for name, f in own_coupled.items():  # a coupled joint's spring
        coupled[name] = coupled.get(name, 0.0) + f
    return StaticsResult(tuple(inputs), efforts, units, tuple(w.tolist()), output, gravity,
                         unbalanced <= tol.balanced * scale, unbalanced, reactions, int(N.shape[1]) if N.size else 0,
                         bool(inputs) and sig < tol.singular, float(sig), amp, L,
                         tuple(zip(labels, map(float, lam))), actuator_efforts(mech, inputs, efforts), coupled,
                         mech.transmissions(inputs), springs, tuple(notes))


def _reactions(mech: Mechanism, q: np.ndarray, lam: np.ndarray, w: np.ndarray | None, output: str | None, gravity: bool, N_lam: np.ndarray | None) -> tuple:
    """Reactions of every joint for constraint forces lam (and the load), and whether each is
    determined: it must not change along the null directions N_lam of the constraint forces."""
    loads = [(mech.link_frame(output), np.asarray(w, float))] if w is not None else []
    out = []
    for name, (kind, wrench, open_) in reaction_table(mech, q, lam, loads, gravity, N_lam).items():
        out.append(Reaction(name, kind, tuple(None if o else float(x) for x, o in zip(wrench, open_)),
                            not open_.any()))
    return tuple(out)


def reaction_table(mech: Mechanism, q: np.ndarray, lam: np.ndarray, loads: list, gravity: bool | np.ndarray, N_lam: np.ndarray, v: np.ndarray | None = None, a: np.ndarray | None = None) -> dict:
    """joint name -> (kind, wrench, open): the reaction of every joint (see joint_wrenches) for
    constraint forces lam, and the mask of its components that change along the null
    directions N_lam of the constraint forces (not determined by the balance)."""
    rows = mech.closure.row_wrenches(q), mech.closure.row_labels()  # the same at q for every call below
    base = joint_wrenches(mech, q, lam, loads, gravity, v, a, rows=rows)
    free = {name: np.zeros(6) for name in base}
    if N_lam is not None and N_lam.size:
        for k in range(N_lam.shape[1]):
            for name, value in joint_wrenches(mech, q, N_lam[:, k], (), False, rows=rows).items():
                free[name] = np.maximum(free[name], np.abs(value[1]))
    size = max([float(np.linalg.norm(x[1])) for x in base.values()] + [1.0])
    # components that change along the indeterminate directions
    return {name: (kind, wrench, free[name] > mech.tolerances.indeterminate * size) for name, (kind, wrench) in base.items()}


def joint_wrenches(mech: Mechanism, q: np.ndarray, lam: np.ndarray, loads: list | tuple=(), gravity: bool=False, v: np.ndarray | None = None, a: np.ndarray | None = None, rows: tuple | None = None) -> dict:
    """joint name -> (kind, wrench at its origin in world axes) for constraint forces lam, the
    ``loads`` ((frame id, wrench (force, moment) at the frame's origin, world axes) each), the
    links' weights with ``gravity`` (True: model.gravity; or a vector (gx, gy, gz)) and, with v and a, the motion's inertial
    forces (Pinocchio's RNEA at (q, v, a)): what the parent side (link1 of a cut joint) exerts
    on the child side (link2).  ``rows``: (closure.row_wrenches(q), closure.row_labels()) when the
    caller has them (reaction_table: the same for every call at q)."""
    model = mech.model
    state = KinematicState(mech, q)
    rows, labels = rows if rows is not None else (mech.closure.row_wrenches(q), mech.closure.row_labels())
    fext = [pin.Force.Zero() for _ in range(model.njoints)]

    placed = {}  # frame -> (its body's joint, that joint's placement, the frame's origin): read once

    def apply(frame: int, wrench_at_origin: np.ndarray) -> None:
        """Add a wrench (force, moment about the frame's origin, world axes) to the frame's body."""
        if frame not in placed:
            joint = frame_parent(mech, frame)[0]
            placed[frame] = (joint, state.joint_placement(joint), state.frame_placement(frame).translation.copy())
        joint, M, o = placed[frame]
        force, moment = wrench_at_origin[:3], wrench_at_origin[3:] + cross3(o, wrench_at_origin[:3])
        fext[joint] += M.actInv(pin.Force(force, moment))

    cut = {}
    for (fa, wa, fb, wb), value in zip(rows, lam):
        if fa is None:
            continue
        apply(fa, wa * value)
        apply(fb, wb * value)
    for frame, wrench in loads:  # the loads, each on its link
        apply(frame, np.asarray(wrench, float))
    # each cut joint: the wrench its rows exert on link2, at F2's origin
    for (fa, wa, fb, wb), value, label in zip(rows, lam, labels):
        if fa is None:
            continue
        name = label.split(":", 1)[0]
        total = cut.setdefault(name, [fb, np.zeros(6)])
        if fb == total[0]:  # (a contact row may name its frames the other way round)
            total[1] = total[1] + wb * value
        elif fa == total[0]:
            total[1] = total[1] + wa * value
    zero_v = np.zeros(model.nv)
    g = model.gravity.linear if gravity is True else np.zeros(3) if gravity is False else np.asarray(gravity, float)
    data = mech.scratch_data()  # RNEA's own Data: the forces each joint transmits, read below
    pin.rnea(mech.model_with_gravity(g), data, q, zero_v if v is None else v, zero_v if a is None else a, fext)
    virtual = {n for names in mech.virtual_joints.values() for n in names}
    compounds = compound_joints(mech)
    inside = {m: name for name, members in compounds.items() for m in members}
    out = {}
    for c in mech.coordinates:
        if c.joint in virtual or (c.joint in inside and c.joint != compounds[inside[c.joint]][0]):
            continue
        jid = c.joint_id
        f = data.f[jid]  # transmitted from the parent into joint jid's body, in the joint frame
        M = state.joint_placement(jid)
        # a compound joint (three revolutes through massless links: a ball joint) is one row, named as mobility
        # names it: the wrench its member next to the parent link transmits
        out[inside.get(c.joint, c.joint)] = ("tree", np.r_[M.rotation @ f.linear, M.rotation @ f.angular])
    for cp in mech.couplings:  # a coupled joint carries its reaction too; its effort: coupled_efforts
        jid = model.getJointId(cp.joint)
        f, M = data.f[jid], state.joint_placement(jid)
        out[cp.joint] = ("coupled", np.r_[M.rotation @ f.linear, M.rotation @ f.angular])
    for name, (_frame, wrench) in cut.items():
        out[name] = ("cut", wrench)
    return out


def coupled_efforts(mech: Mechanism, q: np.ndarray, reactions: dict) -> dict:
    """Coupled joint -> the effort [N m or N] its coupling exerts along it: the component along the
    joint's axis (world axes at q) of its reaction, moment for a revolute, force for a prismatic
    joint.  ``reactions``: joint -> wrench (force, moment) at the joint's origin, world axes."""
    if not mech.couplings:
        return {}
    state = KinematicState(mech, q)
    spec = {j.name: j for j in mech.spec.joints}
    out = {}
    for cp in mech.couplings:
        j = spec[cp.joint]
        axis = state.joint_placement(mech.model.getJointId(cp.joint)).rotation @ (np.asarray(j.axis, float) /
                                                                      np.linalg.norm(j.axis))
        w = np.asarray(reactions[cp.joint], float)
        out[cp.joint] = float(axis @ (w[:3] if j.type == "prismatic" else w[3:]))
    return out


def coupled_units(mech: Mechanism) -> dict:
    """Coupled joint -> the unit of its effort: "N" for a prismatic joint, "N m" for a revolute one."""
    kinds = {j.name: j.type for j in mech.spec.joints}
    return {cp.joint: "N" if kinds.get(cp.joint) == "prismatic" else "N m" for cp in mech.couplings}


def actuator_efforts(mech: Mechanism, inputs: list, efforts: dict) -> dict:
    """Actuator name -> its effort: the input joint's generalized force / (scale * gear) of each input
    the file drives through a tendon, a coupled joint or a gear (files.description.Transmission); None
    where the joint's effort is undetermined."""
    out = {}
    for t in mech.transmissions(inputs):
        e = efforts.get(t.joint)
        out[t.actuator] = None if e is None else e / (t.scale * t.gear)
    return out


def compound_joints(mech: Mechanism) -> dict:
    """Compound joint name as mobility names it (``rod1a_top[S]``: model.topology) -> its tree members, the one
    next to the parent link first (the joint whose origin its reaction is given at); cached on the mechanism.
    Compounds through a cut joint are left out (their members are reported as they are)."""
    if "compound_joints" not in mech.cache:
        model, names = mech.model, set(mech.coordinate_names)
        found = {}
        for j in mech.topology().joints:
            if len(j.members) > 1 and not j.cut and all(m in names for m in j.members):
                found[j.name] = tuple(sorted(j.members, key=lambda m: len(model.supports[mech.coordinate(m).joint_id])))
        mech.cache["compound_joints"] = found
    return mech.cache["compound_joints"]


def reaction_joint_id(mech: Mechanism, name: str) -> int:
    """The tree joint at whose origin a tree reaction row (a joint, or a compound joint) is given."""
    members = compound_joints(mech).get(name)
    return mech.coordinate(members[0] if members else name).joint_id


# ------------------------------------------------------------------ legs
@dataclass(frozen=True)
class Leg:
    """A leg of a parallel mechanism: the joints between the ground and the platform on one
    branch, the constraint wrenches it imposes on the platform and the transmission wrenches
    of its actuators, as 6-vectors (force, moment) at the platform frame's origin and as screws
    (axes in the world)."""

    joints: tuple
    actuated: tuple
    twists: int  # dimension of the platform twists the leg alone allows
    constraint_wrenches: tuple  # 6-vectors
    transmission_wrenches: tuple
    constraint_screws: tuple  # Screw
    transmission_screws: tuple


def no_legs_reason(leg_list: tuple, output: str) -> str | None:
    """Why the chains that join ``output`` to the ground are not a parallel mechanism's legs (None when they
    are): legs are two or more chains of two or more joints each from the ground to a platform (a Delta's,
    a Stewart platform's, a five-bar's).  A slider-crank's slider on its guide or a four-bar's coupler with
    its rocker is a link joined by a single joint on one side: its chains are no legs."""
    if len(leg_list) < 2:
        return f"'{output}' is joined to the ground by one chain"
    single = [leg.joints for leg in leg_list if len(leg.joints) < 2]  # (none: the loop joint itself)
    if single:
        named = ", ".join(j[0] for j in single if j)
        return (f"'{output}' is joined to the ground by {f'the single joint {named}' if named else 'a single loop joint'}"
                " on one side: a link of a linkage, not a platform on legs")
    return None


def wrench_screw(wrench: np.ndarray, point: np.ndarray) -> Screw:
    """The screw of a wrench (force, moment about ``point``): axis along the force through the
    line of action, pitch m . f / |f|^2 (inf for a pure moment)."""
    w = np.asarray(wrench, float)
    f, m0 = w[:3], w[3:] + np.cross(np.asarray(point, float), w[:3])  # moment about the world origin
    return screw_of(np.r_[m0, f])


def legs(mech: Mechanism, q: np.ndarray, output: str, inputs: list[str] | None=None) -> tuple:
    """The legs between the ground and the ``output`` link (see Leg), at the assembled q.

    A leg is the set of tree joints on the branches that reach the platform -- the platform's
    own tree path, and each cut joint on the platform with the tree path to its other side --
    merged where branches share a joint (a Delta's arm carries two rods).  The platform twists a
    leg allows: t with t = J_c q'_L + A_c a_c for each of its connections c (J_c: the twist of
    that connection's body at the platform origin from the leg's joints; A_c: the relative
    twists the cut joint allows), over the leg's joint rates q'_L."""
    model, tol = mech.model, mech.tolerances
    state = KinematicState(mech, q)
    inputs = set(mech.actuated if inputs is None else inputs)
    fid = mech.link_frame(output)
    body = frame_parent(mech, fid)[0]
    o = state.frame_placement(fid).translation
    coords = {c.joint_id: c for c in mech.coordinates}

    def support(joint: int) -> list:
        return [j for j in model.supports[joint] if j in coords]

    def at_platform(frame: int):  # frame Jacobian as the twist of the frame's body at the platform origin
        J = state.frame_jacobian(frame, LWA)
        J[:3] += np.cross(J[3:].T, o - state.frame_placement(frame).translation).T  # v_o = v_p + w x (o - p)
        return J

    branches = [{"joints": set(support(body)), "ends": [(fid, None)]}]
    for cut in mech.cuts:
        for mine, other in ((cut.frame2, cut.frame1), (cut.frame1, cut.frame2)):
            if model.frames[mine].parentJoint == body and model.frames[other].parentJoint != body:
                branches.append({"joints": set(support(model.frames[other].parentJoint)), "ends": [(other, cut)]})
    merged = []
    for br in branches:
        for leg in merged:
            if leg["joints"] & br["joints"]:
                leg["joints"] |= br["joints"]
                leg["ends"] += br["ends"]
                break
        else:
            merged.append({"joints": set(br["joints"]), "ends": list(br["ends"])})
    out = []
    for leg in merged:
        joints = sorted(leg["joints"])
        cols = [coords[j].idx_v for j in joints]
        act = [coords[j].idx_v for j in joints if coords[j].joint in inputs]

        def allowed(locked):
            blocks, n_extra = [], []
            for frame, cut in leg["ends"]:  # noqa: B023 - called within this iteration
                A = _cut_twists(mech, cut, o, state) if cut is not None else np.zeros((6, 0))
                blocks.append((at_platform(frame), A))
                n_extra.append(A.shape[1])
            free_cols = [c for c in cols if c not in (act if locked else [])]  # noqa: B023 - called within this iteration
            # unknowns: t (6), the leg's free joint rates, each connection's a_c
            n = 6 + len(free_cols) + sum(n_extra)
            rows, start = [], 6 + len(free_cols)
            for (J, A), k in zip(blocks, n_extra):
                M = np.zeros((6, n))
                M[:, :6] = np.eye(6)
                M[:, 6:6 + len(free_cols)] = -J[:, free_cols]
                M[:, start:start + k] = -A
                start += k
                rows.append(M)
            Z = null_space(np.vstack(rows), tol, n)
            T = Z[:6]
            return T[:, np.linalg.norm(T, axis=0) > 0] if T.size else np.zeros((6, 0))

        T = allowed(False)
        W = null_space(T.T, tol, 6) if T.size else np.eye(6)  # reciprocal: w . t = 0
        T_locked = allowed(True)
        W_locked = null_space(T_locked.T, tol, 6) if T_locked.size else np.eye(6)
        # transmission: in W_locked, outside span(W): the part of W_locked orthogonal to W
        P = W_locked - W @ (W.T @ W_locked) if W.size else W_locked
        Ut, st, _ = np.linalg.svd(P, full_matrices=False) if P.size else (np.zeros((6, 0)), np.zeros(0), None)
        trans = Ut[:, st > tol.rank_rtol] if st.size else np.zeros((6, 0))  # rank of P (orthonormal columns)
        named = {m: name for name, members in compound_joints(mech).items() for m in members}
        names = tuple(dict.fromkeys(named.get(coords[j].joint, coords[j].joint) for j in joints))  # as mobility
        out.append(Leg(names, tuple(n for n in names if n in inputs), rank(T, tol),
                       tuple(tuple(map(float, c)) for c in W.T), tuple(tuple(map(float, c)) for c in trans.T),
                       tuple(wrench_screw(c, o) for c in W.T), tuple(wrench_screw(c, o) for c in trans.T)))
    return tuple(out)


def _cut_twists(mech: Mechanism, cut: CutJoint, o: np.ndarray, state: KinematicState) -> np.ndarray:
    """The relative twists a cut joint allows (analysis.screws.cut_twists), moved to the platform
    origin o, world axes (6 x k); none for a higher pair (its equivalent linkage's joints belong
    to the leg)."""
    twists = cut_twists(mech, cut, state) or []
    cols = [np.r_[t[:3] + np.cross(t[3:], o), t[3:]] for _, t, _ in twists]  # v_o = v_0 + w x o
    return np.array(cols).T if cols else np.zeros((6, 0))
