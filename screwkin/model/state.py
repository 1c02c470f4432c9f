"""One configuration's kinematic quantities: the one place they are computed.

``KinematicState(mech, q, qd, qdd)`` is an immutable value: forward kinematics (positions,
and rates and accelerations when ``qd``/``qdd`` are given) run lazily, the joint Jacobians only
when one is read, and every read returns a copy, so that nothing depends on what another
analysis left in a Pinocchio ``Data`` and threads may share a mechanism.  The pass runs in a
Data the thread's states share (Mechanism.state_data), again only when another state ran
there since; a model too large for a Data per thread (Mechanism.shares_data, past
SHARED_DATA_NV coordinates) reads the mechanism's one Data, its pass run again at each read
(one thread at a time).  From it every quantity people ask for is read:

* every link's absolute pose, and the velocity and classical acceleration of its frame origin
  with its angular velocity and acceleration (world axes; twists in (linear, angular) order);
* any point fixed on a link (coordinates in the link's frame): position, velocity, acceleration;
* frame and joint placements, joint centres, frame Jacobians, each joint's twists, the tree
  joints' values by name, the constraint Jacobian K of the loops;
* the output frame a command places on a link (``place_tool``: a tool, a named point), under
  its name like a link, its placement composed with its link's (Pinocchio's frame functions
  of a joint and a placement): it is no frame of the model;
* the coordinates of the loop (cut) joints: the value of a one-coordinate ``<loop_joint>`` as a
  tree joint's value is read -- zero where its frames F1 and F2 coincide as written, the angle
  of F2 about the axis (revolute, continuous) or the displacement of F2's origin along the axis
  (prismatic), both measured in F1 -- with its rate and acceleration.

The rule: whatever reads the kinematic quantities of one configuration reads them from a
KinematicState.  Pinocchio's kinematics are called directly only (1) inside an algorithm's inner
loop, on a Data it keeps: the closure's residual and Jacobian and the Newton loops on them
(model.kernel.closure, model.kernel.newton, the position solver's mode signature); (2) for a stack of
configurations at once (analysis.motion.links, model.kernel.stacks's TreeKinematics and BatchClosure,
singularities.batch); (3) by a dynamics algorithm that runs its own pass (RNEA, CRBA, the energies
in analysis.forces) or a viewer that places the geometry (present); (4) on a bare Pinocchio model
that has no mechanism yet (model.legs probing which legs are distances, model.kernel.algebraic's
reference placements for the homotopy).

Units: m, rad, s.
"""

from __future__ import annotations

import itertools
from functools import cached_property
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from ..errors import UsageError, quote
from ._pin import frame_jacobian, joint_axis
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.cuts import CutJoint

__all__ = ["KinematicState", "PointMotion", "OutputFrame", "LOOP_COORDINATE_TYPES", "loop_coordinate_cuts",
           "angular_loop_joints", "leg_ends", "value_for_leg_length", "place_tool", "frame_parent",
           "model_with_output"]

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
#: The loop-joint types whose coordinate a state reports (one coordinate along or about the axis).
LOOP_COORDINATE_TYPES = ("revolute", "continuous", "prismatic")
_KEYS = itertools.count(1)  # one per state: which state's pass a thread's Data holds


class OutputFrame(NamedTuple):
    """The output frame a command analyses (``place_tool``): a tool, or a named point with its link's
    orientation, at ``placement`` (pinocchio.SE3) in ``link``'s frame, called ``name``."""

    name: str
    link: str
    placement: object


def place_tool(mech, name: str, link: str, placement) -> str:
    """Make the frame at ``placement`` (a pinocchio.SE3 in ``link``'s frame: a tool, or a named point
    with the link's orientation) the mechanism's output frame, under ``name``: from then on every
    analysis that takes an output link (its pose, twist, frame Jacobian) takes ``name`` too
    (``mech.link_frame(name)`` is the output frame's id, mech.tool_frame).  The model is not changed:
    this records the frame as ``mech.tool`` (an OutputFrame), which KinematicState and frame_parent
    read; closure systems that need it as a model frame place it in a copy (model_with_output)."""
    if name in mech.spec.links:
        raise UsageError(f"{mech.path}: the output frame's name {quote(name)} is a link's name; choose another")
    mech.link_frame(link)  # a clear error for an unknown link
    mech.tool = OutputFrame(name, link, pin.SE3(placement))
    return name


