"""Measures over many configurations at once: arrays of q in, arrays out.

Two ways to the Jacobians of a stack of configurations:

- ``frame_jacobians``: one Pinocchio call per configuration (about a microsecond
  each from Python), for any model;
- ``SerialJacobians``: the product-of-exponentials structure equations of the
  chain from the ground to a frame (screws.chains: joint twists and the home
  placement read from Pinocchio), evaluated for thousands of configurations per
  numpy call.  Python pays its overhead once per joint per block of
  configurations instead of once per configuration.  It is checked against
  Pinocchio's Jacobians at random configurations when it is built, and refuses
  chains it cannot represent (joints with more than one DOF, helical joints).

The measures (singular values, determinants) are one numpy call on the whole stack.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pinocchio as pin

from ..errors import UsageError
from ..model._pin import compute_frame_jacobian
from ..model.closure import ClosureSystem, CouplingRow, CutJoint
from .screws import chains

__all__ = ["frame_jacobians", "SerialJacobians", "singular_values", "smallest_singular_values",
           "singular_value_ratios", "determinants", "BatchClosure", "Unbatchable", "damped_steps",
           "TreeKinematics"]

_REFERENCES = (pin.ReferenceFrame.WORLD, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED, pin.ReferenceFrame.LOCAL)


def frame_jacobians(model, frame_id: int, Q, reference=pin.ReferenceFrame.WORLD, data=None) -> np.ndarray:
    """(N, 6, nv) frame Jacobians for the configurations in the rows of Q (N, nq)."""
    Q = np.atleast_2d(np.asarray(Q, float))
    if Q.shape[1] != model.nq:
        raise ValueError(f"expected configurations of shape (..., {model.nq}), got {Q.shape}")
    data = data or model.createData()
    out = np.empty((len(Q), 6, model.nv))
    for k, q in enumerate(Q):
        out[k] = compute_frame_jacobian(model, data, q, frame_id, reference)
    return out


class SerialJacobians:
    """Frame Jacobians of the chain from the ground to ``link`` for stacks of configurations.

    J(q) columns are the chain's joint twists at q (space frame, (v, w)), moved to the
    frame origin for LOCAL_WORLD_ALIGNED and also rotated into the frame for LOCAL;
    columns of joints outside the chain are zero, as in Pinocchio.

    >>> sj = SerialJacobians(mech, "flange")
    >>> J = sj(Q)            # (N, 6, nv), Q: (N, nq) Pinocchio configurations
    """

    def __init__(self, mech, link: str | None, reference=pin.ReferenceFrame.LOCAL_WORLD_ALIGNED, block: int = 8192,
                 check: int = 4, chain=None):
        """chain: a screws.Chain to any frame instead of the one to ``link``'s body frame."""

        if reference not in _REFERENCES:
            raise UsageError(f"unknown reference frame {reference}")
        self.mech, self.model, self.reference, self.block = mech, mech.model, reference, int(block)
        if chain is None:
            chain = next(c for c in chains(mech, output=link) if c.name == f"output {link}")
        self.frame = chain.frame
        if not chain.joints:
            raise UsageError(f"{mech.path}: no moving joint lies between the ground and "
                             f"'{self.model.frames[chain.frame].name}'")
        self.chain = chain
        model = self.model
        self._cols = list(chain.columns)
        # how each chain joint's displacement theta is read from q (relative to the neutral configuration)
        self._reads = []
        neutral = mech.neutral()
        for name, col in zip(chain.joints, chain.columns):
            jid = model.getJointId(name)
            iq, nq = model.idx_qs[jid], model.nqs[jid]
            if nq == 1:
                self._reads.append(("linear", iq, float(neutral[iq])))
            elif nq == 2:  # continuous joint: (cos, sin), neutral (1, 0)
                self._reads.append(("angle", iq, 0.0))
            else:  # pragma: no cover - 1-DOF joints have nq 1 or 2
                raise UsageError(f"{mech.path}: joint '{name}' is not a 1-DOF joint")
        self._joints = []
        for k in range(len(chain.joints)):
            v, w = chain.xi0[:3, k], chain.xi0[3:, k]
            if np.linalg.norm(w) > 1e-12:
                if abs(np.linalg.norm(w) - 1) > 1e-9 or abs(w @ v) > 1e-9:
                    raise UsageError(f"{mech.path}: joint '{chain.joints[k]}' is not a pure rotation "
                                     "(helical): the batched Jacobians take revolute and prismatic joints")
                K = pin.skew(w)
                K2 = K @ K  # Rot(w, t) = I + sin(t) K + (1 - cos(t)) K^2
                columns = []  # the columns of Rot that change, each as its nonzero (I, K, K^2) entries
                for b in range(3):
                    if not (K[:, b].any() or K2[:, b].any()):
                        continue  # this column of Rot is e_b whatever t is
                    columns.append((b, [(c, (float(c == b), K[c, b], K2[c, b])) for c in range(3)
                                        if c == b or K[c, b] != 0 or K2[c, b] != 0]))
                self._joints.append(("R", w, np.cross(w, v), columns))
            else:
                self._joints.append(("P", v, None, None))
        self._tool = chain.g0[:3, 3].copy()
        self._tool_rotation = chain.g0[:3, :3].copy()
        if check:
            self._check(np.random.default_rng(0), check)

    # ------------------------------------------------------------ structure equations
    def _theta(self, Q) -> np.ndarray:
        """(n, N) joint displacements of the chain joints."""
        th = np.empty((len(self._reads), len(Q)))
        for k, (kind, iq, zero) in enumerate(self._reads):
            th[k] = Q[:, iq] - zero if kind == "linear" else np.arctan2(Q[:, iq + 1], Q[:, iq])
        return th

    def _block(self, th, pose: bool = False):
        """(N, 6, n) Jacobians of a block of configurations; arrays are laid out with the
        configurations last so that every operation is one numpy call on N numbers.
        pose: also the frame's rotations (N, 3, 3) and origins (N, 3)."""
        n, N = th.shape
        R = np.zeros((3, 3, N))  # R[b] = column b of the accumulated rotation, (3, N)
        R[0, 0] = R[1, 1] = R[2, 2] = 1.0
        p = np.zeros((3, N))
        axes = np.empty((n, 3, N))  # current joint axes w'
        points = np.empty((n, 3, N))  # a point of each current axis (revolute joints)
        J = np.empty((6, n, N))
        # sin and 1 - cos from the half-angle tangent: numpy's float64 tan is vectorized here
        # and sin, cos are not (8x faster for the pair; a few ulps either way)
        t = np.tan(0.5 * th)
        den = 2.0 / (1.0 + t * t)
        sines, versines = t * den, t * t * den
        scratch = np.empty((3, N))
        for k, (kind, a, point, columns) in enumerate(self._joints):
            Ra = _apply(R, a)  # R a: current axis (revolute) or direction (prismatic)
            if kind == "P":
                J[:3, k] = Ra
                J[3:, k] = 0.0
                p += th[k] * Ra
                continue
            axes[k] = Ra
            points[k] = p + _apply(R, point)
            coefficients = {}  # entries of Rot(a, theta) by their (I, K, K^2) weights
            new = []
            for b, terms in columns:  # column b of R Rot(a, theta) = sum_c R[c] Rot[c, b]
                acc = None
                for c, (one, ks, kv) in terms:
                    key = (one, ks, kv)
                    if key not in coefficients:
                        coefficients[key] = one + ks * sines[k] + kv * versines[k]
                    term = np.multiply(R[c], coefficients[key], out=scratch if acc is not None else None)
                    if acc is None:
                        acc = term
                    else:
                        acc += term
                new.append((b, acc))
            for b, col in new:  # p += (R - R Rot) point: the rotation moves the frame about the axis
                np.subtract(R[b], col, out=scratch)
                scratch *= point[b]
                p += scratch
            for b, col in new:
                R[b] = col
        pe = p + _apply(R, self._tool)  # the frame origin
        for k, (kind, *_rest) in enumerate(self._joints):
            if kind == "R":
                w, d = axes[k], pe - points[k]
                J[3:, k] = w
                J[0, k] = w[1] * d[2] - w[2] * d[1]
                J[1, k] = w[2] * d[0] - w[0] * d[2]
                J[2, k] = w[0] * d[1] - w[1] * d[0]
        if self.reference == pin.ReferenceFrame.WORLD:  # velocity of the point at the world origin: v - w x pe
            w = J[3:]
            J[0] -= w[1] * pe[2, None] - w[2] * pe[1, None]
            J[1] -= w[2] * pe[0, None] - w[0] * pe[2, None]
            J[2] -= w[0] * pe[1, None] - w[1] * pe[0, None]
        Re = None
        if self.reference == pin.ReferenceFrame.LOCAL or pose:
            Re = [_apply(R, self._tool_rotation[:, b]) for b in range(3)]  # columns of the frame rotation
        if self.reference == pin.ReferenceFrame.LOCAL:  # components in the frame: Re^T
            Jl = J.copy()
            for part in (slice(0, 3), slice(3, 6)):
                for b in range(3):
                    J[part][b] = sum(Re[b][a][None] * Jl[part][a] for a in range(3))
        if pose:
            return J.transpose(2, 0, 1), np.stack(Re, axis=1).transpose(2, 0, 1), pe.T
        return J.transpose(2, 0, 1)

    def __call__(self, Q) -> np.ndarray:
        """(N, 6, nv) Jacobians for the configurations in the rows of Q (N, nq)."""
        Q = np.atleast_2d(np.asarray(Q, float))
        if Q.ndim != 2 or Q.shape[1] != self.model.nq:
            raise ValueError(f"expected configurations of shape (N, {self.model.nq}), got {Q.shape}")
        th = self._theta(Q)
        out = np.zeros((len(Q), 6, self.model.nv))
        for start in range(0, len(Q), self.block):
            stop = min(start + self.block, len(Q))
            out[start:stop, :, self._cols] = self._block(np.ascontiguousarray(th[:, start:stop]))
        return out

    def poses(self, Q):
        """The frame's placements and chain Jacobians for Q (N, nq): rotations (N, 3, 3),
        origins (N, 3) and (N, 6, n) Jacobians restricted to the chain's n columns."""
        Q = np.atleast_2d(np.asarray(Q, float))
        th = self._theta(Q)
        parts = [self._block(np.ascontiguousarray(th[:, s:s + self.block]), pose=True)
                 for s in range(0, len(Q), self.block)]
        if not parts:
            n = len(th)
            return np.empty((0, 3, 3)), np.empty((0, 3)), np.empty((0, 6, n))
        return (np.concatenate([p[1] for p in parts]), np.concatenate([p[2] for p in parts]),
                np.concatenate([p[0] for p in parts]))

    def chain_jacobians(self, Q) -> np.ndarray:
        """(N, 6, n) the same Jacobians restricted to the n chain joints' columns."""
        Q = np.atleast_2d(np.asarray(Q, float))
        th = self._theta(Q)
        return np.concatenate([self._block(np.ascontiguousarray(th[:, s:s + self.block]))
                               for s in range(0, len(Q), self.block)]) if len(Q) else np.empty((0, 6, len(th)))

    def measures(self, Q, measure: str = "sigma_min", scale_translation: float | None = None, workers: int = 1,
                 method: str = "svd", point: bool = False) -> np.ndarray:
        """(N,) a singularity measure of the chain Jacobian at each configuration of Q (N, nq),
        block by block (the Jacobians of all N are never held at once).

        measure: "sigma_min" (smallest singular value), "sigma_ratio" (smallest over largest)
        or "det" (determinant; square Jacobians only, frame-independent).  For the singular
        values the Jacobian is made dimensionless as everywhere in screwkin: translations
        divided by ``scale_translation`` [m] (default: the mechanism's characteristic length
        ``Mechanism.length``), the columns of sliding joints multiplied by it.
        point: the frame origin as a point: only the 3 translation rows.
        method: see ``smallest_singular_values``.
        workers: threads, each taking whole blocks (numpy releases the GIL in its loops).
        """
        scale = float(scale_translation) if scale_translation else self.mech.length
        slide = np.array([kind == "P" for kind, *_ in self._joints], bool)
        slide = slide if slide.any() else None
        if measure not in ("sigma_min", "sigma_ratio", "det"):
            raise UsageError(f"unknown measure '{measure}': sigma_min, sigma_ratio or det")
        Q = np.atleast_2d(np.asarray(Q, float))
        if Q.ndim != 2 or Q.shape[1] != self.model.nq:
            raise ValueError(f"expected configurations of shape (N, {self.model.nq}), got {Q.shape}")
        n = len(self._cols)
        if measure == "det" and n != 6:
            raise UsageError(f"the chain to '{self.model.frames[self.frame].name}' has {n} joints: a determinant "
                             "needs a square (6 x 6) Jacobian; use sigma_min")
        th = self._theta(Q)
        out = np.empty(len(Q))

        def run(start):
            stop = min(start + self.block, len(Q))
            J = self._block(np.ascontiguousarray(th[:, start:stop]))
            if point:
                J = J[:, :3]
            if measure == "det":
                out[start:stop] = np.linalg.det(J)
            elif measure == "sigma_ratio":
                out[start:stop] = singular_value_ratios(J, scale, method=method, slide=slide)
            else:
                out[start:stop] = smallest_singular_values(J, scale, method=method, slide=slide)

        starts = range(0, len(Q), self.block)
        if workers > 1 and len(starts) > 1:
            with ThreadPoolExecutor(workers) as pool:
                list(pool.map(run, starts))
        else:
            for start in starts:
                run(start)
        return out

    def _check(self, rng, count):
        model = self.model
        data = self.mech.data
        lo = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -np.pi)
        hi = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, np.pi)
        lo, hi = np.maximum(lo, -np.pi), np.minimum(hi, np.pi)
        Q = np.array([pin.normalize(model, rng.uniform(lo, hi)) for _ in range(count)])
        ours = self(Q)
        for q, J in zip(Q, ours):
            ref = compute_frame_jacobian(model, data, q, self.frame, self.reference)
            err = float(np.abs(ref - J).max())
            if err > 1e-9 * max(1.0, float(np.abs(ref).max())):  # pragma: no cover - a bug, not an input error
                raise RuntimeError(f"batched Jacobian differs from Pinocchio's by {err:.1e}")


