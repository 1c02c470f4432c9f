"""pin.integrate for a stack of configurations: q (+) v on the configuration manifold, joint by
joint, for N configurations at once.

Pinocchio integrates one configuration per call from Python.  ``Integrator(model)(Q, V)`` gives
``pin.integrate(model, Q[n], V[n])`` for every n with a few numpy operations per joint type,
written as Pinocchio writes them (its liegroup/*.hxx, version 4): coordinates of a vector space
(revolute, prismatic, helical, translation, universal and spherical-ZYX joints) add; a continuous
joint's (cos, sin) turns by the angle and is renormalized to first order; a ball joint's
quaternion (x, y, z, w) is multiplied by exp3 of the rotation; a free flyer's placement by exp6
of the twist (rotation then translation in the body's axes); a planar joint's (x, y, cos, sin) by
the planar exponential.  tests/model/test_manifold.py compares the result with pin.integrate on random
stacks of every joint type (to 1e-15).  A joint of another kind (a composite or mimic joint)
integrates the whole stack one configuration at a time with pin.integrate, as does a stack of one
(one call to Pinocchio costs less than the numpy operations).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .geometry import quaternion_product

__all__ = ["Integrator", "continuous_angle", "set_continuous_angle"]

_VECTOR = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned", "JointModelPX",
           "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned", "JointModelHX", "JointModelHY",
           "JointModelHZ", "JointModelHelicalUnaligned", "JointModelTranslation", "JointModelSphericalZYX",
           "JointModelUniversal")
_UNBOUNDED = ("JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned")
_GROUPS = {"JointModelSpherical": "so3", "JointModelFreeFlyer": "se3", "JointModelPlanar": "se2",
           **{k: "so2" for k in _UNBOUNDED}}
_EPS = np.finfo(float).eps
_TAYLOR = _EPS ** 0.25  # Pinocchio's TaylorSeriesExpansion<double>::precision<3>()
#: Below this turn rate [rad] a planar joint's exponential is the straight-line one (Pinocchio's
#: SE(2) exp, written as a literal there too).
SE2_STRAIGHT = 1e-14


def continuous_angle(q: np.ndarray, i: int) -> np.ndarray | float:
    """The angle [rad] of the continuous joint whose (cos, sin) stand at q[..., i], q[..., i + 1]:
    atan2(sin, cos), in (-pi, pi]; for a stack of configurations (N, nq), one per row.

    >>> float(continuous_angle(np.array([0.5, 0.0, 1.0]), 1))
    1.5707963267948966
    """
    return np.arctan2(q[..., i + 1], q[..., i])


def set_continuous_angle(q: np.ndarray, i: int, angle: np.ndarray | float) -> None:
    """Write ``angle`` [rad] (a number, or one per row of a stack q (N, nq)) as the (cos, sin) of the
    continuous joint at q[..., i], q[..., i + 1], in place."""
    q[..., i] = np.cos(angle)
    q[..., i + 1] = np.sin(angle)


class Integrator:
    """q (+) v for stacks: ``Integrator(model)(Q (N, nq), V (N, nv)) -> (N, nq)``."""

    def __init__(self, model: pin.Model) -> None:
        self.model = model
        vector_q, vector_v = [], []
        groups = {"so2": ([], []), "so3": ([], []), "se3": ([], []), "se2": ([], [])}
        self.per_configuration = False  # a joint the numpy forms do not cover
        for j in range(1, model.njoints):
            short, iq, iv = model.joints[j].shortname(), model.idx_qs[j], model.idx_vs[j]
            nq, nv = model.nqs[j], model.nvs[j]
            if short in _VECTOR and nq == nv:
                vector_q += range(iq, iq + nq)
                vector_v += range(iv, iv + nv)
            elif short in _GROUPS:
                q_list, v_list = groups[_GROUPS[short]]
                q_list.append(np.arange(iq, iq + nq))
                v_list.append(np.arange(iv, iv + nv))
            else:
                self.per_configuration = True
        self.vector = (np.array(vector_q, int), np.array(vector_v, int))
        self.groups = {g: (np.array(qs, int), np.array(vs, int)) for g, (qs, vs) in groups.items() if qs}
        # all coordinates add, in the same order: Q + V itself
        self.plain = not self.groups and not self.per_configuration and model.nq == model.nv and (
            np.array_equal(self.vector[0], np.arange(model.nq)) and np.array_equal(self.vector[1], np.arange(model.nv)))

    def __call__(self, Q: np.ndarray | tuple, V: np.ndarray) -> np.ndarray:
        if self.plain:
            return Q + V
        Q, V = np.asarray(Q, float), np.asarray(V, float)
        if len(Q) == 1 or self.per_configuration:
            return np.array([pin.integrate(self.model, q, v) for q, v in zip(Q, V)]).reshape(Q.shape)
        out = Q.copy()
        iq, iv = self.vector
        out[:, iq] += V[:, iv]
        for group, (iq, iv) in self.groups.items():
            # (N, joints, coordinates) -> the joints of one kind stacked as N * joints rows
            q, v = Q[:, iq].reshape(-1, iq.shape[1]), V[:, iv].reshape(-1, iv.shape[1])
            out[:, iq] = _INTEGRATE[group](q, v).reshape(len(Q), *iq.shape)
        return out


def _so2(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(cos, sin) turned by the angle v, renormalized to first order."""
    c, s = np.cos(v[:, 0]), np.sin(v[:, 0])
    out = np.stack([c * q[:, 0] - s * q[:, 1], s * q[:, 0] + c * q[:, 1]], axis=1)
    return out * ((3.0 - np.einsum("ni,ni->n", out, out)) / 2.0)[:, None]


