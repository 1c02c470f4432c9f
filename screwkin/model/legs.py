"""Legs that are distance constraints: what model.kernel.algebraic eliminates before a homotopy tracks.

A leg here is a chain of the spanning tree that hangs off one link and carries, at its end, one
frame of a spherical cut joint and nothing else the loops or the modes read: the U-P-S legs of a
Gough-Stewart platform, the S-S rods of a Delta robot, the coupler of an RSSR linkage.  When its
passive joints are revolutes whose axes meet at one point O of the link it hangs from (a universal
or spherical joint written as revolutes), and its inputs are held, the cut frame's origin can be
anywhere on a sphere about O and nowhere else: the leg is the one equation

    |p - O|^2 = r^2      (p: the other frame of the cut joint, r: the leg's length at these inputs)

and its joint angles follow from p, up to the flips that leave its joint centres where they were
(the universal joint turned by pi with the leg spun about its axis).  Eliminated, such a leg takes
its two or three angles out of the unknowns and its idle spin (an S-S rod about its axis) with them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..tolerances import DEFAULT
from .geometry import lines_point
from typing import TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Sequence

__all__ = ["Leg", "distance_legs", "chain_distance"]


@dataclass(frozen=True)
class Leg:
    """cut: the spherical cut joint's name; frame: its frame on the leg, other: its other frame;
    joints: the leg's joint ids (from the frame up); parent: the joint whose link it hangs from;
    centre: O in that joint's frame [m]."""

    cut: str
    frame: int
    other: int
    joints: tuple
    parent: int
    centre: tuple


def distance_legs(model: pin.Model, cuts: list, frozen: set, length: float, keep_frames: list=(), tol: float = DEFAULT.geometry) -> list:
    """The legs of ``cuts`` that are distance constraints (see the module), with the inputs at the
    velocity indices ``frozen`` held; ``keep_frames``: frames that must not lie on a leg (an output);
    ``tol``: the geometric tolerance (axes meeting, a distance constant), relative to the length."""
    frozen = set(int(f) for f in np.asarray(list(frozen), int).ravel())
    data = model.createData()
    q0 = pin.neutral(model)
    pin.framesForwardKinematics(model, data, q0)
    used = {}  # joint -> frames below it that something reads
    reads = [f for c in cuts for f in (c.frame1, c.frame2)] + list(keep_frames)
    for f in reads:
        j = model.frames[f].parentJoint
        while j > 0:
            used.setdefault(j, set()).add(f)
            j = model.parents[j]
    legs, taken = [], set()
    for c in cuts:
        if c.type != "spherical" or c.pair is not None:
            continue
        for f, other in ((c.frame1, c.frame2), (c.frame2, c.frame1)):
            leg = _leg(model, data, q0, c.name, f, other, used, frozen, length, taken, tol)
            if leg is not None:
                legs.append(leg)
                taken.update(leg.joints)
                break
    return legs


def _passive_revolute(model: pin.Model, j: int, frozen: set) -> bool:
    jm = model.joints[j]
    passive = not any(jm.idx_v + k in frozen for k in range(jm.nv))
    return passive and jm.nv == 1 and jm.shortname().startswith("JointModelR")


def _leg(model: pin.Model, data: pin.Data, q0: np.ndarray, name: str, f, other, used: dict, frozen: set, length: float, taken, tol: float) -> Leg | None:
    """The leg ending at frame f, or None."""
    chain = []
    j = model.frames[f].parentJoint
    while j > 0 and used.get(j, set()) == {f} and j not in taken:
        jm = model.joints[j]
        passive = not any(jm.idx_v + k in frozen for k in range(jm.nv))
        if passive and not _passive_revolute(model, j, frozen):
            break
        chain.append(j)
        j = model.parents[j]
    # the longest chain from the frame up whose passive revolutes meet at one point
    while chain:
        revs = [k for k in chain if _passive_revolute(model, k, frozen)]
        centre = _common_point(model, data, revs, length, tol)
        if centre is not None and _constant_distance(model, q0, f, chain, revs, centre, length, tol):
            parent = model.parents[chain[-1]]
            local = data.oMi[parent].actInv(centre) if parent > 0 else centre
            return Leg(name, f, other, tuple(chain), int(parent), tuple(float(v) for v in local))
        chain = chain[:-1]
    return None


