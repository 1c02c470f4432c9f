"""Loop-closure rows and damped Newton for stacks of configurations (the workspace's inverse
kinematics, batched continuation): ``TreeKinematics`` computes the placements and Jacobians of
frames of a tree of 1-DOF joints for N configurations in one pass down the tree, and
``BatchClosure`` builds on them the same rows, in the same order, as model.kernel.closure.ClosureSystem
and solves them with the one damped-Newton loop of model/kernel/newton.py (``iterate``), all configurations
at once.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from ...tolerances import Tolerances
from . import newton
from .closure import ClosureSystem
from .contract import ClosureKernel, NotProvided
from .scaling import sliding_columns
from ..cuts import CouplingRow, CutJoint
from ..linalg import complement
from ..state import frame_parent, model_with_output

Array = NDArray[Any]

__all__ = ["TreeKinematics", "tree_kinematics", "BatchClosure", "Unbatchable"]


class Unbatchable(Exception):
    """The mechanism holds something the batched closure does not represent (joints of more
    than one coordinate, <mimic> joints, helical joints, sliding contacts): the caller solves
    one configuration at a time with model.kernel.closure.ClosureSystem instead."""


def tree_kinematics(mech: Any) -> TreeKinematics | None:
    """The mechanism's TreeKinematics, made once (mech.cache), None when its joints are not all 1-DOF
    revolute or prismatic (its users then run Pinocchio a configuration at a time)."""
    key = "links.tree"
    if key not in mech.cache:
        try:
            mech.cache[key] = TreeKinematics(mech)
        except Unbatchable:
            mech.cache[key] = None
    return mech.cache[key]


class TreeKinematics:
    """Placements and LOCAL_WORLD_ALIGNED Jacobians of frames of a tree of 1-DOF revolute and
    prismatic joints for stacks of configurations: one pass down the tree per stack (each
    joint's placement once: Pinocchio's forwardKinematics written for N configurations).  Each
    joint costs one matrix product of its parent's N rotations with a constant 3 x 11 matrix
    (Rodrigues' formula split into constant parts, the placement's translation and the axis)
    and a few elementwise operations.  Joint axes and placements are Pinocchio's; the rows
    BatchClosure builds on them equal ClosureSystem's (tests/model/kernel/test_newton.py)."""

    _AXES = {"JointModelRX": (1, 0, 0), "JointModelRY": (0, 1, 0), "JointModelRZ": (0, 0, 1),
             "JointModelPX": (1, 0, 0), "JointModelPY": (0, 1, 0), "JointModelPZ": (0, 0, 1)}

    def __init__(self, mech: Any) -> None:
        model = mech.model
        self.mech, self.model = mech, model
        if model.nq != model.nv:
            raise Unbatchable(f"{mech.path}: joints of more than one coordinate")
        data = mech.scratch_data()
        q0 = pin.neutral(model)
        self.joints = []  # (parent, kind "R" | "P", constant 3 x 11 matrix, idx_q)
        for j in range(1, model.njoints):
            short = model.joints[j].shortname()
            if model.nvs[j] != 1 or not (short in self._AXES or short.endswith(("RevoluteUnaligned",
                                                                               "PrismaticUnaligned"))):
                raise Unbatchable(f"{mech.path}: joint '{model.names[j]}' ({short}) is not a 1-DOF revolute or "
                                  "prismatic joint (a <mimic> joint, a helical or multi-DOF joint)")
            kind = "P" if ("PrismaticUnaligned" in short or short.startswith("JointModelP")) else "R"
            if short in self._AXES:
                axis = np.array(self._AXES[short], float)
            else:  # the motion subspace in the joint's own frame at q0
                S = pin.computeJointJacobian(model, data, q0, j)[:, model.idx_vs[j]]
                axis = S[3:] if kind == "R" else S[:3]
                axis = axis / np.linalg.norm(axis)
            M = model.jointPlacements[j]
            K = pin.skew(axis)
            C = np.hstack([M.rotation, M.rotation @ K, M.rotation @ K @ K, M.translation[:, None],
                           (M.rotation @ axis)[:, None]])
            self.joints.append((model.parents[j], kind, C.T.copy(), model.idx_qs[j]))
        self.supports: dict[int, Any] = {}
        self._frames: dict[Any, Any] = {}

    def _support(self, jid: int) -> Any:
        """(joint ids, which are revolute, velocity columns) of the joints moving joint jid."""
        if jid not in self.supports:
            sup = [int(j) for j in self.model.supports[jid] if j > 0]
            self.supports[jid] = (np.array(sup, int), np.array([self.joints[j - 1][1] == "R" for j in sup], bool),
                                  np.array([self.model.idx_vs[j] for j in sup], int)) if sup else None
        return self.supports[jid]

    def _frame(self, f: Any) -> Any:
        """(parent joint, [R | t]^T of the frame's placement) of frame f (model.state.frame_parent: the output
        frame where place_tool put it)."""
        if f in self._frames:
            return self._frames[f]
        joint, placement = frame_parent(self.mech, f)
        out = (joint, np.hstack([placement.rotation, placement.translation[:, None]]).T.copy())
        if f != self.mech.tool_frame:  # (the output frame is wherever place_tool last put it)
            self._frames[f] = out
        return out

    def _pass(self, Q: np.ndarray) -> Any:
        """(RTs, ps, ws) of every joint (index 0 the ground) for the configurations Q (N, nq):
        rotations transposed and flattened (3, 3N), origins (N, 3), axes in the world (N, 3)."""
        model = self.model
        N = len(Q)
        # rotations kept transposed and flattened: RT[j, 3 n + i] = R[n][i, j], so that a child's
        # is one product with the parent's, C^T RT (11 x 3N), and the rest is on contiguous rows
        RTs = [np.tile(np.eye(3), N)] + [None] * (model.njoints - 1)
        ps = [np.zeros((N, 3))] + [None] * (model.njoints - 1)
        ws = [None] * model.njoints  # joint axes (directions) in the world, (N, 3)
        # sin and 1 - cos of every coordinate from the half-angle tangent (numpy's tan is vectorized,
        # its sin and cos are not), each repeated for the 3 entries of a column of a rotation
        t = np.tan(0.5 * Q.T)  # (nq, N)
        den = 2.0 / (1.0 + t * t)
        sines, versines = np.repeat(t * den, 3, axis=1), np.repeat(t * t * den, 3, axis=1)  # (nq, 3N)
        for j, (parent, kind, C, iq) in enumerate(self.joints, start=1):
            XT = _thin(C, RTs[parent])  # (C is kept transposed)
            pos = ps[parent] + XT[9].reshape(N, 3)
            w = XT[10].reshape(N, 3)
            if kind == "R":  # A Rot(a, th) = A + sin(th) A [a]x + (1 - cos(th)) A [a]x^2, A = R_parent R_placement
                RT = XT[0:3] + sines[iq] * XT[3:6] + versines[iq] * XT[6:9]
            else:
                RT = XT[0:3]
                pos = pos + w * Q[:, iq, None]
            RTs[j], ps[j], ws[j] = RT, pos, w
        return RTs, ps, ws

    def motions(self, Q: np.ndarray, V: np.ndarray, A: np.ndarray, frame_ids: Any) -> tuple:
        """Placements (R (N, F, 3, 3), t (N, F, 3)), velocities (v, w) and classical accelerations
        (a, alpha) of the frames' origins in world axes (N, F, 6) for joint positions Q, rates V and
        accelerations A (N, nv): links._frame_motions' result (Pinocchio's forwardKinematics a step,
        LOCAL_WORLD_ALIGNED), by the recursions down the tree on the stacks.  A revolute joint's
        axis w turns with its parent: omega += w q', alpha += w q'' + omega_p x w q'; a prismatic
        joint slides its origin: v += w q', a += w q'' + 2 omega_p x w q'."""
        Q, V, A = (np.atleast_2d(np.asarray(x, float)) for x in (Q, V, A))
        N = len(Q)
        RTs, ps, ws = self._pass(Q)
        zero = np.zeros((N, 3))
        om, vel, al, acc = [zero], [zero], [zero], [zero]
        for j, (parent, kind, _, iq) in enumerate(self.joints, start=1):
            w, r = ws[j], ps[j] - ps[parent]
            wp, alp = om[parent], al[parent]
            wr = np.cross(wp, r)
            v = vel[parent] + wr
            a = acc[parent] + np.cross(alp, r) + np.cross(wp, wr)
            wqd, wqdd = w * V[:, iq, None], w * A[:, iq, None]  # (nq == nv: iq is the velocity index)
            if kind == "R":
                o, alpha = wp + wqd, alp + wqdd + np.cross(wp, wqd)
            else:
                o, alpha = wp, alp
                v, a = v + wqd, a + wqdd + 2.0 * np.cross(wp, wqd)
            om.append(o)
            vel.append(v)
            al.append(alpha)
            acc.append(a)
        F = len(frame_ids)
        R, t = np.empty((N, F, 3, 3)), np.empty((N, F, 3))
        tw, ac = np.empty((N, F, 6)), np.empty((N, F, 6))
        for i, f in enumerate(frame_ids):
            jid, CfT = self._frame(f)
            XT = _thin(CfT, RTs[jid])
            R[:, i] = XT[0:3].reshape(3, N, 3).transpose(1, 2, 0)
            t[:, i] = ps[jid] + XT[3].reshape(N, 3)
            r = t[:, i] - ps[jid]
            wr = np.cross(om[jid], r)
            tw[:, i, :3], tw[:, i, 3:] = vel[jid] + wr, om[jid]
            ac[:, i, :3] = acc[jid] + np.cross(al[jid], r) + np.cross(om[jid], wr)
            ac[:, i, 3:] = al[jid]
        return R, t, tw, ac

    def centres(self, Q: np.ndarray, refs: Any) -> dict:
        """{ref: (N, 3)} the world positions [m] KinematicState.centre reads -- ("joint", i) joint i's
        centre, ("mount", i) where joint i sits on its parent, ("frame", f) frame f's origin -- at every
        row of Q: its stacked form, from one pass down the tree."""
        Q = np.atleast_2d(np.asarray(Q, float))
        N = len(Q)
        RTs, ps, _ = self._pass(Q)
        out = {}
        for kind, i in refs:
            if kind == "joint":
                out[(kind, i)] = ps[i]
                continue
            if kind == "mount":
                jid, t = self.model.parents[i], np.asarray(self.model.jointPlacements[i].translation, float)[None]
            else:
                jid, CfT = self._frame(i)
                t = CfT[3:4]
            out[(kind, i)] = ps[jid] + _thin(t, RTs[jid])[0].reshape(N, 3)
        return out

    def frames(self, Q: np.ndarray, frame_ids: Any, jacobian: bool = True) -> dict:
        """{frame id: (R (N, 3, 3), p (N, 3), J (N, 6, n), cols (n,))}: rotation, origin and the
        frame's Jacobian (linear velocity of its origin, angular velocity; world axes) on the
        velocity columns ``cols`` of the joints that move it (J and cols None for a frame
        fixed to the ground, and without ``jacobian``)."""
        Q = np.atleast_2d(np.asarray(Q, float))
        N = len(Q)
        RTs, ps, ws = self._pass(Q)
        Wall = np.stack([np.zeros((N, 3))] + ws[1:], axis=2)  # (N, 3, njoints)
        Pall = np.stack(ps, axis=2)
        out: dict[Any, tuple] = {}
        for f in frame_ids:
            jid, CfT = self._frame(f)
            XT = _thin(CfT, RTs[jid])
            Rf = XT[0:3].reshape(3, N, 3).transpose(1, 2, 0)
            pf = ps[jid] + XT[3].reshape(N, 3)
            support = self._support(jid) if jacobian else None
            if not support:
                out[f] = (Rf, pf, None, None)  # (a frame on the ground)
                continue
            sup, revolute, cols = support
            W = Wall[:, :, sup]  # (N, 3, n) the joints' axes
            D = pf[:, :, None] - Pall[:, :, sup]  # from a point of each axis to the frame's origin
            J = np.empty((N, 6, len(sup)))
            # revolute: (w x d, w); prismatic: (w, 0)
            J[:, 0] = W[:, 1] * D[:, 2] - W[:, 2] * D[:, 1]
            J[:, 1] = W[:, 2] * D[:, 0] - W[:, 0] * D[:, 2]
            J[:, 2] = W[:, 0] * D[:, 1] - W[:, 1] * D[:, 0]
            J[:, 3:] = W
            if not revolute.all():
                J[:, :3, ~revolute] = W[:, :, ~revolute]
                J[:, 3:, ~revolute] = 0.0
            out[f] = (Rf, pf, J, cols)
        return out