def _apply(R, x) -> np.ndarray:
    """R x for a stack of rotations stored by columns (R[b]: (3, N)) and a constant 3-vector x."""
    out = None
    for b in range(3):
        if x[b] != 0.0:
            term = R[b] * x[b]
            out = term if out is None else out + term
    return out if out is not None else np.zeros(R.shape[1:])


def singular_values(J) -> np.ndarray:
    """(N, min(m, n)) singular values of a stack of matrices (N, m, n), largest first."""
    return np.linalg.svd(np.asarray(J), compute_uv=False)


def smallest_singular_values(J, scale_translation: float = 1.0, method: str = "svd", slide=None) -> np.ndarray:
    """(N,) smallest singular value of each Jacobian in the stack, translations divided by a
    characteristic length ``scale_translation`` [m] (and the columns of sliding joints, the
    mask ``slide``, multiplied by it) so that the values are dimensionless.

    method "svd": singular values of each matrix (LAPACK gesdd).  method "gram": the
    smallest eigenvalue of J^T J (symmetric eigensolver, about twice as fast), where
    sigma_min >= 1e-3 sigma_max; its relative error there is at most about
    eps (sigma_max / sigma_min)^2 < 1e-9; matrices closer to singular take the SVD.
    """
    return _extreme_singular_values(J, scale_translation, method, slide)[0]


