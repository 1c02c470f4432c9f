"""MJCF ``<equality>`` elements as cut joints and couplings.

- ``connect``: a spherical cut joint (a point of body1 held on body2);
- two ``connect``s between the same two bodies at different points: one revolute cut joint about
  the line through them (what the two hold together: MuJoCo's 6 rows have rank 5), so a planar
  loop closed that way stays planar (screwkin export writes a revolute loop joint so);
- ``weld``: a fixed cut joint: F2 at ``anchor`` on body2, F1 on body1 where ``relpose`` puts it.
  MuJoCo's engine (engine_core_constraint.c) holds body1's point ``relpose[:3]`` on body2's anchor
  and turns body2 by ``relpose[3:]`` from body1: so ``relpose``'s position is the anchor's place
  in body1, which is body2's origin (as MuJoCo's documentation words it) only for a zero anchor.
  Without ``relpose`` (a zero quaternion) F1 is where F2 is at qpos0, as MuJoCo's compiler makes it;
- ``joint``: a coupling joint1 = a0 + a1 joint2 of MuJoCo's values (MuJoCo's polynomial is in the
  displacements from qpos0, y - y0 = a0 + a1 (x - x0), so the offset takes the joints' ``ref``);
  a nonlinear polynomial is refused with the reason.

Equalities have a namespace of their own (MuJoCo's): an unnamed one is called ``connect1``,
``weld2``, ... unless a joint, body or equality has that name already; a named one with a joint's
name is renamed (said in a warning), since screwkin reports cut joints beside tree joints.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..errors import quote, shorten
from ..tolerances import DEFAULT
from .description import Coupling, CutJointSpec
from .urdf import numbers

__all__ = ["read_equalities", "quat_matrix", "matrix_quat"]


def quat_matrix(q: np.ndarray) -> np.ndarray:
    """The rotation matrix of MuJoCo's quaternion (w, x, y, z), normalised (Pinocchio's)."""
    w, x, y, z = (float(v) for v in q)
    return pin.Quaternion(w, x, y, z).normalized().matrix()


def matrix_quat(R) -> tuple:
    """MuJoCo's quaternion (w, x, y, z) of a rotation matrix."""
    q = pin.Quaternion(np.asarray(R, float))
    return (q.w, q.x, q.y, q.z)


def _rpy(M) -> tuple:
    return tuple(pin.rpy.matrixToRpy(M.rotation))


def read_equalities(r, world: dict, sites: dict, mjoints: dict, reference: dict, taken: set) -> tuple:
    """(cut joints, couplings) of every <equality>.  world: body -> pose at qpos0; sites: name ->
    (body, placement); mjoints: joint -> (type, body); reference: joint -> ref; taken: the names of
    joints and bodies."""
    p = r.problems
    cuts, couplings, names = [], [], set()
    count = {"connect": 0, "weld": 0, "joint": 0}
    connects = []  # (name, body1, body2, anchor in body1, point in body2) of the connects by body
    for eq in r.root.findall("equality"):
        for e in eq:
            tag = e.tag
            a = r.attrs(e, "main")
            if tag not in count:
                p.append(f"<equality><{shorten(str(tag), 30)}> is not supported (connect, weld and joint are)")
                continue
            count[tag] += 1
            name = a.get("name")
            if not name:
                name = f"{tag}{count[tag]}"
                while name in names or name in taken:
                    name += "_"
            what = f"<equality><{tag}> {quote(name)}"
            if name in names:
                p.append(f"{what}: two equalities have this name")
                continue
            names.add(name)
            if name in taken:
                new = name + "~eq"
                r.warnings.append(f"{what} has the name of a joint or body: called {quote(new)} here")
                name = new
            if a.get("active", "true") == "false":
                r.warnings.append(f"{what} is inactive (active=\"false\"): not read")
                continue
            if tag == "joint":
                c = _joint_equality(r, a, what, mjoints, reference)
                if c is not None:
                    couplings.append(c)
                continue
            ends = _ends(r, a, what, world, sites)
            if ends is None:
                continue
            (b1, S1), (b2, S2), by_site = ends
            if tag == "connect":
                if by_site:  # the two sites' origins coincide
                    F1, F2 = pin.SE3(np.eye(3), S1.translation), pin.SE3(np.eye(3), S2.translation)
                else:  # anchor on body1; the point of body2 there at qpos0
                    anchor = r.vec(a.get("anchor") or "?", 3, f"{what} anchor", (0, 0, 0))
                    F1 = pin.SE3(np.eye(3), anchor)
                    F2 = pin.SE3(np.eye(3), (world[b2].inverse() * world[b1]).act(anchor))
                connects.append((name, b1, b2, F1.translation, F2.translation))
                continue
            if by_site:  # the two sites' frames coincide
                F1, F2 = S1, S2
            else:
                anchor = r.vec(a.get("anchor"), 3, f"{what} anchor", (0, 0, 0))
                F2 = pin.SE3(np.eye(3), anchor)
                rel = r.vec(a.get("relpose"), 7, f"{what} relpose", (0, 1, 0, 0, 0, 0, 0))
                if np.any(rel[3:]):  # as MuJoCo's engine reads it: the anchor's place on body1, body2's turn
                    F1 = pin.SE3(quat_matrix(rel[3:]), rel[:3])
                else:  # as at qpos0
                    F1 = world[b1].inverse() * world[b2] * F2
            cuts.append(CutJointSpec(name, "fixed", b1, b2, tuple(F1.translation), _rpy(F1),
                                     tuple(F2.translation), _rpy(F2), source="mjcf"))
    cuts += _connect_cuts(r, connects, world)
    return cuts, couplings