def frame_parent(mech, fid: int) -> tuple:
    """(joint id, pinocchio.SE3 in that joint's frame) of frame ``fid``: as the model holds it, except the
    output frame (mech.tool_frame), on its link where place_tool put it.  A frame's world placement is
    ``data.oMi[joint] * placement`` after any forward-kinematics pass in ``data``."""
    model = mech.model
    if fid == mech.tool_frame and mech.tool is not None:
        body = model.frames[mech.link_frame(mech.tool.link)]
        return body.parentJoint, body.placement * mech.tool.placement
    f = model.frames[fid]
    return f.parentJoint, f.placement


def model_with_output(mech, model: pin.Model | None = None) -> pin.Model:
    """A copy of the mechanism's model (or ``model``, itself a copy, changed in place) with the output
    frame placed where place_tool put it, for a closure system that holds it as a cut joint's frame
    (inverse kinematics, a workspace's targets); the mechanism's own model is never changed."""
    model = pin.Model(mech.model) if model is None else model
    if mech.tool is not None:
        joint, placement = frame_parent(mech, mech.tool_frame)
        frame = model.frames[mech.tool_frame]
        frame.name, frame.parentJoint, frame.placement = mech.tool.name, joint, placement
        frame.parentFrame = mech.link_frame(mech.tool.link)
        model.frames[mech.tool_frame] = frame
    return model


def loop_coordinate_cuts(mech) -> tuple:
    """The cut joints whose coordinate a state reports: one coordinate, no higher pair built on them."""
    return tuple(c for c in mech.cuts if c.type in LOOP_COORDINATE_TYPES and c.dof == 1 and not c.pair)


def angular_loop_joints(mech) -> tuple:
    """Names of the reported loop-joint coordinates that are angles."""
    return tuple(c.name for c in loop_coordinate_cuts(mech) if c.type != "prismatic")


def leg_ends(mech) -> dict:
    """Prismatic tree joint -> (start, end): the joint centres the leg connects, as ("joint", id) or
    ("frame", id) (KinematicState.centre): the centre of the joint that carries the prismatic joint's
    parent link, and the first centre on its child link (a joint it carries, else a cut joint's frame
    on it) away from the prismatic joint's origin.  A leg length is the distance between the two (a
    Stewart leg's U to S).  Read once per mechanism, at its file's configuration."""
    if "leg_ends" in mech.cache:
        return mech.cache["leg_ends"]
    model, state = mech.model, KinematicState(mech, mech.neutral())
    tiny = mech.tolerances.geometry
    out = {}
    for c in mech.coordinates:
        jid = c.joint_id
        short = model.joints[jid].shortname()
        if c.nv != 1 or "JointModelP" not in short or "Planar" in short:
            continue
        parent = model.parents[jid]
        start = ("joint", parent) if parent > 0 else None
        if start is None:
            continue
        origin = state.centre(("joint", jid))
        candidates = [("joint", k) for k in model.children[jid]]
        candidates += [("frame", f) for cut in mech.cuts for f in (cut.frame1, cut.frame2)
                       if model.frames[f].parentJoint == jid]
        end = next((r for r in candidates if np.linalg.norm(state.centre(r) - origin) > tiny), None)
        if end is not None:
            out[c.joint] = (start, end)
    mech.cache["leg_ends"] = out
    return out


def value_for_leg_length(mech, joint: str, length: float) -> float:
    """The prismatic joint's value [m] that makes its leg ``length`` [m] long: with d0 the vector
    between the leg's ends at value 0 and u the joint's axis (both in the parent link's frame, where
    only this joint moves the end), |d0 + x u| = length, the root that extends the leg."""
    ends = leg_ends(mech).get(joint)
    if ends is None:
        raise UsageError(f"{mech.path}: {quote(joint)} is not a prismatic joint between two joint centres "
                         "(no leg length to set)")
    model, state = mech.model, KinematicState(mech, mech.neutral())
    c = mech.coordinate(joint)
    R = state.joint_placement(model.parents[c.joint_id]).rotation
    start, end = (state.centre(r) for r in ends)
    d0 = R.T @ (end - start)
    u = R.T @ (state.joint_placement(c.joint_id).rotation @ joint_axis(model.joints[c.joint_id]))
    b = float(d0 @ u)
    disc = b * b - float(d0 @ d0) + length * length
    if disc < 0:
        raise UsageError(f"{mech.path}: leg {quote(joint)} cannot be {length:.6g} m long: its ends stay "
                         f"{np.sqrt(float(d0 @ d0) - b * b):.6g} m apart across its axis")
    return -b + float(np.sqrt(disc))