_TARGET_KINDS = {"pose": ("fixed", 0), "point": ("spherical", 3)}
#: A stack this short is evaluated a configuration at a time by Pinocchio (ClosureSystem.evaluate, the same rows
#: to round-off): a stack's numpy pass costs about a millisecond whatever its length, Pinocchio's a tenth of that a
#: configuration -- the few configurations Newton still iterates on after the others converged (past a fold,
#: where it gives up only after tens of steps).
FEW = 4


class BatchClosure(ClosureKernel):
    """The loop-closure rows of ``mech`` (the same rows, in the same order, as its
    model.kernel.closure.ClosureSystem) for many configurations at once, and a damped-Newton solver
    that moves all of them together: every iteration is a few numpy calls on the whole stack
    instead of one Pinocchio pass and one linear solve per configuration.

    Frame placements and Jacobians come from the product-of-exponentials structure equations
    of the chains from the ground to each cut-joint frame (SerialJacobians).  The rows equal
    ClosureSystem.evaluate's (tests/model/kernel/test_newton.py compares them on every batchable robot);
    ``check=N`` compares them again at N random configurations when the object is built (a
    debugging aid: the program does not check at run time).

    target: None, or (link, "pose" | "point"): one more cut joint, a weld ("pose") or a ball
    joint ("point") between the output link and a ground frame whose placement is given per
    configuration (``targets``: origins (N, 3), and a rotation (3, 3) shared by all) -- the
    inverse kinematics of a workspace grid.

    Raises Unbatchable for what it does not represent.
    """

    def __init__(self, mech: Any, target: Any = None, check: int = 0) -> None:
        # with a target, a copy of the model with the output frame placed (model.state.model_with_output): the
        # target's cut joint is a frame of it, and the self-check moves the target frame in it, not in the mechanism's
        model = mech.model if target is None else model_with_output(mech)
        self.mech, self.model = mech, model
        if model.nq != model.nv:
            raise Unbatchable(f"{mech.path}: joints of more than one coordinate")
        if any(not isinstance(e, CouplingRow) for e in mech.extra_rows):
            raise Unbatchable(f"{mech.path}: sliding contacts (higher pairs)")
        if any(e.kind == "angle" for e in mech.extra_rows):
            raise Unbatchable(f"{mech.path}: a link's absolute angle held as an input (a row modulo a turn)")
        if any(model.nvs[j] != 1 for j in range(1, model.njoints)):
            raise Unbatchable(f"{mech.path}: a joint that is not a 1-DOF joint (or a <mimic> joint)")
        cuts = list(mech.cuts)
        self.target = None
        if target is not None:
            link, kind = target
            ctype, dof = _TARGET_KINDS[kind]
            cuts.append(CutJoint("target", ctype, dof, mech.target_frame, mech.link_frame(link), "world", link,
                                 (1.0, 0.0, 0.0)))
            self.target = (link, kind)
        self.cuts = cuts
        # a ClosureSystem of the same cut joints: its plans give the rows, it checks ours
        self.system = ClosureSystem(model, cuts, mech.tolerances, mech.path, data=mech.scratch_data(),
                                    extra=mech.extra_rows)
        self.nrows = self.system.nrows
        self.solver_rows = self.system._rows(True)
        self.nq, self.nv, self.m = model.nq, model.nv, self.solver_rows
        # which of the solver's rows are lengths [m] (positions; the couplings of rolling and screw pairs)
        self.solver_position_rows = self.length_rows = self.system.solver_position_rows
        self.sliding = sliding_columns(model)
        frames = []
        for c in cuts:
            for f in (c.frame1, c.frame2):
                if f != mech.target_frame and f not in frames:
                    frames.append(f)
        self._frame_ids = frames
        self.tree = TreeKinematics(mech)
        self.couplings = [(np.array([iq for iq, _, _ in e.terms]), np.array([iv for _, iv, _ in e.terms]),
                           np.array([c for _, _, c in e.terms]), e.constant) for e in mech.extra_rows]
        self._revolute_cuts = [(k, np.asarray(c.axis, float)) for k, c in enumerate(cuts)
                               if c.type in ("revolute", "continuous", "cylindrical", "planar")]
        if check:
            self._check(np.random.default_rng(0), check)

    # ------------------------------------------------------------------ frames
    def _frames(self, Q: np.ndarray, jacobian: bool = True) -> dict:
        """{frame id: (R (N, 3, 3), p (N, 3), J (N, 6, n) LOCAL_WORLD_ALIGNED on the chain's
        columns, columns (n,))}; J and the columns None for a frame on the ground (and for
        every frame without ``jacobian``)."""
        return self.tree.frames(Q, self._frame_ids, jacobian)

    def _placements(self, c: Any, frames: Any, targets: Any, N: int) -> tuple:
        """(R1, t1, J1, cols1, R2, t2, J2, cols2) of cut joint c (J None: the frame does not move)."""
        if c.frame1 == self.mech.target_frame:
            t, Rt = targets
            first = (np.broadcast_to(np.asarray(Rt, float), (N, 3, 3)), np.asarray(t, float), None, None)
        else:
            first = frames[c.frame1]
        return first + frames[c.frame2]

    # ------------------------------------------------------------------ rows
    def evaluate(self, Q: Array, jacobian: bool = True, targets: Any = None) -> tuple[Array, Array | None]:
        """The solver's rows (ClosureSystem.evaluate(solver=True)) of every configuration of Q (N, nq):
        r (N, m) and K (N, m, nv) (None without ``jacobian``); targets: the target's placements
        (origins (N, 3), rotation (3, 3)) of a closure with a target."""
        return self._rows(Q, targets, jacobian, solver=True)

    def integrate(self, Q: Array, V: Array) -> Array:
        return self.system.integrator(Q, V)

    def constraint_jacobian(self, Q: Array) -> Array:
        return self.constraint_jacobians(Q)

    def reversed_joints(self, q: Array, placed: bool = False) -> list[str]:
        frames = self._frames(np.asarray(q, float)[None], jacobian=False)
        return [self.cuts[k].name for k, a in self._revolute_cuts
                if (frames[self.cuts[k].frame1][0][0] @ a) @ (frames[self.cuts[k].frame2][0][0] @ a) < 0]

    @property
    def name(self) -> str:
        return self.mech.path

    def constraint_jacobians(self, Q: np.ndarray, targets: Any = None) -> np.ndarray:
        """The minimal rows' Jacobian K (N, rows, nv) (ClosureSystem.jacobian) of configurations
        that close the loops: a rotation vector's rows use the derivative of log3 at the
        identity, which they are at within the closure tolerance."""
        K = self._rows(Q, targets, True, solver=False)[1]
        assert K is not None
        return K

    def _rows(self, Q: np.ndarray, targets: Any, jacobian: bool, solver: bool) -> tuple[np.ndarray, np.ndarray | None]:
        Q = np.atleast_2d(np.asarray(Q, float))
        N, nv = len(Q), self.model.nv
        if self.target is not None and targets is None:
            raise ValueError("this closure has a target: give its placements")
        frames = self._frames(Q, jacobian)
        nrows = self.solver_rows if solver else self.nrows
        r = np.empty((N, nrows))
        K: Any = np.zeros((N, nrows, nv)) if jacobian else None

        def add(rows: Any, cols: Any, A: np.ndarray) -> None:  # K[:, rows, cols] += A (N, len(rows), len(cols))
            if cols is not None:
                K[:, rows, cols] += A

        i = 0
        for c, (P, pairs, vectors, rotation) in zip(self.cuts, self.system.plans):
            R1, t1, J1, c1, R2, t2, J2, c2 = self._placements(c, frames, targets, N)
            d = t2 - t1
            E = _rows_times(np.asarray(P, float), R1.transpose(0, 2, 1))  # (N, k, 3): position rows, world axes
            k = E.shape[1]
            r[:, i:i + k] = _apply_rows(E, d)
            rows = slice(i, i + k)
            if jacobian:  # e . (v2 - v1) + (e x d) . w1 = e . (v2 - v1 + d x w1)
                if J2 is not None:
                    add(rows, c2, _stacked_products(E, J2[:, :3]))
                if J1 is not None:
                    add(rows, c1, _stacked_products(E, _cross_columns(d, J1[:, 3:]) - J1[:, :3]))
            i += k
            if solver and vectors is not None:
                for v in np.asarray(vectors, float):  # R2 v - R1 v; derivative (R1 v) x w1 - (R2 v) x w2
                    U1, U2 = R1 @ v, R2 @ v
                    r[:, i:i + 3] = U2 - U1
                    if jacobian:
                        if J1 is not None:
                            add(slice(i, i + 3), c1, _cross_columns(U1, J1[:, 3:]))
                        if J2 is not None:
                            add(slice(i, i + 3), c2, -_cross_columns(U2, J2[:, 3:]))
                    i += 3
                continue
            if rotation:  # log3(R1^T R2), derivative Jlog3 R2^T (w2 - w1) with Jlog3 = I at closure
                r[:, i:i + 3] = _log3(R1.transpose(0, 2, 1) @ R2)
                if jacobian:
                    R2t = R2.transpose(0, 2, 1)
                    if J2 is not None:
                        add(slice(i, i + 3), c2, _stacked_products(R2t, J2[:, 3:]))
                    if J1 is not None:
                        add(slice(i, i + 3), c1, -_stacked_products(R2t, J1[:, 3:]))
                i += 3
                continue
            for u0, w0 in pairs:  # alignments u . w; derivative (w x u) . (w2 - w1)
                u, w = R1 @ np.asarray(u0, float), R2 @ np.asarray(w0, float)
                r[:, i] = np.einsum("ni,ni->n", u, w)
                if jacobian:
                    wu = np.cross(w, u)[:, None, :]
                    if J2 is not None:
                        add(slice(i, i + 1), c2, _stacked_products(wu, J2[:, 3:]))
                    if J1 is not None:
                        add(slice(i, i + 1), c1, -_stacked_products(wu, J1[:, 3:]))
                i += 1
        for iq, iv, coef, const in self.couplings:
            r[:, i] = Q[:, iq] @ coef + const
            if jacobian:
                for v, cf in zip(iv, coef):
                    K[:, i, v] += cf
            i += 1
        return r, K

    def bias(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        """K'(q, v) v of every configuration (N, rows): ClosureSystem.bias's minimal rows (zero joint
        accelerations) for stacks, from the frames' classical accelerations (TreeKinematics.motions)
        instead of Pinocchio's a configuration at a time.  A rotation vector's rows take the
        derivative of log3 at the identity, as constraint_jacobians does (the configurations close
        the loops: R1^T R2 = I within the closure tolerance); a coupling's row is linear: 0."""
        if self.target is not None:
            raise NotProvided("bias of a closure with a target is not defined")
        Q, V = np.atleast_2d(np.asarray(Q, float)), np.atleast_2d(np.asarray(V, float))
        N = len(Q)
        ids = self._frame_ids
        R, t, tw, ac = self.tree.motions(Q, V, np.zeros_like(V), ids)
        at = {f: k for k, f in enumerate(ids)}
        out = np.zeros((N, self.nrows))
        i = 0

        def world(R_: np.ndarray, u: np.ndarray) -> np.ndarray:  # R u for a stack of rotations and a constant vector
            return np.einsum("nij,j->ni", R_, np.asarray(u, float))

        for cut, (P, pairs, _, rotation) in zip(self.cuts, self.system.plans):
            a, b = at[cut.frame1], at[cut.frame2]
            R1, R2, d = R[:, a], R[:, b], t[:, b] - t[:, a]
            w1, w2, al1, al2 = tw[:, a, 3:], tw[:, b, 3:], ac[:, a, 3:], ac[:, b, 3:]
            dd, ddd = tw[:, b, :3] - tw[:, a, :3], ac[:, b, :3] - ac[:, a, :3]
            # e fixed in F1: d2/dt2 (e . d) = e . (d'' - 2 w1 x d' - al1 x d + w1 x (w1 x d))
            g = ddd - 2.0 * np.cross(w1, dd) - np.cross(al1, d) + np.cross(w1, np.cross(w1, d))
            k = len(P)
            out[:, i:i + k] = np.einsum("kj,nij,ni->nk", P, R1, g)  # P (R1^T g)
            i += k
            if rotation:
                out[:, i:i + 3] = np.einsum("nij,ni->nj", R2, al2 - al1 + np.cross(w2, w1))  # R2^T (...)
                i += 3
                continue
            for u, w in pairs:  # d2/dt2 (u . w), u fixed in F1 and w in F2
                u, w = world(R1, u), world(R2, w)
                ud, wd = np.cross(w1, u), np.cross(w2, w)
                udd, wdd = np.cross(al1, u) + np.cross(w1, ud), np.cross(al2, w) + np.cross(w2, wd)
                out[:, i] = np.einsum("ni,ni->n", udd, w) + 2.0 * np.einsum("ni,ni->n", ud, wd) + \
                    np.einsum("ni,ni->n", u, wdd)
                i += 1
        return out

    def reversed_axes(self, Q: np.ndarray) -> np.ndarray:
        """(N,) True where a revolute (cylindrical, planar) cut joint is assembled with its two
        axes opposed: a root of the rows that is not the joint (ClosureSystem.wrong_branch)."""
        Q = np.atleast_2d(np.asarray(Q, float))
        bad = np.zeros(len(Q), bool)
        if not self._revolute_cuts:
            return bad
        frames = self._frames(Q)
        for k, a in self._revolute_cuts:
            c = self.cuts[k]
            R1, R2 = frames[c.frame1][0], frames[c.frame2][0]  # (a target is never a revolute cut joint)
            bad |= np.einsum("ni,ni->n", R1 @ a, R2 @ a) < 0
        return bad

    # ------------------------------------------------------------------ solving
    def solve(self, Q0: np.ndarray, targets: Any = None, frozen: Any = (), tolerances: Tolerances | None = None,
              iterations: int | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Damped Newton from every row of Q0 at once: model.kernel.newton.iterate (the loop of
        ClosureSystem.solve, each configuration with its own damping) on these rows.  frozen:
        velocity indices that do not move (inputs).  Returns (Q, converged (N,), residual norms
        (N,), iterations (N,)); a configuration that converges with a reversed revolute cut joint
        counts as not converged."""
        tol = tolerances or self.mech.tolerances
        Q = np.array(np.atleast_2d(Q0), float)
        N, nv = Q.shape[0], self.model.nv
        if self.solver_rows == 0 or N == 0:
            return Q, np.ones(N, bool), np.zeros(N), np.zeros(N, int)

        def evaluate(Q_: np.ndarray, which: Any, jacobian: bool) -> tuple[np.ndarray, np.ndarray | None]:
            if targets is None and len(Q_) <= FEW:  # (the last few still iterating: Pinocchio's pass, the same rows)
                rows = [self.system.evaluate(q, jacobian, True) for q in Q_]
                return np.array([r for r, _ in rows]), (np.array([K for _, K in rows]) if jacobian else None)
            return self.evaluate(Q_, jacobian, None if targets is None else (targets[0][which], targets[1]))

        free = complement(nv, frozen)
        out = newton.iterate(evaluate, Q, free, tol, self.integrate, newton.stacked_steps, iterations)
        converged = out.converged.copy()
        if converged.any():
            c = np.flatnonzero(converged)
            converged[c] &= ~self.reversed_axes(out.q[c])
        return out.q, converged, out.residual, out.iterations

    # ------------------------------------------------------------------ self-check
    def _check(self, rng: np.random.Generator, count: int) -> None:
        """Our rows against ClosureSystem's: at random configurations (solver rows) and at the
        mechanism's closed configurations (constraint Jacobian)."""
        mech, model, system = self.mech, self.model, self.system
        lo = np.maximum(np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -np.pi), -np.pi)
        hi = np.minimum(np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, np.pi), np.pi)
        Q = rng.uniform(lo, hi, size=(count, model.nq))
        closed = [mech.generic_configurations()[0].q] if mech.cuts or mech.extra_rows else []
        frame = model.frames[mech.target_frame]
        saved = frame.placement.copy()
        try:
            for q, is_closed in [(q, False) for q in Q] + [(q, True) for q in closed]:
                targets = None
                if self.target is not None:
                    data = mech.scratch_data()
                    pin.framesForwardKinematics(model, data, q)
                    M = data.oMf[self.cuts[-1].frame2]
                    placement = M if is_closed else pin.SE3(M.rotation, M.translation + 0.01)
                    frame.placement = placement
                    model.frames[mech.target_frame] = frame
                    targets = (placement.translation[None], placement.rotation)
                if is_closed:
                    ours, ref = self.constraint_jacobians(q[None], targets)[0], system.jacobian(q)
                else:
                    r, K = self.evaluate(q[None], True, targets)
                    assert K is not None
                    r_ref, K_ref = system.evaluate(q, True, solver=True)
                    assert K_ref is not None
                    ours, ref = np.hstack([r[0][:, None], K[0]]), np.hstack([r_ref[:, None], K_ref])
                err = float(np.abs(ours - ref).max()) if ref.size else 0.0
                if err > 1e-8 * max(1.0, float(np.abs(ref).max()) if ref.size else 1.0):  # pragma: no cover - a bug
                    raise RuntimeError(f"{mech.path}: batched closure rows differ from ClosureSystem's by {err:.1e}")
        finally:
            frame.placement = saved
            model.frames[mech.target_frame] = frame