def singular_value_ratios(J, scale_translation: float = 1.0, method: str = "svd", slide=None) -> np.ndarray:
    """(N,) smallest over largest singular value of each Jacobian (translations divided by
    ``scale_translation``, see ``smallest_singular_values``); methods as there."""
    low, high = _extreme_singular_values(J, scale_translation, method, slide)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(high > 0, low / high, 0.0)


def _extreme_singular_values(J, scale_translation, method, slide=None):
    J = np.array(J, float)
    if J.ndim != 3:
        raise ValueError(f"expected a stack of matrices (N, m, n), got shape {J.shape}")
    J[:, :3, :] /= scale_translation
    if slide is not None:
        J[:, :, slide] *= scale_translation
    if method == "svd":
        s = singular_values(J)
        return s[:, -1], s[:, 0]
    if method != "gram":
        raise UsageError(f"unknown method '{method}': svd or gram")
    if J.shape[1] < J.shape[2]:  # wide: the Gram matrix J^T J is singular; use J J^T
        J = J.transpose(0, 2, 1)
    lam = np.linalg.eigvalsh(np.matmul(J.transpose(0, 2, 1), J))
    low, high = np.sqrt(np.maximum(lam[:, 0], 0.0)), np.sqrt(np.maximum(lam[:, -1], 0.0))
    near = lam[:, 0] < _GRAM_KAPPA**2 * lam[:, -1]
    if near.any():
        s = singular_values(J[near])
        low[near], high[near] = s[:, -1], s[:, 0]
    return low, high


