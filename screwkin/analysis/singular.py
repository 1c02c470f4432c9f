"""Singularity analysis at a configuration (Gosselin-Angeles, Zlatanov-Fenton-Benhabib).

With V a basis of the joint rates the loops allow (null space of K), inputs a
and passive joints p, and an output link o:

- constraint singularity: rank K drops below its generic value: the mobility
  changes or branches meet; the extra motion is reported;
- actuator (direct-kinematic) singularity: with the inputs locked the passive
  joints can still move (beyond the idle spins): K_p loses rank.  A limit
  position (a branch limit of a motion along an input) is one;
- serial (inverse-kinematic) singularity: the output link loses a direction of
  motion: rank(J_o V) drops below its generic value;
- stationary joints: joints whose rate the loops force to zero at this
  configuration (their row of V vanishes), while at generic configurations they
  move.

Each measure is a singular value relative to the largest of its matrix, taken
of dimensionless matrices: translations (the position rows of K, the linear
velocity rows of J_o) are divided by the mechanism's one characteristic length
L (``Mechanism.length``) and the rates of sliding joints multiplied by it, so
the numbers do not depend on the unit of length and are the same in every
command (``solve``'s singular flag comes from :func:`measures` too).  The
generic ranks are the largest over the mechanism's generic configurations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..model.linalg import complement, null_space, rank
from ..model.cuts import in_plane, pair_contact
from ..model.geometry import plane_basis
from ..model.kernel.scaling import dimensionless, dimensionless_twists
from ..model.kernel.stacks import tree_kinematics
from ..model.state import KinematicState, loop_coordinate_cuts
from ..tolerances import DEFAULT
from .screws import cut_twists, screw_of
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.model.cuts import CutJoint
    from screwkin.tolerances import Tolerances
    from collections.abc import Iterable

__all__ = ["actuator_det_rows", "actuator_det_sign", "SingularityReport", "SingularTwist", "Generic", "classify", "measures",
           "stacked_measures", "scaled_jacobians", "lost_direction",
           "KINDS", "named_types", "GramLoop", "loop_twists", "gram_cofactors", "pair_twist", "pair_rate"]

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
KINDS = ("serial", "actuator", "constraint")


@dataclass(frozen=True)
class SingularTwist:
    kind: str  # "actuator" | "serial" | "constraint"
    joint_rates: dict  # joint name -> rate of the motion (unit norm)
    twist: tuple | None  # output twist (v, w) of that motion, or the lost direction
    screw: object | None  # screwkin.analysis.screws.Screw of the twist


@dataclass(frozen=True)
class SingularityReport:
    serial: bool
    actuator: bool
    constraint: bool
    stationary_joints: tuple
    sigma_min: float
    sigmas: dict  # per kind, relative smallest singular value
    condition: float | None
    manipulability: float | None
    length: float  # characteristic length [m]
    singular_twists: tuple
    inputs: tuple
    output: str | None
    point: bool = False  # the output link's origin analysed as a point
    gram: tuple = ()  # GramLoop: the Gram-matrix cofactors of each loop's joint twists
    # the condition number of the map from the input rates to the output's twist (Merlet's), and why it is None or
    # inf: analysis.singularities.ellipsoids.with_input_output_condition (classify leaves them None)
    condition_input_output: float | None = None
    input_output_note: str | None = None


def _rel(s: np.ndarray, k: int) -> float:
    """k-th singular value (1-based) relative to the largest; 0 when missing."""
    if k <= 0:
        return 1.0
    if len(s) < k or s[0] <= 0:
        return 0.0
    return float(s[k - 1] / s[0])


@dataclass(frozen=True)
class Scaled:
    """Dimensionless matrices at a configuration: K (minimal rows, position rows / L),
    J (the output frame origin's twist, linear rows / L; only the linear rows for a point),
    both with the columns of sliding joints multiplied by L; V an orthonormal basis of the
    null space of K (rates in the same scaled coordinates)."""

    K: np.ndarray
    J: np.ndarray | None
    V: np.ndarray
    L: float


def scaled_jacobians(mech: Mechanism, q: np.ndarray, output: str | None=None, point: bool = False, length: float | None = None) -> Scaled:
    """The matrices of :class:`Scaled` at q (assembled)."""
    L = float(length or mech.length)
    slide = mech.translational
    K = mech.closure.jacobian(q)
    if K.size:
        K = dimensionless(K, mech.closure.position_rows, slide, L)
        V = null_space(K, mech.tolerances, mech.nv)
    else:
        K, V = np.zeros((0, mech.nv)), np.eye(mech.nv)
    J = None
    if output is not None:
        J = dimensionless_twists(KinematicState(mech, q).link_jacobian(output, LWA), slide, L)
        if point:
            J = J[:3]
    return Scaled(K, J, V, L)


class Generic:
    """Generic ranks of a mechanism for given inputs and output: the largest over the
    mechanism's generic configurations (``Mechanism.generic_configurations``), and the
    joints that move there (a joint whose rate the loops force to zero everywhere is not
    "stationary" at any one configuration)."""

    def __init__(self, mech: Mechanism, inputs: Iterable[str], output: str | None=None, point: bool = False, configurations=None) -> None:
        tol = mech.tolerances
        configs = configurations if configurations is not None else mech.generic_configurations()[1]
        self.inputs = list(inputs)
        self.output, self.point = output, point
        self.a = mech.velocity_indices(self.inputs)
        self.p = complement(mech.nv, self.a)
        self.rank_K = self.rank_Kp = 0
        self.out_dim = 0 if output is not None else None
        self.out_rotations = 0 if output is not None else None
        self.moving = np.zeros(mech.nv, bool)
        for q in configs:
            S = scaled_jacobians(mech, q, output, point)
            self.rank_K = max(self.rank_K, rank(S.K, tol))
            self.rank_Kp = max(self.rank_Kp, rank(S.K[:, self.p], tol) if S.K.size else 0)
            self.moving |= np.linalg.norm(S.V, axis=1) > tol.moves
            if S.J is not None:
                T = S.J @ S.V
                self.out_dim = max(self.out_dim, rank(T, tol))
                if not point:
                    self.out_rotations = max(self.out_rotations, rank(T[3:], tol))
        self.configurations = tuple(configs)


def measures(mech: Mechanism, q: np.ndarray, g: Generic, length: float | None = None) -> dict:
    """The relative smallest singular values that decide each kind of singularity at q
    (1 = far from it, 0 = singular): ``constraint`` of K, ``actuator`` of K_p (the passive
    columns), ``serial`` of J_o V relative to |J_o| (only with an output).  One function for
    every command: ``solve``'s singular flag, ``singularities``, sweeps and maps."""
    S = scaled_jacobians(mech, q, g.output, g.point, length)
    return _measures(S, g)


def _measures(S: Scaled, g: Generic) -> dict:
    out = {"constraint": _rel(np.linalg.svd(S.K, compute_uv=False), g.rank_K) if S.K.size else 1.0}
    Kp = S.K[:, g.p] if S.K.size else np.zeros((0, len(g.p)))
    out["actuator"] = _rel(np.linalg.svd(Kp, compute_uv=False), g.rank_Kp) if Kp.size and g.rank_Kp else 1.0
    if S.J is not None and g.out_dim:
        s = np.linalg.svd(S.J @ S.V, compute_uv=False)
        scale = np.linalg.norm(S.J, 2)  # V is orthonormal: s <= |J|, meaningful when the output stops
        out["serial"] = float(s[g.out_dim - 1] / scale) if len(s) >= g.out_dim and scale > 0 else 0.0
    return out


def actuator_det_rows(mech: Mechanism, g: Generic) -> tuple:
    """(rows, why): the rows of K (minimal, dimensionless) that are not zero at every generic configuration,
    when they make K_p square (as many as the passive joints, of full rank): det K_p[rows] is then a
    continuous function on the configurations whose sign changes only where K_p is singular (an actuator
    or constraint singularity).  rows None and why in words where K_p is not square so."""
    if not mech.closure.nrows or not len(g.p):
        return None, "no loop closed by passive joints: no actuator Jacobian"
    size = np.zeros(mech.closure.nrows)
    for q in g.configurations:
        size = np.maximum(size, np.abs(scaled_jacobians(mech, q).K[:, g.p]).max(axis=1))
    rows = np.flatnonzero(size > mech.tolerances.rank_rtol * size.max())
    if g.rank_Kp != len(g.p) or len(rows) != len(g.p):
        return None, (f"the actuator Jacobian K_p has {len(rows)} rows that move and {len(g.p)} passive columns "
                      f"(rank {g.rank_Kp}): not square, its determinant's sign is no argument")
    return rows, ""


def actuator_det_sign(mech: Mechanism, q: np.ndarray, g: Generic, rows: np.ndarray) -> int:
    """The sign of det K_p[rows] at q (dimensionless; rows from actuator_det_rows): +1, -1, or 0 where the
    actuator measure is below Tolerances.singular (too near a singularity for its sign to say anything)."""
    if measures(mech, q, g)["actuator"] < mech.tolerances.singular:
        return 0
    return int(np.sign(np.linalg.det(scaled_jacobians(mech, q).K[np.ix_(rows, g.p)])))


def stacked_measures(mech: Mechanism, Q: np.ndarray, g: Generic, K: np.ndarray) -> dict:
    """``measures`` of every row of the closed configurations Q (N, nq) at once: {kind: (N,)}, the kinds in
    measures' order.  K (N, rows, nv): their constraint Jacobians, the rows of ClosureSystem.jacobian (a
    model.kernel.stacks.BatchClosure's); the output's Jacobian from model.kernel.stacks.TreeKinematics.
    The same numbers as ``measures`` row by row, to round-off (stacked SVDs); None when the output's
    Jacobian cannot be stacked (a joint TreeKinematics does not take)."""
    Q = np.atleast_2d(np.asarray(Q, float))
    N, L, tol = len(Q), float(mech.length), mech.tolerances
    slide = mech.translational
    ones = np.ones(N)

    def rel(S: np.ndarray, k: int) -> np.ndarray:  # _rel of every row
        if k <= 0:
            return ones.copy()
        if S.shape[1] < k:
            return np.zeros(N)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(S[:, 0] > 0, S[:, k - 1] / np.where(S[:, 0] > 0, S[:, 0], 1.0), 0.0)

    Ks = dimensionless(K, mech.closure.position_rows, slide, L) if K.shape[1] else np.zeros((N, 0, mech.nv))
    out = {"constraint": rel(np.linalg.svd(Ks, compute_uv=False), g.rank_K) if Ks.shape[1] else ones.copy()}
    out["actuator"] = (rel(np.linalg.svd(Ks[:, :, g.p], compute_uv=False), g.rank_Kp)
                       if Ks.shape[1] and len(g.p) and g.rank_Kp else ones.copy())
    if g.output is None or not g.out_dim:
        return out
    tree = tree_kinematics(mech)
    if tree is None:
        return None
    fid = mech.link_frame(g.output)
    J = np.zeros((N, 6, mech.nv))
    _, _, Jc, cols = tree.frames(Q, [fid])[fid]
    if Jc is not None:
        J[:, :, cols] = Jc
    J = dimensionless_twists(J, slide, L)
    J = J[:, :3] if g.point else J
    serial = np.zeros(N)
    norms = np.linalg.norm(J, 2, axis=(1, 2))
    if Ks.shape[1]:  # V: the null space of K, by null_space's rank rule, row by row
        _, s, vt = np.linalg.svd(Ks, full_matrices=True)
        r = np.sum(s > np.maximum(tol.rank_rtol * s[:, :1], tol.rank_atol), axis=1)
        r[s[:, 0] <= tol.rank_atol] = 0
    else:
        vt, r = np.broadcast_to(np.eye(mech.nv), (N, mech.nv, mech.nv)), np.zeros(N, int)
    for rk in np.unique(r):
        rows = np.flatnonzero(r == rk)
        T = J[rows] @ vt[rows, rk:].transpose(0, 2, 1)
        if T.shape[2] == 0:
            continue
        sv = np.linalg.svd(T, compute_uv=False)
        if sv.shape[1] >= g.out_dim:
            ok = norms[rows] > 0
            serial[rows] = np.where(ok, sv[:, g.out_dim - 1] / np.where(ok, norms[rows], 1.0), 0.0)
    out["serial"] = serial
    return out


def classify(mech: Mechanism, q: np.ndarray, inputs: list | None = None, output: str | None=None, length: float | None=None, generic: Generic | None = None, point: bool = False) -> SingularityReport:
    """Classify the configuration q (assembled) for the given inputs and output link.
    length: the characteristic length [m] (default ``mech.length``); point: the output
    link's origin as a point (its 3 translations) instead of its full motion."""
    tol = mech.tolerances
    inputs = list(inputs if inputs is not None else mech.actuated)
    g = generic or Generic(mech, inputs, output, point)
    S = scaled_jacobians(mech, q, output, point, length)
    L = S.L
    sig = _measures(S, g)
    names = mech.coordinate_names
    slide = mech.translational
    constraint = g.rank_K > 0 and sig["constraint"] < tol.singular
    actuator = len(inputs) > 0 and sig["actuator"] < tol.singular
    serial = "serial" in sig and sig["serial"] < tol.singular
    twists = []
    J_world = origin = None
    if output is not None:
        state = KinematicState(mech, q)
        fid = mech.link_frame(output)
        # spatial twists (v at the world origin, w) for the screws: their axes are where they are in the world
        J_world = state.frame_jacobian(fid, pin.ReferenceFrame.WORLD)
        origin = state.frame_placement(fid).translation

    def unscale(x: np.ndarray):  # scaled rates -> joint rates [rad/s, m/s]
        x = x.copy()
        x[slide] *= L
        return x

    if constraint:
        _, _, vt = np.linalg.svd(S.K)
        twists.append(_motion_twist("constraint", unscale(vt[g.rank_K - 1]), names, J_world, tol))
    if actuator:
        _, _, vt = np.linalg.svd(S.K[:, g.p])
        x = np.zeros(mech.nv)
        x[g.p] = vt[g.rank_Kp - 1]
        twists.append(_motion_twist("actuator", unscale(x), names, J_world, tol))
    cond = manip = None
    if S.J is not None and g.out_dim:
        U, s, _ = np.linalg.svd(S.J @ S.V, full_matrices=True)
        kept = s[:g.out_dim]
        cond = float(kept[0] / kept[-1]) if len(kept) == g.out_dim and kept[-1] > 0 else float("inf")
        manip = float(np.prod(kept))
        if serial:  # the lost direction, as a spatial twist: v at the world origin = v_o - w x o
            topo = mech.topology(q)
            normal = topo.normal if topo.motion_space == "planar" else None
            lost = lost_direction(S.J @ S.V, g.out_dim, normal)
            lost[:3] *= L
            lost[:3] -= np.cross(lost[3:], origin)
            twists.append(SingularTwist("serial", {}, tuple(lost), screw_of(lost, L)))
    elif S.K.size and g.rank_Kp:
        s = np.linalg.svd(S.K[:, g.p], compute_uv=False)[:g.rank_Kp]
        cond = float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
    stationary = tuple(n for k, n in enumerate(names)
                       if g.moving[k] and S.V.shape[1] and np.linalg.norm(S.V[k]) < tol.stationary)
    # the loop (cut) joints too, from the same motions: a cut joint's rate is its F2's twist relative to F1
    # along its axis (model.state), zero in every motion of the null space (so the Gram table agrees)
    if S.V.shape[1]:
        states = [KinematicState(mech, q, unscale(S.V[:, i])) for i in range(S.V.shape[1])]
        for c in loop_coordinate_cuts(mech):
            scale = L if c.type == "prismatic" else 1.0
            if max(abs(st.loop_rate(c)) for st in states) / scale < tol.stationary:
                stationary += (c.name,)
        # a rolling, gear or screw pair too: its rate is that of its Gram column (pair_twist), the links' relative turning
        for c in mech.cuts:
            if c.pair in ONE_TWIST and max(abs(pair_rate(mech, c, st)) for st in states) < tol.stationary:
                stationary += (c.name,)
    sigmas = {k: sig.get(k, 1.0) for k in KINDS}
    return SingularityReport(serial, actuator, constraint, stationary, min(sigmas.values()), sigmas, cond, manip,
                             L, tuple(twists), tuple(inputs), output, point, gram_cofactors(mech, q, L))


def named_types(rep: SingularityReport, local=None, tol: Tolerances=DEFAULT) -> tuple:
    """The kinds that meet at the configuration in the standard vocabularies: (vocabulary, name, what it
    means here) for Gosselin and Angeles 1990 (type I: the output loses a direction, type II: it moves with
    the inputs locked, type III: both) and Zlatanov, Fenton and Benhabib 1995 (redundant input: the inputs
    move with the output at rest; redundant output: the output moves with the inputs at rest; redundant
    passive motion: only passive joints move; increased instantaneous mobility: K loses rank), and for a
    rank drop the configuration-space type from the local analysis (``local``: analysis.local), the
    constraint singularity of Zlatanov, Bonev and Gosselin 2002 when the configuration space itself is
    singular there."""
    out = []
    if rep.serial and rep.actuator:
        out.append(("Gosselin-Angeles", "type III", "types I and II at once"))
    if rep.serial:
        out.append(("Gosselin-Angeles", "type I", "inverse-kinematic: the output loses a direction of motion"))
        out.append(("Zlatanov-Fenton-Benhabib", "redundant input", "the inputs can move while the output stays"))
    if rep.actuator:
        out.append(("Gosselin-Angeles", "type II", "direct-kinematic: the mechanism moves with its inputs locked"))
        twist = next((t for t in rep.singular_twists if t.kind == "actuator"), None)
        moves = twist is not None and twist.twist is not None and np.linalg.norm(twist.twist) > tol.motion
        if rep.output is None:
            out.append(("Zlatanov-Fenton-Benhabib", "redundant output or redundant passive motion",
                        "passive joints move with the inputs at rest (give --output to tell which)"))
        elif moves:
            out.append(("Zlatanov-Fenton-Benhabib", "redundant output", "the output moves with the inputs at rest"))
        else:
            out.append(("Zlatanov-Fenton-Benhabib", "redundant passive motion",
                        "passive joints move with the inputs and the output at rest"))
    if rep.constraint:
        out.append(("Zlatanov-Fenton-Benhabib", "increased instantaneous mobility",
                    "K loses rank: more instantaneous freedoms than the mechanism has elsewhere"))
        if local is not None and local.kind not in ("regular", "undecided"):
            out.append(("Zlatanov-Bonev-Gosselin", "constraint singularity",
                        f"the configuration space is singular here: {local.kind}"))
    return tuple(out)


@dataclass(frozen=True)
class GramLoop:
    """The Gram-matrix cofactors of one loop's joint twists (Murray, Li and Sastry).

    The loop closed by cut joint ``loop`` through the spanning tree has joint twists
    xi_1..xi_n (the columns of S, 6 x n: the tree joints on either side of the cut and the cut
    joint's own freedoms, world axes, linear parts divided by L and sliding columns multiplied
    by it: dimensionless); its velocity constraint is S theta' = 0.  With G = S^T S and the
    loop's own mobility ``nullity`` = n - rank S equal to 1, adj(G) = c v v^T (v the unit vector
    spanning the null space, c > 0 the product of G's nonzero eigenvalues), so the diagonal
    cofactor C_ii = det(G without row and column i) = c v_i^2 vanishes exactly when joint i is
    stationary: theta_i' = 0 in every motion of the loop.  With nullity 0 or more than 1 every
    C_ii is 0 identically and says nothing: ``cofactors`` is then empty and ``note`` says why."""

    loop: str  # the cut joint that closes it
    joints: tuple  # column names (coordinate names; a cut joint's freedoms "cut[k]")
    nullity: int  # n - rank S: the loop's mobility on its own
    cofactors: dict  # joint -> C_ii
    relative: dict  # joint -> C_ii / sum_j C_jj = v_i^2
    zero: tuple  # joints whose cofactor is zero: v_i^2 < stationary^2 (Tolerances.stationary, as stationary_joints)
    note: str | None = None


#: |v_i| below this: joint i's rate is zero, by default (Tolerances.stationary, the threshold of
#: stationary_joints and of the zero Gram cofactors; a mechanism's own tolerances decide).
STATIONARY = DEFAULT.stationary


def loop_twists(mech: Mechanism, q: np.ndarray, cut: CutJoint, length: float | None=None) -> tuple:
    """(names, S, note) of the loop closed by ``cut`` at q: S the dimensionless 6 x n matrix of
    its joint twists (see GramLoop), F2's side negated so that S theta' = 0; S is None (and note
    says why) when the loop has a higher pair or a joint without one twist per coordinate."""
    model = mech.model
    L = float(length or mech.length)
    state = KinematicState(mech, q)
    J1 = state.frame_jacobian(cut.frame1, pin.ReferenceFrame.WORLD)
    J2 = state.frame_jacobian(cut.frame2, pin.ReferenceFrame.WORLD)
    sides = []
    for f in (cut.frame1, cut.frame2):
        sides.append({j for j in model.supports[model.frames[f].parentJoint] if j > 0})
    names, cols, slide = [], [], []
    coord_names = mech.coordinate_names
    virtual = set(mech.virtual_joints.get(cut.name, ()))
    for c in mech.coordinates:
        on1, on2 = c.joint_id in sides[0], c.joint_id in sides[1]
        if on1 == on2 or c.joint in virtual:
            continue  # not in the loop, on the common path from the ground (it cancels), or a pair's virtual joint
        for k in range(c.idx_v, c.idx_v + c.nv):
            names.append(coord_names[k])
            cols.append(J1[:, k] if on1 else -J2[:, k])
            slide.append(bool(mech.translational[k]))
    extra = pair_twist(mech, cut, state) if cut.pair in ONE_TWIST else cut_twists(mech, cut, state)
    if extra is None:
        return names, None, ("the loop closes through a sliding contact (cam, pin in a slot): its two freedoms, "
                             "rolling and sliding, have no one-twist equivalent: not computed")
    for name, t, sl in extra:
        names.append(name)
        cols.append(t)
        slide.append(sl)
    S = dimensionless_twists(np.array(cols, float).T.reshape(6, len(cols)), np.array(slide, bool), L)
    return names, S, None


#: Pairs closed through an equivalent linkage whose Gram column is one twist (pair_twist): rolling and gear pairs
#: a revolute about the contact point (their instantaneous equivalent), a screw pair its screw.
ONE_TWIST = ("rolling", "gear", "helical")


def _pair_frames(mech: Mechanism, cut: CutJoint) -> tuple:
    """(the file's loop joint, frame id of F1, of F2) of the rolling or gear pair closed by ``cut``."""
    spec = next(c for c in mech.spec.cut_joints if c.name == cut.name)
    return spec, mech.model.getFrameId(f"{cut.name}@F1"), cut.frame2


def _pair_axis(mech: Mechanism, cut: CutJoint, state: KinematicState) -> tuple:
    """(spec, F1, F2, p, a): a point p of the pair's one-twist axis and its unit direction a, world."""
    spec, f1, f2 = _pair_frames(mech, cut)
    M1 = state.frame_placement(f1)
    if cut.pair == "helical":  # the screw's axis through F1's origin
        return spec, f1, f2, M1.translation, M1.rotation @ in_plane(spec.axis)[0]
    return (spec, f1, f2, *pair_contact(spec, M1, state.frame_placement(f2)))


def pair_twist(mech: Mechanism, cut: CutJoint, state: KinematicState) -> list:
    """[(name, twist, False)]: the pair closed by ``cut`` as one twist (v at the world origin, w) at a
    unit rate of turning of F2's link relative to F1's.  A rolling or gear pair: a revolute about
    its axis through the contact point (model.cuts.pair_contact; pure rolling is that rotation);
    a screw pair: the screw of pitch lead / 2 pi about its axis through F1's origin."""
    spec, _, _, p, a = _pair_axis(mech, cut, state)
    v = -np.cross(a, p) + (spec.lead / (2 * np.pi) * a if cut.pair == "helical" else 0.0)
    return [(cut.name, np.concatenate([v, a]), False)]


def pair_rate(mech: Mechanism, cut: CutJoint, state: KinematicState) -> float:
    """The rate [rad/s] of the pair's column in pair_twist in the motion of ``state`` (with rates):
    F2's angular velocity relative to F1's about the pair's axis."""
    _, f1, f2, _, a = _pair_axis(mech, cut, state)
    return float((state.frame_twist(f2)[3:] - state.frame_twist(f1)[3:]) @ a)


def gram_cofactors(mech: Mechanism, q: np.ndarray, length: float | None=None) -> tuple:
    """GramLoop for each loop (one per cut joint: the fundamental loops of the spanning tree)."""
    tol = mech.tolerances
    out = []
    for cut in mech.cuts:
        names, S, note = loop_twists(mech, q, cut, length)
        if S is None:
            out.append(GramLoop(cut.name, tuple(names), -1, {}, {}, (), note))
            continue
        n = S.shape[1]
        nullity = n - rank(S, tol)
        if nullity != 1:
            why = ("the loop is rigid on its own (no motion): every cofactor is nonzero" if nullity == 0 else
                   f"the loop has {nullity} freedoms on its own: adj(G) = 0, every cofactor vanishes identically")
            out.append(GramLoop(cut.name, tuple(names), nullity, {}, {}, (), why))
            continue
        G = S.T @ S
        C = np.array([np.linalg.det(np.delete(np.delete(G, i, 0), i, 1)) for i in range(n)])
        total = float(C.sum())
        rel = C / total if total > 0 else np.zeros(n)
        cof = {nm: float(c) for nm, c in zip(names, C)}
        out.append(GramLoop(cut.name, tuple(names), 1, cof, {nm: float(r) for nm, r in zip(names, rel)},
                            tuple(nm for nm, r in zip(names, rel) if r < tol.stationary ** 2)))
    return tuple(out)


def lost_direction(JV: np.ndarray, out_dim: int, normal: np.ndarray | None=None) -> np.ndarray:
    """The output direction lost at a serial singularity, as a unit (6,) twist (v, w) in the rows' scaled
    coordinates (a point's output: v only, w zero): the left singular vector of the output's motion map
    JV (rows (v, w) or v, columns the mechanism's motions) for its ``out_dim``-th singular value, the one
    that vanishes.  For a planar mechanism (``normal``) the map is first restricted to the plane's
    components (v in the plane, w about the normal): the directions out of the plane are lost everywhere,
    and round-off there (1e-17) would otherwise tie with the vanishing singular value and could be chosen
    -- a direction that projects onto the plane as the zero twist."""
    rows = JV.shape[0]
    if normal is None:
        U = np.linalg.svd(JV, full_matrices=True)[0]
        out = np.zeros(6)
        out[:rows] = U[:, out_dim - 1]
        return out
    e1, e2, n = plane_basis(normal)
    P = np.zeros((3 if rows == 6 else 2, rows))  # the plane's components of a (v, w) or v row vector
    P[0, :3], P[1, :3] = e1, e2
    if rows == 6:
        P[2, 3:] = n
    U = np.linalg.svd(P @ JV, full_matrices=True)[0]
    out = np.zeros(6)
    out[:rows] = P.T @ U[:, min(out_dim, len(P)) - 1]
    return out


def _motion_twist(kind: str, x: np.ndarray, names: list[str], J: np.ndarray, tol: Tolerances) -> SingularTwist:
    """The motion x (any length) as a SingularTwist: its rates (those not zero next to the unit
    vector: above Tolerances.equal), its twist and screw (none for a zero twist)."""
    x = x / np.linalg.norm(x)
    rates = {n: float(v) for n, v in zip(names, x) if abs(v) > tol.equal}
    if J is None:
        return SingularTwist(kind, rates, None, None)
    t = J @ x
    return SingularTwist(kind, rates, tuple(t), screw_of(t) if np.linalg.norm(t) > tol.zero else None)
