"""Measures over many configurations at once: arrays of q in, arrays out.

Two ways to the Jacobians of a stack of configurations:

- ``frame_jacobians``: one Pinocchio call per configuration (about a microsecond
  each from Python), for any model;
- ``SerialJacobians``: the product-of-exponentials structure equations of the
  chain from the ground to a frame (screws.chains: joint twists and the home
  placement read from Pinocchio), evaluated for thousands of configurations per
  numpy call.  Python pays its overhead once per joint per block of
  configurations instead of once per configuration.  Its Jacobians equal
  Pinocchio's (tests/analysis/singularities/test_batch.py; ``check=N`` compares them again when it is
  built), and it refuses chains it cannot represent (joints with more than one
  DOF, helical joints).

The measures (singular values, determinants) are one numpy call on the whole stack.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pinocchio as pin

from ...errors import UsageError
from ...model._pin import compute_frame_jacobian
from ...model.manifold import continuous_angle
from ..screws import chains
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["frame_jacobians", "SerialJacobians", "stack_singular_values", "smallest_singular_values",
           "singular_value_ratios", "determinants"]

_REFERENCES = (pin.ReferenceFrame.WORLD, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED, pin.ReferenceFrame.LOCAL)


def frame_jacobians(model: pin.Model, frame_id: int, Q: np.ndarray, reference: pin.ReferenceFrame=pin.ReferenceFrame.WORLD, data=None) -> np.ndarray:
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

    def __init__(self, mech: Mechanism, link: str | None, reference: pin.ReferenceFrame=pin.ReferenceFrame.LOCAL_WORLD_ALIGNED, block: int = 8192,
                 check: int = 0, chain=None) -> None:
        """chain: a screws.Chain to any frame instead of the one to ``link``'s body frame."""

        if reference not in _REFERENCES:
            raise UsageError(f"unknown reference frame {reference}")
        self.mech, self.model, self.reference, self.block = mech, mech.model, reference, int(block)
        if chain is None:
            chain = next(c for c in chains(mech, output=link) if c.name == f"output {link}")
        self.frame = chain.frame
        if not chain.joints:
            raise UsageError(f"{mech.path}: no moving joint lies between the ground and "
                             f"'{chain.name.removeprefix('output ')}'")
        self.chain = chain
        model = self.model
        self._cols = list(chain.columns)
        # how each chain joint's displacement theta is read from q (relative to the neutral configuration)
        self._reads = []
        neutral = mech.neutral()
        for name, _col in zip(chain.joints, chain.columns):
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
    def _theta(self, Q: np.ndarray) -> np.ndarray:
        """(n, N) joint displacements of the chain joints."""
        th = np.empty((len(self._reads), len(Q)))
        for k, (kind, iq, zero) in enumerate(self._reads):
            th[k] = Q[:, iq] - zero if kind == "linear" else continuous_angle(Q, iq)
        return th

    def _block(self, th: np.ndarray, pose: bool = False) -> tuple:
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

    def __call__(self, Q: np.ndarray | tuple) -> np.ndarray:
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

    def poses(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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

    def measures(self, Q: np.ndarray, measure: str = "sigma_min", scale_translation: float | None = None, workers: int = 1,
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

        def run(start) -> None:
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

    def _check(self, rng: np.random.Generator, count: int) -> None:
        model = self.model
        data = self.mech.scratch_data()
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


def _apply(R: np.ndarray, x: np.ndarray) -> np.ndarray:
    """R x for a stack of rotations stored by columns (R[b]: (3, N)) and a constant 3-vector x."""
    out = None
    for b in range(3):
        if x[b] != 0.0:
            term = R[b] * x[b]
            out = term if out is None else out + term
    return out if out is not None else np.zeros(R.shape[1:])


def stack_singular_values(J: np.ndarray) -> np.ndarray:
    """(N, min(m, n)) singular values of a stack of matrices (N, m, n), largest first."""
    return np.linalg.svd(np.asarray(J), compute_uv=False)


def smallest_singular_values(J: np.ndarray | tuple, scale_translation: float = 1.0, method: str = "svd", slide=None) -> np.ndarray:
    """(N,) smallest singular value of each Jacobian in the stack, translations divided by a
    characteristic length ``scale_translation`` [m] (and the columns of sliding joints, the
    mask ``slide``, multiplied by it) so that the values are dimensionless.

    method "svd": singular values of each matrix (LAPACK gesdd).  method "gram": the
    smallest eigenvalue of J^T J (symmetric eigensolver, about twice as fast), where
    sigma_min >= 1e-3 sigma_max; its relative error there is at most about
    eps (sigma_max / sigma_min)^2 < 1e-9; matrices closer to singular take the SVD.
    """
    return _extreme_singular_values(J, scale_translation, method, slide)[0]


def singular_value_ratios(J: np.ndarray | tuple, scale_translation: float = 1.0, method: str = "svd", slide=None) -> np.ndarray:
    """(N,) smallest over largest singular value of each Jacobian (translations divided by
    ``scale_translation``, see ``smallest_singular_values``); methods as there."""
    low, high = _extreme_singular_values(J, scale_translation, method, slide)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(high > 0, low / high, 0.0)


def _extreme_singular_values(J: np.ndarray, scale_translation: float, method: str, slide=None) -> tuple:
    J = np.array(J, float)
    if J.ndim != 3:
        raise ValueError(f"expected a stack of matrices (N, m, n), got shape {J.shape}")
    J[:, :3, :] /= scale_translation
    if slide is not None:
        J[:, :, slide] *= scale_translation
    if method == "svd":
        s = stack_singular_values(J)
        return s[:, -1], s[:, 0]
    if method != "gram":
        raise UsageError(f"unknown method '{method}': svd or gram")
    if J.shape[1] < J.shape[2]:  # wide: the Gram matrix J^T J is singular; use J J^T
        J = J.transpose(0, 2, 1)
    lam = np.linalg.eigvalsh(np.matmul(J.transpose(0, 2, 1), J))
    low, high = np.sqrt(np.maximum(lam[:, 0], 0.0)), np.sqrt(np.maximum(lam[:, -1], 0.0))
    near = lam[:, 0] < _GRAM_KAPPA**2 * lam[:, -1]
    if near.any():
        s = stack_singular_values(J[near])
        low[near], high[near] = s[:, -1], s[:, 0]
    return low, high


_GRAM_KAPPA = 1e-3  # below this sigma_min / sigma_max the Gram eigenvalue loses digits: use the SVD


def determinants(J: np.ndarray) -> np.ndarray:
    """(N,) determinants of a stack of square matrices (N, n, n) (LU with partial pivoting)."""
    return np.linalg.det(np.asarray(J))


# ---------------------------------------------------------------------------------------------
# loop closure for stacks of configurations