_GRAM_KAPPA = 1e-3  # below this sigma_min / sigma_max the Gram eigenvalue loses digits: use the SVD


def determinants(J) -> np.ndarray:
    """(N,) determinants of a stack of square matrices (N, n, n) (LU with partial pivoting)."""
    return np.linalg.det(np.asarray(J))


# ---------------------------------------------------------------------------------------------
# loop closure for stacks of configurations


class Unbatchable(Exception):
    """The mechanism holds something the batched closure does not represent (joints of more
    than one coordinate, <mimic> joints, helical joints, sliding contacts): the caller solves
    one configuration at a time with model.closure.ClosureSystem instead."""


class TreeKinematics:
    """Placements and LOCAL_WORLD_ALIGNED Jacobians of frames of a tree of 1-DOF revolute and
    prismatic joints for stacks of configurations: one pass down the tree per stack (each
    joint's placement once: Pinocchio's forwardKinematics written for N configurations).  Each
    joint costs one matrix product of its parent's N rotations with a constant 3 x 11 matrix
    (Rodrigues' formula split into constant parts, the placement's translation and the axis)
    and a few elementwise operations.  Joint axes and placements are Pinocchio's; BatchClosure
    checks the rows built on them against Pinocchio's."""

    _AXES = {"JointModelRX": (1, 0, 0), "JointModelRY": (0, 1, 0), "JointModelRZ": (0, 0, 1),
             "JointModelPX": (1, 0, 0), "JointModelPY": (0, 1, 0), "JointModelPZ": (0, 0, 1)}

    def __init__(self, mech):
        model = mech.model
        self.model = model
        if model.nq != model.nv:
            raise Unbatchable(f"{mech.path}: joints of more than one coordinate")
        data = model.createData() if model.njoints < 64 else mech.data
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
        self.supports = {}
        self._frames = {}

    def _support(self, jid):
        """(joint ids, which are revolute, velocity columns) of the joints moving joint jid."""
        if jid not in self.supports:
            sup = [int(j) for j in self.model.supports[jid] if j > 0]
            self.supports[jid] = (np.array(sup, int), np.array([self.joints[j - 1][1] == "R" for j in sup], bool),
                                  np.array([self.model.idx_vs[j] for j in sup], int)) if sup else None
        return self.supports[jid]

    def _frame(self, f):
        """(parent joint, [R | t]^T of the frame's placement) of frame f."""
        if f not in self._frames:
            frame = self.model.frames[f]
            self._frames[f] = (frame.parentJoint,
                               np.hstack([frame.placement.rotation, frame.placement.translation[:, None]]).T.copy())
        return self._frames[f]

    def frames(self, Q, frame_ids, jacobian: bool = True) -> dict:
        """{frame id: (R (N, 3, 3), p (N, 3), J (N, 6, n), cols (n,))}: rotation, origin and the
        frame's Jacobian (linear velocity of its origin, angular velocity; world axes) on the
        velocity columns ``cols`` of the joints that move it (J and cols None for a frame
        fixed to the ground, and without ``jacobian``)."""
        model = self.model
        Q = np.atleast_2d(np.asarray(Q, float))
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
            XT = C @ RTs[parent]  # (C is kept transposed)
            pos = ps[parent] + XT[9].reshape(N, 3)
            w = XT[10].reshape(N, 3)
            if kind == "R":  # A Rot(a, th) = A + sin(th) A [a]x + (1 - cos(th)) A [a]x^2, A = R_parent R_placement
                RT = XT[0:3] + sines[iq] * XT[3:6] + versines[iq] * XT[6:9]
            else:
                RT = XT[0:3]
                pos = pos + w * Q[:, iq, None]
            RTs[j], ps[j], ws[j] = RT, pos, w
        Wall = np.stack([np.zeros((N, 3))] + ws[1:], axis=2)  # (N, 3, njoints)
        Pall = np.stack(ps, axis=2)
        out = {}
        for f in frame_ids:
            jid, CfT = self._frame(f)
            XT = CfT @ RTs[jid]
            Rf = XT[0:3].reshape(3, N, 3).transpose(1, 2, 0)
            pf = ps[jid] + XT[3].reshape(N, 3)
            support = self._support(jid) if jacobian else None
            if not support:
                out[f] = (Rf, pf, None, None)
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


