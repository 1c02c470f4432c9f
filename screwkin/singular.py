"""Singularity analysis at a configuration (Gosselin-Angeles, Zlatanov-Fenton-Benhabib).

With V a basis of the joint rates the loops allow (null space of K), inputs a
and passive joints p, and an output link o:

- constraint singularity: rank K drops below its generic value: the mobility
  changes or branches meet; the extra motion is reported;
- actuator (direct-kinematic) singularity: with the inputs locked the passive
  joints can still move (beyond the idle spins): K_p loses rank;
- serial (inverse-kinematic) singularity: the output link loses a direction of
  motion: rank(J_o V) drops below its generic value;
- stationary joints: joints whose rate the loops force to zero (their row of V
  vanishes), while generically they move.

Each measure is a singular value relative to the largest of its matrix; mixed
translation/rotation quantities are made dimensionless with a characteristic
length L (translations divided by L), stated in the result.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ._pin import frame_jacobian
from .mobility import null_space, rank
from .screws import screw_of

__all__ = ["SingularityReport", "classify"]

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class SingularTwist:
    kind: str  # "actuator" | "serial" | "constraint"
    joint_rates: dict  # joint name -> rate of the motion (unit norm)
    twist: tuple | None  # output twist (v, w) of that motion, or the lost direction
    screw: dict | None


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

    def to_dict(self) -> dict:
        return {
            "serial": self.serial, "actuator": self.actuator, "constraint": self.constraint,
            "stationary_joints": list(self.stationary_joints), "sigma_min": self.sigma_min,
            "sigmas": self.sigmas, "condition": self.condition, "manipulability": self.manipulability,
            "characteristic_length": self.length, "inputs": list(self.inputs), "output": self.output,
            "singular_twists": [{"kind": t.kind, "joint_rates": t.joint_rates,
                                 "twist": list(t.twist) if t.twist is not None else None, "screw": t.screw}
                                for t in self.singular_twists],
        }


def characteristic_length(mech, q) -> float:
    """RMS distance of the joint centres from their centroid [m] (at least 1 mm)."""
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    pts = np.array([data.oMf[f].translation for f, fr in enumerate(mech.model.frames)
                    if fr.type == pin.FrameType.JOINT])
    if len(pts) < 2:
        return 1.0
    return max(float(np.sqrt(np.mean(np.sum((pts - pts.mean(0)) ** 2, axis=1)))), 1e-3)


def _rel(s, k):
    """k-th singular value (1-based) relative to the largest; 0 when missing."""
    if k <= 0:
        return 1.0
    if len(s) < k or s[0] <= 0:
        return 0.0
    return float(s[k - 1] / s[0])


class Generic:
    """Generic ranks of a mechanism for given inputs and output, measured at the
    assembled configurations of the mobility analysis."""

    def __init__(self, mech, inputs, output=None):
        tol = mech.tolerances
        mob = mech.mobility(output=output)
        self.rank_K = mob.rank
        self.idle = mob.idle_dofs
        self.a = mech.velocity_indices(inputs)
        self.p = np.setdiff1d(np.arange(mech.nv), self.a)
        K = mech.closure.jacobian(mob.q)
        self.rank_Kp = rank(K[:, self.p], tol) if K.size else 0
        self.out_dim = mob.output.dimension if mob.output is not None else None
        V = null_space(K, tol, mech.nv) if K.size else np.eye(mech.nv)
        self.moving = np.linalg.norm(V, axis=1) > 1e-9  # joints that generically move


def classify(mech, q, inputs=None, output=None, length=None, generic=None) -> SingularityReport:
    """Classify the configuration q (assembled) for the given inputs and output link."""
    tol = mech.tolerances
    inputs = list(inputs or mech.actuated)
    g = generic or Generic(mech, inputs, output)
    L = length or characteristic_length(mech, q)
    names = mech.coordinate_names
    K = mech.closure.jacobian(q)
    nv = mech.nv
    if K.size:
        sK = np.linalg.svd(K, compute_uv=False)
        V = null_space(K, tol, nv)
    else:
        sK, V = np.zeros(0), np.eye(nv)
    sig_c = _rel(sK, g.rank_K)
    constraint = g.rank_K > 0 and sig_c < tol.singular
    twists = []
    model = mech.model
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J = J_out = None
    if output is not None:
        fid = mech.link_frame(output)
        # spatial twists (v at the world origin, w) for the screws: their axes are where they are in the world
        J = frame_jacobian(model, data, fid, pin.ReferenceFrame.WORLD).copy()
        J[:3] /= L
        # the measures from the twist of the output frame's origin (world axes): they must not
        # depend on where the world origin is
        J_out = frame_jacobian(model, data, fid, LWA).copy()
        J_out[:3] /= L
        origin = data.oMf[fid].translation.copy()
    if constraint:
        _, _, vt = np.linalg.svd(K)
        extra = vt[g.rank_K - 1]
        twists.append(_motion_twist("constraint", extra, names, J, L))
    # actuator: K_p loses rank (inputs locked, passive joints still free beyond the idle spins)
    Kp = K[:, g.p] if K.size else np.zeros((0, len(g.p)))
    if Kp.size and g.rank_Kp:
        sKp = np.linalg.svd(Kp, compute_uv=False)
        sig_a = _rel(sKp, g.rank_Kp)
    else:
        sig_a = 1.0
    actuator = len(inputs) > 0 and sig_a < tol.singular
    if actuator:
        _, _, vt = np.linalg.svd(Kp)
        x = np.zeros(nv)
        x[g.p] = vt[g.rank_Kp - 1]
        twists.append(_motion_twist("actuator", x, names, J, L))
    # serial: the output loses a direction of its generic twist space
    sig_s, cond, manip, serial = 1.0, None, None, False
    if J_out is not None and g.out_dim:
        T = J_out @ V
        U, s, _ = np.linalg.svd(T, full_matrices=True)
        # relative to the output Jacobian itself (V is orthonormal, so s <= |J|): stays
        # meaningful when the output stops altogether
        scale = np.linalg.norm(J_out, 2)
        sig_s = float(s[g.out_dim - 1] / scale) if len(s) >= g.out_dim and scale > 0 else 0.0
        serial = sig_s < tol.singular
        kept = s[:g.out_dim]
        cond = float(kept[0] / kept[-1]) if kept[-1] > 0 else float("inf")
        manip = float(np.prod(kept))
        if serial:  # the lost direction, as a spatial twist: v at the world origin = v_o - w x o
            lost = U[:, g.out_dim - 1].copy()
            lost[:3] = lost[:3] * L - np.cross(lost[3:], origin)
            twists.append(SingularTwist("serial", {}, tuple(lost), screw_of(lost).to_dict()))
    elif Kp.size and g.rank_Kp:
        s = np.linalg.svd(Kp, compute_uv=False)[:g.rank_Kp]
        cond = float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
    stationary = tuple(n for k, n in enumerate(names)
                       if g.moving[k] and V.shape[1] and np.linalg.norm(V[k]) < 1e-7)
    sigmas = {"constraint": sig_c, "actuator": sig_a, "serial": sig_s}
    return SingularityReport(serial, actuator, constraint, stationary, min(sigmas.values()), sigmas, cond, manip,
                             L, tuple(twists), tuple(inputs), output)


def measures(mech, q, g, output=None, length=1.0) -> dict:
    """The relative smallest singular values of classify(), without the rest (for scans)."""
    tol = mech.tolerances
    K = mech.closure.jacobian(q)
    out = {"constraint": _rel(np.linalg.svd(K, compute_uv=False), g.rank_K) if K.size else 1.0}
    Kp = K[:, g.p] if K.size else np.zeros((0, 0))
    out["actuator"] = _rel(np.linalg.svd(Kp, compute_uv=False), g.rank_Kp) if Kp.size and g.rank_Kp else 1.0
    if output is not None and g.out_dim:
        model = mech.model
        data = mech.data
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        J = frame_jacobian(model, data, mech.link_frame(output), LWA).copy()  # as in classify
        J[:3] /= length
        V = null_space(K, tol, mech.nv) if K.size else np.eye(mech.nv)
        s = np.linalg.svd(J @ V, compute_uv=False)
        out["serial"] = float(s[g.out_dim - 1] / np.linalg.norm(J, 2)) if len(s) >= g.out_dim else 0.0
    return out


def _motion_twist(kind, x, names, J, L):
    x = x / np.linalg.norm(x)
    rates = {n: float(v) for n, v in zip(names, x) if abs(v) > 1e-9}
    if J is None:
        return SingularTwist(kind, rates, None, None)
    t = J @ x
    t[:3] *= L
    return SingularTwist(kind, rates, tuple(t), screw_of(t).to_dict() if np.linalg.norm(t) > 1e-12 else None)