def _connect_cuts(r, connects: list, world: dict) -> list:
    """Spherical cut joints of the connects; two between the same bodies: one revolute."""
    pairs = {}
    for c in connects:
        pairs.setdefault(frozenset((c[1], c[2])), []).append(c)
    out = []
    for group in pairs.values():
        if len(group) == 2:
            (n1, b1, b2, a1, p1), (n2, c1, _, a2, p2) = group
            if c1 != b1:  # the second written the other way round: its anchor is on b1's partner
                a2 = (world[b1].inverse() * world[c1]).act(a2)
            d = np.asarray(a2, float) - np.asarray(a1, float)
            L = float(np.linalg.norm(d))
            if L > DEFAULT.geometry * max(1.0, float(np.linalg.norm(a1))):
                F1 = pin.SE3(np.eye(3), np.asarray(a1, float))
                F2 = world[b2].inverse() * world[b1] * F1
                out.append(CutJointSpec(n1, "revolute", b1, b2, tuple(F1.translation), (0.0, 0.0, 0.0),
                                        tuple(F2.translation), _rpy(F2), tuple(d / L), source="mjcf"))
                r.warnings.append(f"<connect>s {quote(n1)} and {quote(n2)} hold {quote(b1)} and {quote(b2)} at two "
                                  f"points {L:.4g} m apart: read as one revolute loop joint {quote(n1)} about the line "
                                  "through them (MuJoCo's 6 rows, one redundant)")
                continue
        for name, b1, b2, F1, F2 in group:
            out.append(CutJointSpec(name, "spherical", b1, b2, tuple(F1), (0.0, 0.0, 0.0), tuple(F2), (0.0, 0.0, 0.0),
                                    source="mjcf"))
    return out


def _ends(r, a: dict, what: str, world: dict, sites: dict) -> tuple | None:
    """((body1, S1), (body2, S2), by_site) of a connect or weld; body2 omitted or "world" is the world."""
    p = r.problems
    if a.get("site1") or a.get("site2"):
        out = []
        for k in ("site1", "site2"):
            s = a.get(k)
            if s not in sites:
                p.append(f"{what} {k} {quote(s)} is not a site of the file")
                return None
            out.append(sites[s])
        b1, b2 = out[0][0], out[1][0]
        res = (out[0], out[1], True)
    else:
        b1, b2 = a.get("body1"), a.get("body2") or "world"
        for k, b in (("body1", b1), ("body2", b2)):
            if b not in world:  # a body of the file (not one of the links made for its joints)
                p.append(f"{what} {k} {quote(b)} is not a body of the file")
                return None
        res = ((b1, None), (b2, None), False)
    if b1 == b2:
        p.append(f"{what} connects body {quote(b1)} to itself")
        return None
    return res


def _joint_equality(r, a, what: str, mjoints: dict, reference: dict) -> Coupling | None:
    p = r.problems
    j1, j2 = a.get("joint1"), a.get("joint2")
    if not j2:
        p.append(f"{what} has no joint2: locking a joint at a value is not supported")
        return None
    for k, j in (("joint1", j1), ("joint2", j2)):
        if j not in mjoints:
            p.append(f"{what} {k} {quote(j)} is not a joint of the file")
            return None
        if mjoints[j][0] not in ("hinge", "slide"):
            p.append(f"{what} {k} {quote(j)} is a {mjoints[j][0]} joint: only hinge and slide joints can be coupled")
            return None
    c = numbers(a.get("polycoef"), 5, f"{what} polycoef", p, (0, 1, 0, 0, 0), 1e9, "")
    if any(c[2:]):
        p.append(f"{what} polycoef {quote(a.get('polycoef'))} is not linear: a nonlinear coupling of "
                 f"{quote(j1)} to {quote(j2)} would need a constraint row of its own; only joint1 = a0 + a1 joint2 "
                 "is read")
        return None
    if j1 == j2:
        p.append(f"{what} couples joint {quote(j1)} to itself")
        return None
    y0, x0 = reference.get(j1, 0.0), reference.get(j2, 0.0)  # y - y0 = a0 + a1 (x - x0)
    return Coupling(j1, j2, float(c[1]), float(c[0]) + y0 - float(c[1]) * x0)