class BatchClosure:
    """The loop-closure rows of ``mech`` (the same rows, in the same order, as its
    model.closure.ClosureSystem) for many configurations at once, and a damped-Newton solver
    that moves all of them together: every iteration is a few numpy calls on the whole stack
    instead of one Pinocchio pass and one linear solve per configuration.

    Frame placements and Jacobians come from the product-of-exponentials structure equations
    of the chains from the ground to each cut-joint frame (SerialJacobians); the rows are
    checked against ClosureSystem.evaluate, at random configurations for the solver's rows and
    at the mechanism's closed ones for the constraint Jacobian, when the object is built.

    target: None, or (link, "pose" | "point"): one more cut joint, a weld ("pose") or a ball
    joint ("point") between the output link and a ground frame whose placement is given per
    configuration (``targets``: origins (N, 3), and a rotation (3, 3) shared by all) -- the
    inverse kinematics of a workspace grid.

    Raises Unbatchable for what it does not represent.
    """

    def __init__(self, mech, target=None, check: int = 3):
        model = mech.model
        self.mech, self.model = mech, model
        if model.nq != model.nv:
            raise Unbatchable(f"{mech.path}: joints of more than one coordinate")
        if any(not isinstance(e, CouplingRow) for e in mech.extra_rows):
            raise Unbatchable(f"{mech.path}: sliding contacts (higher pairs)")
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
        self.system = ClosureSystem(model, cuts, mech.tolerances, mech.path, data=mech.data, extra=mech.extra_rows)
        self.nrows = self.system.nrows
        self.solver_rows = self.system._rows(True)
        # which of the solver's rows are lengths [m] (positions; the couplings of rolling and screw
        # pairs), the others dimensionless
        mask = []
        for c, (P, pairs, vectors, _) in zip(cuts, self.system.plans):
            rest = self.system._cut_rows(c, (P, pairs, vectors, None), True) - len(P)
            mask += [True] * len(P) + [False] * rest
        self.solver_position_rows = np.array(mask + [True] * len(mech.extra_rows), bool)
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
    def _frames(self, Q, jacobian: bool = True):
        """{frame id: (R (N, 3, 3), p (N, 3), J (N, 6, n) LOCAL_WORLD_ALIGNED on the chain's
        columns, columns (n,))}; J and the columns None for a frame on the ground (and for
        every frame without ``jacobian``)."""
        return self.tree.frames(Q, self._frame_ids, jacobian)

    def _placements(self, c, frames, targets, N):
        """(R1, t1, J1, cols1, R2, t2, J2, cols2) of cut joint c (J None: the frame does not move)."""
        if c.frame1 == self.mech.target_frame:
            t, Rt = targets
            first = (np.broadcast_to(np.asarray(Rt, float), (N, 3, 3)), np.asarray(t, float), None, None)
        else:
            first = frames[c.frame1]
        return first + frames[c.frame2]

    # ------------------------------------------------------------------ rows
    def evaluate(self, Q, targets=None, jacobian: bool = True):
        """The solver's rows (ClosureSystem.evaluate(solver=True)) of every configuration:
        r (N, rows) and K (N, rows, nv) (None without ``jacobian``)."""
        return self._rows(Q, targets, jacobian, solver=True)

    def constraint_jacobians(self, Q, targets=None) -> np.ndarray:
        """The minimal rows' Jacobian K (N, rows, nv) (ClosureSystem.jacobian) of configurations
        that close the loops: a rotation vector's rows use the derivative of log3 at the
        identity, which they are at within the closure tolerance."""
        return self._rows(Q, targets, True, solver=False)[1]

    def _rows(self, Q, targets, jacobian, solver):
        Q = np.atleast_2d(np.asarray(Q, float))
        N, nv = len(Q), self.model.nv
        if self.target is not None and targets is None:
            raise ValueError("this closure has a target: give its placements")
        frames = self._frames(Q, jacobian)
        nrows = self.solver_rows if solver else self.nrows
        r = np.empty((N, nrows))
        K = np.zeros((N, nrows, nv)) if jacobian else None

        def add(rows, cols, A):  # K[:, rows, cols] += A (N, len(rows), len(cols))
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
                    add(rows, c2, _times(E, J2[:, :3]))
                if J1 is not None:
                    add(rows, c1, _times(E, _cross_columns(d, J1[:, 3:]) - J1[:, :3]))
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
                        add(slice(i, i + 3), c2, _times(R2t, J2[:, 3:]))
                    if J1 is not None:
                        add(slice(i, i + 3), c1, -_times(R2t, J1[:, 3:]))
                i += 3
                continue
            for u0, w0 in pairs:  # alignments u . w; derivative (w x u) . (w2 - w1)
                u, w = R1 @ np.asarray(u0, float), R2 @ np.asarray(w0, float)
                r[:, i] = np.einsum("ni,ni->n", u, w)
                if jacobian:
                    wu = np.cross(w, u)[:, None, :]
                    if J2 is not None:
                        add(slice(i, i + 1), c2, _times(wu, J2[:, 3:]))
                    if J1 is not None:
                        add(slice(i, i + 1), c1, -_times(wu, J1[:, 3:]))
                i += 1
        for iq, iv, coef, const in self.couplings:
            r[:, i] = Q[:, iq] @ coef + const
            if jacobian:
                for v, cf in zip(iv, coef):
                    K[:, i, v] += cf
            i += 1
        return r, K

    def reversed_axes(self, Q) -> np.ndarray:
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
    def solve(self, Q0, targets=None, frozen=(), tolerances=None, iterations: int | None = None):
        """Damped Newton (Levenberg-Marquardt, minimum-norm steps, the damping of each
        configuration its own) from every row of Q0 at once, as ClosureSystem.solve does for
        one.  frozen: velocity indices that do not move (inputs).  Returns (Q, converged (N,),
        residual norms (N,), iterations (N,)); a configuration that converges with a reversed
        revolute cut joint counts as not converged."""
        tol = tolerances or self.mech.tolerances
        max_it = int(iterations if iterations is not None else tol.max_iterations)
        Q = np.array(np.atleast_2d(Q0), float)
        N, nv = Q.shape[0], self.model.nv
        free = np.setdiff1d(np.arange(nv), np.asarray(frozen, int))
        its = np.zeros(N, int)
        if self.solver_rows == 0 or N == 0:
            return Q, np.ones(N, bool), np.zeros(N), its
        tgt = targets
        r, K = self.evaluate(Q, tgt)
        norm = np.linalg.norm(r, axis=1)
        mu, nu = np.full(N, 1e-9), np.full(N, 2.0)
        active = norm >= tol.closure
        for _ in range(max_it):
            idx = np.flatnonzero(active)
            if not len(idx):
                break
            its[idx] += 1
            Kf = K[idx][:, :, free]
            ri = r[idx]
            dqf, lin2 = damped_steps(Kf, ri, mu[idx])
            Qn = Q[idx].copy()
            Qn[:, free] += dqf
            sub = None if tgt is None else (tgt[0][idx], tgt[1])
            rn, Kn = self.evaluate(Qn, sub)
            nn = np.linalg.norm(rn, axis=1)
            ok = nn < norm[idx]
            # Nielsen's damping update from the gain ratio (actual / predicted decrease)
            n0 = norm[idx]
            predicted = n0**2 - lin2
            with np.errstate(divide="ignore", invalid="ignore"):
                rho = np.where(predicted > 0, (n0**2 - nn**2) / predicted, 0.0)
            a = idx[ok]
            mu[a] = np.maximum(mu[a] * np.maximum(1.0 / 3.0, 1.0 - (2.0 * rho[ok] - 1.0) ** 3), 1e-12)
            nu[a] = 2.0
            Q[a], r[a], K[a], norm[a] = Qn[ok], rn[ok], Kn[ok], nn[ok]
            b = idx[~ok]
            mu[b] *= nu[b]
            nu[b] *= 2.0
            active[idx] = (norm[idx] >= tol.closure) & (mu[idx] <= 1e10)
        converged = norm < tol.closure
        if converged.any():
            c = np.flatnonzero(converged)
            converged[c] &= ~self.reversed_axes(Q[c])
        return Q, converged, norm, its

    # ------------------------------------------------------------------ self-check
    def _check(self, rng, count):
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
                    pin.framesForwardKinematics(model, mech.data, q)
                    M = mech.data.oMf[self.cuts[-1].frame2]
                    placement = M if is_closed else pin.SE3(M.rotation, M.translation + 0.01)
                    frame.placement = placement
                    model.frames[mech.target_frame] = frame
                    targets = (placement.translation[None], placement.rotation)
                if is_closed:
                    ours, ref = self.constraint_jacobians(q[None], targets)[0], system.jacobian(q)
                else:
                    r, K = self.evaluate(q[None], targets)
                    r_ref, K_ref = system.evaluate(q, True, solver=True)
                    ours, ref = np.hstack([r[0][:, None], K[0]]), np.hstack([r_ref[:, None], K_ref])
                err = float(np.abs(ours - ref).max()) if ref.size else 0.0
                if err > 1e-8 * max(1.0, float(np.abs(ref).max()) if ref.size else 1.0):  # pragma: no cover - a bug
                    raise RuntimeError(f"{mech.path}: batched closure rows differ from ClosureSystem's by {err:.1e}")
        finally:
            frame.placement = saved
            model.frames[mech.target_frame] = frame