def _thin(C: np.ndarray, RT: np.ndarray, block: int = 4096) -> np.ndarray:
    """C @ RT for a small constant C (k <= 11, 3) and a long RT (3, 3N), a block of columns at a time.
    OpenBLAS threads the whole product (over 262,144 multiply-adds), and in a process that has
    imported pinocchio, on 2 busy cores, its threads wait for each other: 10-16 ms instead of 0.1
    for 60,000 columns.  Blocks of 4,096 columns stay under its threshold: one thread, 0.2 ms, the
    same numbers (each column's product is the same kernel's)."""
    n = RT.shape[1]
    if n <= block:
        return C @ RT
    out = np.empty((C.shape[0], n))
    for i in range(0, n, block):
        np.matmul(C, RT[:, i:i + block], out=out[:, i:i + block])
    return out


def _stacked_products(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """A @ B for stacks A (N, k, 3), B (N, 3, n): three broadcast products (numpy's stacked
    matmul on 3-long inner products costs several times more)."""
    return A[:, :, 0, None] * B[:, None, 0] + A[:, :, 1, None] * B[:, None, 1] + A[:, :, 2, None] * B[:, None, 2]


def _rows_times(P: np.ndarray, Rt: np.ndarray) -> np.ndarray:
    """P @ Rt for a constant P (k, 3) and a stack Rt (N, 3, 3)."""
    return np.einsum("ki,nij->nkj", P, Rt)


def _apply_rows(E: np.ndarray, d: np.ndarray) -> np.ndarray:
    """E @ d for stacks E (N, k, 3), d (N, 3)."""
    return E[:, :, 0] * d[:, 0, None] + E[:, :, 1] * d[:, 1, None] + E[:, :, 2] * d[:, 2, None]


def _cross_columns(a: np.ndarray, W: np.ndarray) -> np.ndarray:
    """a x w for every column w of W: a (N, 3), W (N, 3, n) -> (N, 3, n)."""
    a0, a1, a2 = a[:, 0, None], a[:, 1, None], a[:, 2, None]
    return np.stack([a1 * W[:, 2] - a2 * W[:, 1], a2 * W[:, 0] - a0 * W[:, 2], a0 * W[:, 1] - a1 * W[:, 0]], axis=1)


def _log3(R: np.ndarray) -> np.ndarray:
    """Rotation vectors of a stack of rotations (N, 3, 3) (pinocchio.log3 for each; angles
    below pi)."""
    c = np.clip((np.trace(R, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    theta = np.arccos(c)
    s = np.sin(theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(theta < 1e-8, 0.5 + theta**2 / 12.0, theta / (2.0 * s))
    v = np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], axis=1)
    return v * f[:, None]