class PointMotion:
    """Position [m], velocity [m/s] and classical acceleration [m/s^2] of a point, world axes
    (velocity and acceleration None when the state has no rates)."""

    __slots__ = ("position", "velocity", "acceleration")

    def __init__(self, position: np.ndarray, velocity: np.ndarray | None=None, acceleration: np.ndarray | None=None) -> None:
        self.position, self.velocity, self.acceleration = position, velocity, acceleration

    def __repr__(self) -> str:
        return f"PointMotion(position={self.position}, velocity={self.velocity}, acceleration={self.acceleration})"


class KinematicState:
    """The kinematics of ``mech`` at ``q`` (and rates ``qd``, accelerations ``qdd``: tangent
    vectors of the model, (nv,)).  Read-only; every quantity is computed when first asked (Pinocchio's
    pass run again where another state has used the thread's Data since) and returned as a copy."""

    def __init__(self, mech, q: np.ndarray, qd: np.ndarray | None=None, qdd: np.ndarray | None=None) -> None:
        self.mech = mech
        self.q = np.array(q, float)
        self.qd = None if qd is None else np.array(qd, float)
        self.qdd = None if qd is None else np.zeros(mech.nv) if qdd is None else np.array(qdd, float)
        for a in (self.q, self.qd, self.qdd):
            if a is not None:
                a.setflags(write=False)
        self._key = next(_KEYS)

    # ------------------------------------------------------------------ Pinocchio's pass
    def _pass(self, data: pin.Data, jacobians: bool, placed: bool = False) -> pin.Data:
        """Pinocchio's pass for this state in ``data``: placements, and motions when it has rates
        (unless ``placed``: done already); with ``jacobians`` the joint Jacobians too."""
        model = self.mech.model
        if not placed:
            if self.qd is None:
                pin.framesForwardKinematics(model, data, self.q)
            else:
                pin.forwardKinematics(model, data, self.q, self.qd, self.qdd)
                pin.updateFramePlacements(model, data)
        if jacobians and model.nv:
            pin.computeJointJacobians(model, data, self.q)
            pin.updateFramePlacements(model, data)
        return data

    def _data(self, jacobians: bool = False) -> pin.Data:
        """A Data holding this state's pass (with the joint Jacobians when asked), to read at once:
        the thread's Data for states (Mechanism.state_data), the pass run again only when another
        state ran there since; for a model too large for a Data per thread (Mechanism.shares_data)
        the mechanism's shared one, the pass run again at each read."""
        mech = self.mech
        if mech.shares_data:
            return self._pass(mech.data, jacobians)
        slot = mech.state_data
        data = getattr(slot, "data", None)
        if data is None:
            data = slot.data = mech.model.createData()
            slot.key = slot.jacobians = None
        if slot.key != self._key:
            self._pass(data, jacobians)
            slot.key, slot.jacobians = self._key, jacobians
        elif jacobians and not slot.jacobians:
            self._pass(data, True, placed=True)
            slot.jacobians = True
        return data

    @property
    def has_rates(self) -> bool:
        return self.qd is not None

    def _output(self, fid: int):
        """(joint, placement in it) of the output frame place_tool placed, when ``fid`` is it; else None."""
        mech = self.mech
        return frame_parent(mech, fid) if fid == mech.tool_frame and mech.tool is not None else None

    def frame_placement(self, fid: int) -> pin.SE3:
        """World placement of a frame (pinocchio.SE3, a copy)."""
        out = self._output(fid)
        d = self._data()
        return d.oMi[out[0]] * out[1] if out else pin.SE3(d.oMf[fid])

    def joint_placement(self, jid: int) -> pin.SE3:
        """World placement of a joint's frame (pinocchio.SE3, a copy)."""
        return pin.SE3(self._data().oMi[jid])

    def centre(self, ref: tuple | list) -> np.ndarray:
        """World position [m] of a point named by reference: ("joint", i) the centre of joint i (its
        frame's origin, moving with it), ("mount", i) where joint i sits on its parent link (fixed
        there whatever joint i's value), ("frame", f) frame f's origin."""
        kind, i = ref
        d = self._data()
        if kind == "mount":
            return d.oMi[self.mech.model.parents[i]].act(self.mech.model.jointPlacements[i].translation)
        return (d.oMi[i] if kind == "joint" else d.oMf[i]).translation.copy()

    def joint_twists(self, jid: int) -> np.ndarray:
        """(6, k) the unit twists of joint jid's k coordinates (its motion subspace S moved to the
        world: spatial, (v at the world origin, w), world axes) [m/rad, 1]."""
        d = self._data()
        S = np.asarray(d.joints[jid].S, float).reshape(6, -1)
        M = d.oMi[jid]
        return np.column_stack([M.act(pin.Motion(S[:, k])).vector for k in range(S.shape[1])]) if S.size \
            else np.zeros((6, 0))

    def frame_jacobian(self, fid: int, reference: pin.ReferenceFrame=LWA) -> np.ndarray:
        """(6, nv) Jacobian of a frame in (linear, angular) order, in ``reference``
        (LOCAL_WORLD_ALIGNED by default: the frame origin's velocity and the angular
        velocity, world axes; WORLD: the spatial twist at the world origin) [m/rad, 1]."""
        out = self._output(fid)
        d = self._data(jacobians=True)
        if out:
            return frame_jacobian(self.mech.model, d, out[0], reference, placement=out[1])
        return frame_jacobian(self.mech.model, d, fid, reference).copy()

    def link_jacobian(self, link: str, reference: pin.ReferenceFrame=LWA) -> np.ndarray:
        return self.frame_jacobian(self.mech.link_frame(link), reference)

    @cached_property
    def joint_values(self) -> dict:
        """Tree coordinate name -> value [rad or m] (Mechanism.joint_values)."""
        return self.mech.joint_values(self.q)

    @cached_property
    def constraint_jacobian(self) -> np.ndarray:
        """K (rows of the loops and higher pairs, nv): K q' = 0 for the motions they allow
        (model.kernel.closure, computed in the closure's own Data and copied here)."""
        return np.array(self.mech.closure.jacobian(self.q), float)

    def frame_pose(self, fid: int) -> np.ndarray:
        """4x4 world pose of a frame."""
        return self.frame_placement(fid).homogeneous

    def frame_twist(self, fid: int) -> np.ndarray:
        """(v, w) of the frame's origin, world axes [m/s, rad/s]."""
        out = self._output(fid)
        where = out if out else (fid,)
        return pin.getFrameVelocity(self.mech.model, self._data(), *where, LWA).vector.copy()

    def frame_acceleration(self, fid: int) -> np.ndarray:
        """Classical acceleration (a, alpha) of the frame's origin, world axes [m/s^2, rad/s^2]."""
        out = self._output(fid)
        where = out if out else (fid,)
        return pin.getFrameClassicalAcceleration(self.mech.model, self._data(), *where, LWA).vector.copy()

    # ------------------------------------------------------------------ links and points
    def link_pose(self, link: str) -> np.ndarray:
        return self.frame_pose(self.mech.link_frame(link))

    def point(self, link: str, local: tuple=(0.0, 0.0, 0.0)) -> PointMotion:
        """Motion of the point with coordinates ``local`` [m] in ``link``'s frame."""
        fid = self.mech.link_frame(link)
        M = self.frame_placement(fid)
        r = M.rotation @ np.asarray(local, float)  # from the frame origin to the point, world axes
        p = M.translation + r
        if not self.has_rates:
            return PointMotion(p)
        v, w = np.split(self.frame_twist(fid), 2)
        a, alpha = np.split(self.frame_acceleration(fid), 2)
        return PointMotion(p, v + np.cross(w, r), a + np.cross(alpha, r) + np.cross(w, np.cross(w, r)))

    def link_motion(self, link: str) -> dict:
        """position, velocity, acceleration of the link frame's origin; omega, alpha (vectors)."""
        fid = self.mech.link_frame(link)
        out = {"position": self.frame_placement(fid).translation.copy()}
        if self.has_rates:
            v, w = np.split(self.frame_twist(fid), 2)
            a, alpha = np.split(self.frame_acceleration(fid), 2)
            out.update(velocity=v, acceleration=a, omega=w, alpha=alpha)
        return out

    # ------------------------------------------------------------------ loop-joint coordinates
    def _cut_frames(self, cut: CutJoint) -> tuple:
        M1, M2 = self.frame_placement(cut.frame1), self.frame_placement(cut.frame2)
        axis = M1.rotation @ np.asarray(cut.axis, float)
        return M1, M2, axis / np.linalg.norm(axis)

    def loop_value(self, cut: CutJoint) -> float:
        """The coordinate of a one-coordinate cut joint [rad or m] (see the module's docstring)."""
        M1, M2, axis = self._cut_frames(cut)
        if cut.type == "prismatic":
            return float((M2.translation - M1.translation) @ axis)
        R = M1.rotation.T @ M2.rotation  # F2 in F1: a rotation about the axis (in F1) when closed
        a = np.asarray(cut.axis, float) / np.linalg.norm(cut.axis)
        # R = cos t I + sin t [a]x + (1 - cos t) a a^T: sin t from its antisymmetric part along a,
        # cos t = (trace R - a^T R a) / 2
        s = 0.5 * a @ np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
        c = 0.5 * (np.trace(R) - a @ R @ a)
        return float(np.arctan2(s, c))

    def loop_rate(self, cut: CutJoint) -> float:
        """d/dt of loop_value [rad/s or m/s] (needs rates)."""
        M1, M2, axis = self._cut_frames(cut)
        v1, w1 = np.split(self.frame_twist(cut.frame1), 2)
        v2, w2 = np.split(self.frame_twist(cut.frame2), 2)
        if cut.type == "prismatic":
            return float((v2 - v1) @ axis + (M2.translation - M1.translation) @ np.cross(w1, axis))
        return float((w2 - w1) @ axis)

    def loop_acceleration(self, cut: CutJoint) -> float:
        """d^2/dt^2 of loop_value [rad/s^2 or m/s^2] (needs rates)."""
        M1, M2, axis = self._cut_frames(cut)
        v1, w1 = np.split(self.frame_twist(cut.frame1), 2)
        v2, w2 = np.split(self.frame_twist(cut.frame2), 2)
        a1, al1 = np.split(self.frame_acceleration(cut.frame1), 2)
        a2, al2 = np.split(self.frame_acceleration(cut.frame2), 2)
        da = np.cross(w1, axis)  # d axis / dt
        dda = np.cross(al1, axis) + np.cross(w1, da)
        if cut.type == "prismatic":
            r = M2.translation - M1.translation
            return float((a2 - a1) @ axis + 2.0 * (v2 - v1) @ da + r @ dda)
        return float((al2 - al1) @ axis + (w2 - w1) @ da)

    @cached_property
    def leg_lengths(self) -> dict:
        """Prismatic joint -> the distance between the joint centres its leg connects [m] (leg_ends)."""
        ends = leg_ends(self.mech)
        return {j: float(np.linalg.norm(self.centre(e) - self.centre(s))) for j, (s, e) in ends.items()}

    @cached_property
    def guide_positions(self) -> dict:
        """Prismatic joint whose guide is the ground (a tree joint on the ground, or a prismatic cut joint whose
        F1 is on it) -> the slider's position along its guide [m]: the guide direction's component of the
        slider's frame origin (the joint's frame; a cut joint's F2), i.e. measured from the foot of the
        perpendicular from the world origin onto the guide line -- a slider-crank's slider distance d when its
        crank pivots at the origin.  (The joint's value is measured from where the file placed the joint.)"""
        model, out = self.mech.model, {}
        for c in self.mech.coordinates:
            if c.nv == 1 and c.nq == 1 and self.mech.translational[c.idx_v] and model.parents[c.joint_id] == 0:
                M = self.joint_placement(c.joint_id)
                out[c.joint] = float(M.translation @ (M.rotation @ joint_axis(model.joints[c.joint_id])))
        for cut in self.loop_cuts:
            if cut.type == "prismatic" and model.frames[cut.frame1].parentJoint == 0:
                _, M2, axis = self._cut_frames(cut)
                out[cut.name] = float(M2.translation @ axis)
        return out

    @cached_property
    def loop_cuts(self) -> tuple:
        """The cut joints whose coordinate is reported (loop_coordinate_cuts)."""
        return loop_coordinate_cuts(self.mech)

    @cached_property
    def loop_joints(self) -> dict:
        """Cut joint name -> value [rad or m]."""
        return {c.name: self.loop_value(c) for c in self.loop_cuts}

    @cached_property
    def loop_rates(self) -> dict | None:
        return {c.name: self.loop_rate(c) for c in self.loop_cuts} if self.has_rates else None

    @cached_property
    def loop_accelerations(self) -> dict | None:
        return {c.name: self.loop_acceleration(c) for c in self.loop_cuts} if self.has_rates else None