def _exp3(w: np.ndarray) -> np.ndarray:
    """Unit quaternions (x, y, z, w) of the rotations exp([w]x) (Pinocchio's quaternion::exp3)."""
    t2 = np.einsum("ni,ni->n", w, w)
    t = np.sqrt(t2 + _EPS * _EPS)
    half = 0.5 * t
    far = np.stack([*(np.sin(half)[:, None] * (w / t[:, None])).T, np.cos(half)], axis=1)
    h2 = t2 / 4.0  # order 4 Taylor expansion in the angle near 0
    near = np.concatenate([(0.5 * (1.0 - h2 / 6.0 + h2 * h2 / 120.0))[:, None] * w,
                           (1.0 - h2 / 2.0 + h2 * h2 / 24.0)[:, None]], axis=1)
    return np.where((t2 > _TAYLOR)[:, None], far, near)


def _normalize(quat: np.ndarray) -> np.ndarray:
    """Pinocchio's quaternion::firstOrderNormalize: times (3 - |q|^2) / 2."""
    return quat * ((3.0 - np.einsum("ni,ni->n", quat, quat)) / 2.0)[:, None]


def _rotate(quat: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The vectors x turned by the unit quaternions quat (Eigen's q * v: v + 2 w (u x v) + 2 u x (u x v))."""
    u, w = quat[:, :3], quat[:, 3:]
    uv = 2.0 * np.cross(u, x)
    return x + w * uv + np.cross(u, uv)


def _so3(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    return _normalize(quaternion_product(q, _exp3(v)))


def _se3(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Free flyer (x, y, z, quaternion) moved by exp6 of the twist v = (linear, angular) in its own axes."""
    lin, w = v[:, :3], v[:, 3:]
    t2 = np.einsum("ni,ni->n", w, w) + _EPS * _EPS
    t = np.sqrt(t2)
    ct, st, inv_t2 = np.cos(t), np.sin(t), 1.0 / t2
    small = t < _TAYLOR
    a = np.where(small, 0.5 - t2 / 24.0, (1.0 - ct) * inv_t2)[:, None]
    b = np.where(small, 1.0 / 6.0 - t2 / 120.0, (t - st) * inv_t2 / t)[:, None]
    wv = np.cross(w, lin)
    trans = lin + a * wv + b * np.cross(w, wv)
    quat = q[:, 3:]
    turned = quaternion_product(quat, _exp3(w))
    turned = np.where((np.einsum("ni,ni->n", turned, quat) < 0.0)[:, None], -turned, turned)
    return np.concatenate([_rotate(quat, trans) + q[:, :3], _normalize(turned)], axis=1)


def _se2(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Planar joint (x, y, cos, sin) moved by the planar exponential of v = (vx, vy, omega)."""
    omega = v[:, 2]
    cv, sv = np.cos(omega), np.sin(omega)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = (-v[:, 1] - (-v[:, 1] * cv + v[:, 0] * -sv)) / omega
        ty = (v[:, 0] - (-v[:, 1] * sv + v[:, 0] * cv)) / omega
    straight = np.abs(omega) <= SE2_STRAIGHT
    tx, ty = np.where(straight, v[:, 0], tx), np.where(straight, v[:, 1], ty)
    c0, s0 = q[:, 2], q[:, 3]
    return np.stack([c0 * tx - s0 * ty + q[:, 0], s0 * tx + c0 * ty + q[:, 1], c0 * cv - s0 * sv,
                     s0 * cv + c0 * sv], axis=1)


_INTEGRATE = {"so2": _so2, "so3": _so3, "se3": _se3, "se2": _se2}