def _times(A, B) -> np.ndarray:
    """A @ B for stacks A (N, k, 3), B (N, 3, n): three broadcast products (numpy's stacked
    matmul on 3-long inner products costs several times more)."""
    return A[:, :, 0, None] * B[:, None, 0] + A[:, :, 1, None] * B[:, None, 1] + A[:, :, 2, None] * B[:, None, 2]


def _rows_times(P, Rt) -> np.ndarray:
    """P @ Rt for a constant P (k, 3) and a stack Rt (N, 3, 3)."""
    return np.einsum("ki,nij->nkj", P, Rt)


def _apply_rows(E, d) -> np.ndarray:
    """E @ d for stacks E (N, k, 3), d (N, 3)."""
    return E[:, :, 0] * d[:, 0, None] + E[:, :, 1] * d[:, 1, None] + E[:, :, 2] * d[:, 2, None]


def _cross_columns(a, W) -> np.ndarray:
    """a x w for every column w of W: a (N, 3), W (N, 3, n) -> (N, 3, n)."""
    a0, a1, a2 = a[:, 0, None], a[:, 1, None], a[:, 2, None]
    return np.stack([a1 * W[:, 2] - a2 * W[:, 1], a2 * W[:, 0] - a0 * W[:, 2], a0 * W[:, 1] - a1 * W[:, 0]], axis=1)