def _common_point(model: pin.Model, data: pin.Data, revs: list, length: float, tol: float):
    """The point where the revolutes' axes meet (at the neutral configuration), or None when there are
    fewer than two independent axes or they do not meet."""
    if len(revs) < 2:
        return None
    points, dirs = [], []
    for j in revs:
        M = data.oMi[j]
        S = np.asarray(data.joints[j].S).reshape(6, -1)[3:, 0]
        dirs.append(M.rotation @ (S / np.linalg.norm(S)))
        points.append(M.translation)
    if np.linalg.matrix_rank(np.array(dirs), tol=tol) < 2:
        return None
    o, off = lines_point(points, dirs, tol)
    return o if o is not None and off <= tol * length else None


def _constant_distance(model: pin.Model, q0: np.ndarray, f, chain, revs: list, centre, length: float, tol: float) -> bool:
    """Whether the frame's origin stays at one distance from the centre as the leg's passive revolutes
    turn (tried at random angles, with its inputs at two values)."""
    rng = np.random.default_rng(7)
    data = model.createData()
    inputs = [k for k in chain if k not in revs]
    for trial in range(2):
        q = np.array(q0)
        for k in inputs:  # the inputs at some value (the leg's length depends on it, its constancy must not)
            jm = model.joints[k]
            if jm.nq == 1:
                q[jm.idx_q] = 0.1 * trial * length
        dists = []
        for _ in range(4):
            _turn(model, q, revs, rng)
            pin.framesForwardKinematics(model, data, q)
            dists.append(np.linalg.norm(data.oMf[f].translation - centre))
        if max(dists) - min(dists) > tol * length:
            return False
    return True


def chain_distance(model: pin.Model, frozen, joint: int, length: float, tol: float = DEFAULT.geometry) -> tuple | None:
    """(A, B) when the tree's chain from the ground to ``joint`` is itself a distance between the ground
    and joint's link: passive revolutes meeting at a point A of the ground first, passive revolutes
    meeting at a point B of the link last (three: it turns freely about B), inputs between, |B - A|
    the same however the revolutes turn.  A in the world, B in the joint's frame [m]; else None."""
    frozen = set(int(f) for f in np.asarray(list(frozen), int).ravel())
    chain = []
    j = joint
    while j > 0:
        chain.append(j)
        j = model.parents[j]
    chain.reverse()  # from the ground
    rev = [_passive_revolute(model, k, frozen) for k in chain]
    head = 0
    while head < len(chain) and rev[head]:
        head += 1
    tail = len(chain)
    while tail > head and rev[tail - 1]:
        tail -= 1
    middle = chain[head:tail]
    if head < 2 or len(chain) - tail != 3 or any(_passive(model, k, frozen) for k in middle):
        return None
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    a = _common_point(model, data, chain[:head], length, tol)
    b = _common_point(model, data, chain[tail:], length, tol)
    if a is None or b is None:
        return None
    b_local = data.oMi[joint].actInv(b)
    rng = np.random.default_rng(11)
    dists = []
    for _ in range(4):
        q = pin.neutral(model)
        _turn(model, q, chain[:head] + chain[tail:], rng)
        pin.forwardKinematics(model, data, q)
        dists.append(np.linalg.norm(data.oMi[joint].act(b_local) - a))
    if max(dists) - min(dists) > tol * length:
        return None
    return a, b_local


def _passive(model: pin.Model, j: int, frozen: set) -> bool:
    jm = model.joints[j]
    return not any(jm.idx_v + k in frozen for k in range(jm.nv))


def _turn(model: pin.Model, q: np.ndarray, joints: Sequence[int], rng: np.random.Generator) -> None:
    """q with the revolutes ``joints`` turned to random angles (in place)."""
    for k in joints:
        jm = model.joints[k]
        angle = rng.uniform(-np.pi, np.pi)
        if jm.nq == 1:
            q[jm.idx_q] = angle
        else:
            q[jm.idx_q:jm.idx_q + 2] = (np.cos(angle), np.sin(angle))
