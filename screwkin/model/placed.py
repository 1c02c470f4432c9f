"""A mechanism placed at one configuration, as the plain data the writers of
:mod:`screwkin.files.exporter` turn into MJCF or URDF text.

Every link of the file's spanning tree becomes a body placed in its parent where the
configuration puts it (so that configuration is the written file's own: MuJoCo's qpos0, the
URDF's all-zero), with its joint (its axis does not move in its own link as it turns), the
inertia Pinocchio holds for it (links fixed to it are merged into it, as Pinocchio merges
them), the cut joints with their frames unchanged, the couplings measured from there and the
inputs.  The links of the tree's root hang from the world; the root itself, unless it is the
world, is a body without a joint.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..errors import MechanismFileError, quote
from ..files.exporter import PlacedBody, PlacedCut, PlacedJoint, PlacedMechanism, coupling_about
from ..files.mjcf import matrix_quat
from .topology import frame_link

__all__ = ["placed", "check_closed", "WRITABLE_CUTS"]

#: Cut-joint types the writers can express (the higher pairs cannot).
WRITABLE_CUTS = ("fixed", "revolute", "continuous", "prismatic", "cylindrical", "universal", "planar", "spherical")

#: A joint limit beyond this [rad or m] is no limit (files write 1e9 or 1e16 for "none").
_NO_LIMIT = 1e6


def _inertia(I):
    m = I.inertia
    return (m[0, 0], m[1, 1], m[2, 2], m[0, 1], m[0, 2], m[1, 2])


def placed(mech, q, fmt: str = "MJCF", length: float | None = None, comment: str = "") -> PlacedMechanism:
    """``mech`` at configuration ``q`` (an assembled one, for loops closed in the file).

    Raises MechanismFileError for what ``fmt`` cannot express (a higher pair; for URDF a ball
    or universal joint in the tree)."""
    spec, model = mech.spec, mech.model
    data = mech.scratch_data()
    pin.framesForwardKinematics(model, data, q)
    rep = dict(spec.replacements)
    for c in spec.cut_joints:
        if c.type not in WRITABLE_CUTS:
            raise MechanismFileError(mech.path, f"loop joint {quote(c.name)} is a {c.type} pair: {fmt} cannot "
                                                "express it (lower pairs only)")
    world = {name: data.oMf[mech.link_frame(name)] for name in spec.links}
    root = spec.root
    bodies = []
    if root != "world":
        bodies.append(PlacedBody(root, None, tuple(world[root].translation), matrix_quat(world[root].rotation)))
    values, empty = {}, []
    for j in spec.joints:
        parent = None if j.parent == root else j.parent
        X = world[j.parent].inverse() * world[j.child] if parent is not None else world[j.child]
        t = rep.get(j.name) or j.type
        if t == "planar":
            raise MechanismFileError(mech.path, f"joint {quote(j.name)} is a planar tree joint: {fmt} export writes "
                                                "revolute, prismatic, ball, floating and fixed joints")
        if t.startswith(("UJOINT", "CARDAN")):
            raise MechanismFileError(mech.path, f"joint {quote(j.name)} is a universal joint (sidecar {t}): "
                                                f"write it as two revolutes to export it as {fmt}")
        joint, mass, com, inertia = None, 0.0, (0.0, 0.0, 0.0), (0.0,) * 6
        moving = t != "fixed" and t != "FIXED" and model.existJointName(j.name)
        if moving:
            jid = model.getJointId(j.name)
            kind = {"SPHERICAL": "ball", "floating": "free", "prismatic": "slide"}.get(t, "hinge")
            if kind == "ball" and fmt == "URDF":
                raise MechanismFileError(mech.path, f"joint {quote(j.name)} is a ball joint: URDF has none "
                                                    "(export it as MJCF)")
            if kind == "free" and parent is not None:
                raise MechanismFileError(mech.path, f"joint {quote(j.name)} is floating but not on a link of the "
                                                    f"ground: {fmt} allows free joints only there")
            rng = None
            coord = next((c for c in mech.coordinates if c.joint == j.name), None)
            if kind in ("hinge", "slide") and coord is not None:
                value = float(q[coord.idx_q])
                values[j.name] = value
                lo, hi = model.lowerPositionLimit[coord.idx_q], model.upperPositionLimit[coord.idx_q]
                if abs(lo) < _NO_LIMIT and abs(hi) < _NO_LIMIT:
                    if hi > lo:
                        rng = (float(lo - value), float(hi - value))
                    else:
                        empty.append(j.name)
            joint = PlacedJoint(j.name, kind, tuple(float(a) for a in j.axis), rng, tuple(j.dynamics.items()))
            # Pinocchio's inertia of the joint's body, in the joint's frame: the child link's frame
            I = model.frames[mech.link_frame(j.child)].placement.actInv(model.inertias[jid])
            mass, com, inertia = float(I.mass), tuple(I.lever), _inertia(I)
        elif t in ("fixed", "FIXED"):
            joint = PlacedJoint(j.name, "fixed")
        bodies.append(PlacedBody(j.child, parent, tuple(X.translation), matrix_quat(X.rotation), joint, mass, com,
                                 inertia))
    cuts = []
    for c, s in zip(mech.cuts, spec.cut_joints):
        F = []
        for fid, frame in ((c.frame1, c.link1), (c.frame2, c.link2)):
            link = frame_link(mech, frame)
            F.append((link, world[link].inverse() * data.oMf[fid]))
        (b1, F1), (b2, F2) = F
        rel = data.oMf[c.frame1].inverse() * data.oMf[c.frame2]
        cuts.append(PlacedCut(s.name, s.type, b1, tuple(F1.translation), matrix_quat(F1.rotation), b2,
                              tuple(F2.translation), matrix_quat(F2.rotation), tuple(s.axis),
                              tuple(s.axis2) if s.axis2 is not None else None,
                              (tuple(rel.translation), matrix_quat(rel.rotation))))
    couplings = []
    for cp in spec.couplings:
        primary = values.get(cp.mimics, 0.0)
        couplings.append(coupling_about(cp, primary, cp.multiplier * primary + cp.offset))
    notes = ()
    if empty:
        notes = (f"{len(empty)} joints with empty limits (lower = upper: {', '.join(quote(n, 30) for n in empty[:3])}"
                 f"{', ...' if len(empty) > 3 else ''}) are written unlimited, as screwkin moves them",)
    gears = tuple((t.joint, t.scale * t.gear) for t in mech.transmissions() if t.scale * t.gear != 1.0)
    return PlacedMechanism(spec.name, tuple(bodies), tuple(cuts), tuple(couplings), tuple(mech.actuated), comment,
                           length if length else mech.length, notes, gears)


def check_closed(mech, q, tol: float) -> float:
    """The largest loop-closure residual at q [m or rad]; MechanismFileError when over tol."""
    r = float(np.max(np.abs(mech.closure.residual(q)))) if mech.closure.nrows else 0.0
    if r > tol:
        raise MechanismFileError(mech.path, f"the loops are not closed at the configuration to write (residual "
                                            f"{r:.3g}): solve first")
    return r