def damped_steps(Kf, r, mu):
    """model.closure._damped_step for a stack: Kf (N, m, n), r (N, m), mu (N,) ->
    (steps (N, n), squared residuals of the linear model (N,))."""
    N, m, n = Kf.shape
    tall = m > n
    Kt = Kf.transpose(0, 2, 1)
    A = Kt @ Kf if tall else Kf @ Kt
    size = A.shape[1]
    trace = np.trace(A, axis1=1, axis2=2)
    A[:, np.arange(size), np.arange(size)] += (mu * np.maximum(trace / m, 1e-12))[:, None]
    b = (Kt @ r[:, :, None])[:, :, 0] if tall else r
    try:
        y = np.linalg.solve(A, b[:, :, None])[:, :, 0]
    except np.linalg.LinAlgError:  # one of them singular in floating point: least squares for all
        y = np.stack([np.linalg.lstsq(Ai, bi, rcond=None)[0] for Ai, bi in zip(A, b)])
    dq = -y if tall else -(Kt @ y[:, :, None])[:, :, 0]
    lin = r + (Kf @ dq[:, :, None])[:, :, 0]
    return dq, np.einsum("ni,ni->n", lin, lin)


def _log3(R) -> np.ndarray:
    """Rotation vectors of a stack of rotations (N, 3, 3) (pinocchio.log3 for each; angles
    below pi)."""
    c = np.clip((np.trace(R, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    theta = np.arccos(c)
    s = np.sin(theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(theta < 1e-8, 0.5 + theta**2 / 12.0, theta / (2.0 * s))
    v = np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], axis=1)
    return v * f[:, None]
