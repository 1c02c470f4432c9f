"""Topology of a mechanism: links, joints, compound joints, loops, motion space.

Links are rigid bodies: URDF links joined by fixed joints (or by a fixed cut
joint) are one link, the ground is one link, and the massless, geometry-less
links inside a recognized compound joint are no link at all.  Chains of 1-DOF
joints through such massless links are recognized from their geometry at an
assembled configuration:

- universal: two revolutes whose axes intersect (not parallel);
- spherical: three revolutes whose axes meet at one point and span space;
- cylindrical: a revolute and a prismatic along the same line direction.

Joint types and their counts feed the Kutzbach/Gruebler criteria; the motion
space (planar, spherical, spatial) is detected from the axes, not declared.
"""

from __future__ import annotations

import os.path
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from ..files.description import CUT_JOINT_DOF
from ..files.sidecar import axis_letters
from ..tolerances import DEFAULT
from ._pin import frame_id
from .geometry import lines_point
from .six_bar import six_bar_inversion
from .state import KinematicState

__all__ = ["Joint", "Topology", "build_topology", "frame_link", "UnionFind", "open_joints"]

MOTION = {
    "revolute": "rotation",
    "continuous": "rotation",
    "prismatic": "translation",
    "cylindrical": "rotation and translation",
    "universal": "two rotations",
    "spherical": "spherical (three rotations)",
    "planar": "planar (two translations, one rotation)",
    "helical": "helical (screw)",
    "rolling": "rolling",
    "gear": "rolling (gear teeth)",
    "contact": "rolling and sliding",
    "floating": "free",
    "fixed": "none",
}
SYMBOL = {
    "revolute": "R", "continuous": "R", "prismatic": "P", "cylindrical": "C", "universal": "U", "spherical": "S",
    "planar": "E", "helical": "H", "rolling": "Ro", "gear": "G", "contact": "Ct", "floating": "F", "fixed": "-",
}
#: Pairs whose elements touch along a line or at a point (the others over a surface).
HIGHER = ("rolling", "gear", "contact")
#: Pairs whose relative motion is planar, with their axis as the plane's normal.
PLANAR_PAIRS = ("planar", "rolling", "gear", "contact")
#: Joint types whose elements do not touch (the pair column says none, as info --joint-types does).
NO_CONTACT = ("floating", "fixed")


@dataclass(frozen=True)
class Joint:
    """A kinematic pair of the mechanism (possibly a compound of URDF joints).

    members: the URDF joint names it is made of (one for a simple joint).
    cut:     True when it is (or contains) a cut joint closing a loop.
    point, direction: a point on the axis and the axis direction (world, at the
    analysed configuration); direction is None for spherical/floating joints.
    """

    name: str
    type: str
    dof: int
    links: tuple
    members: tuple
    cut: bool
    point: tuple | None = None
    direction: tuple | None = None
    direction2: tuple | None = None  # universal joints: the axis fixed in links[1]
    profile: str | None = None  # sliding contacts: "circle-line", "point-line", ...

    @property
    def motion(self) -> str:
        """The relative motion the pair allows, in words."""
        return MOTION[self.type]

    @property
    def pair(self) -> str:
        """'lower' (elements touching over a surface), 'higher' (along a line or at a point), or 'none'
        for a floating joint (no contact at all) and a weld, as ``info --joint-types`` lists them."""
        if self.type in NO_CONTACT:
            return "none"
        return "higher" if self.type in HIGHER else "lower"

    @property
    def contact(self) -> str:
        """How its elements touch: 'surface' for lower pairs (a screw too); 'line' for rolling
        cylinders, gear teeth and cams; 'point' where a point profile (a knife edge, a pin) meets
        a curve (both seen in the plane of motion)."""
        if self.type in NO_CONTACT:
            return "none"
        if self.type not in HIGHER:
            return "surface" + (", compound" if len(self.members) > 1 else "")
        return "point" if self.profile and "point" in self.profile else "line"

    @property
    def symbol(self) -> str:
        return SYMBOL[self.type]


@dataclass(frozen=True)
class Topology:
    """Links, joints and loops of a mechanism, and its detected motion space."""

    links: tuple  # link names (a merged link is named after its first URDF link)
    link_members: dict  # link name -> tuple of URDF link names
    ground: str
    joints: tuple  # Joint
    motion_space: str  # "planar" | "spherical" | "spatial"
    motion_space_detail: str
    dummy_links: tuple = field(default=())  # URDF links inside compound joints
    welds: tuple = field(default=())  # fixed cut joints: they join two URDF links into one link
    normal: tuple | None = None  # planar: the unit normal of the plane of motion (world axes)
    couplings: tuple = field(default=())  # description.Coupling: <mimic> joints, one constraint each

    @property
    def n_links(self) -> int:
        return len(self.links)

    @property
    def n_joints(self) -> int:
        return len(self.joints)

    @property
    def loops(self) -> int:
        return self.n_joints - self.n_links + 1

    @property
    def sum_dof(self) -> int:
        return sum(j.dof for j in self.joints)

    @property
    def full_joints(self) -> int:
        """J1 of the planar count: joints of one DOF (lower pairs, pure rolling, gears)."""
        return sum(1 for j in self.joints if j.dof == 1)

    @property
    def half_joints(self) -> int:
        """J2 of the planar count: joints of two DOF in the plane (sliding contacts: cams, slots)."""
        return sum(1 for j in self.joints if j.dof == 2)

    @property
    def textbook_planar(self) -> bool:
        """Whether the planar count can be written 3(N - 1) - 2 J1 - J2 (every joint J1 or J2)."""
        return self.motion_space == "planar" and all(j.dof in (1, 2) for j in self.joints)

    def count(self, lam: int) -> int:
        """Chebychev-Gruebler-Kutzbach count with motion-space dimension lam, less one for each
        coupling (a mimic joint's value follows another's): lam (N - 1 - J) + sum f - C."""
        return lam * (self.n_links - 1 - self.n_joints) + self.sum_dof - len(self.couplings)

    @property
    def kutzbach(self) -> int:
        return self.count(6)

    @property
    def gruebler(self):
        return self.count(3) if self.motion_space == "planar" else None

    @property
    def spherical_count(self):
        return self.count(3) if self.motion_space == "spherical" else None

    @property
    def count_in_motion_space(self) -> int:
        return self.count(6 if self.motion_space == "spatial" else 3)

    @property
    def six_bar(self) -> str | None:
        """The inversion of a planar six-bar of revolute and prismatic joints ("Watt I" ...
        "Stephenson III", by the graph: screwkin.model.six_bar), else None."""
        if self.motion_space != "planar" or self.couplings or \
                any(j.type not in ("revolute", "continuous", "prismatic") for j in self.joints):
            return None
        return six_bar_inversion([tuple(j.links) for j in self.joints], self.ground)


class UnionFind:
    """Disjoint sets of ``items`` (union-find with path halving): find(x) its set's representative,
    join(a, b) puts b's set under a's representative."""

    def __init__(self, items: range | list) -> None:
        self.parent = {i: i for i in items}

    def find(self, x: int | str) -> int | str:
        while self.parent[x] != x:
            self.parent[x] = self.parent[self.parent[x]]
            x = self.parent[x]
        return x

    def join(self, a: int | str, b: int | str) -> None:
        ra, rb = self.find(a), self.find(b)
        if ra != rb:
            self.parent[rb] = ra


def frame_link(mech, frame_name: str) -> str:
    """The URDF link a Pinocchio frame is attached to (the output frame's: the link place_tool put it on)."""
    spec = mech.spec
    if frame_name in spec.links:
        return frame_name
    if mech.tool is not None and frame_name == mech.tool.name:
        return mech.tool.link
    for j in spec.joints:
        if j.name == frame_name:
            return j.child

    model = mech.model
    fid = frame_id(model, frame_name)
    for _ in range(len(model.frames)):
        f = model.frames[fid]
        if f.type == pin.FrameType.BODY and f.name in spec.links:
            return f.name
        fid = f.parentFrame
    return spec.root


def open_joints(mech) -> tuple:
    """The tree joints (with coordinates) that no closure row involves, in tree order: on the tree
    path between the two frames of no cut joint or contact, and in no linear coupling row (a
    rolling or screw pair's law, a link held at an angle).  Nothing but its own value decides
    such a joint -- a serial arm's joints, a gripper hanging off a loop -- so it is an input of
    every configuration: solved for, it would be any value."""
    model = mech.model
    on_loop = set()
    pairs = [(c.frame1, c.frame2) for c in mech.cuts]
    pairs += [(r.frame1, r.frame2) for r in mech.extra_rows if hasattr(r, "frame1")]
    for f1, f2 in pairs:
        a = set(model.supports[model.frames[f1].parentJoint])
        b = set(model.supports[model.frames[f2].parentJoint])
        on_loop |= a ^ b  # the joints between the frames, not their common ancestors
    by_v = {c.idx_v + k: c.joint_id for c in mech.coordinates for k in range(c.nv)}
    for r in mech.extra_rows:
        on_loop |= {by_v[iv] for _, iv, _ in getattr(r, "terms", ())}
    return tuple(c.joint for c in mech.coordinates if c.joint_id not in on_loop)


@dataclass
class _Edge:
    name: str
    type: str
    dof: int
    a: str
    b: str
    cut: bool
    point: np.ndarray | None
    direction: np.ndarray | None
    direction2: np.ndarray | None = None
    profile: str | None = None


def _edges(mech, q: np.ndarray) -> tuple:
    """Every non-fixed joint as an edge between URDF links, with its world axis at q."""
    model = mech.model
    state = KinematicState(mech, q)
    replaced = dict(mech.spec.replacements)
    edges, welds = [], []
    for j in mech.spec.joints:
        t = j.type
        rep = replaced.get(j.name)
        if rep == "SPHERICAL":
            t = "spherical"
        elif rep == "FIXED":
            t = "fixed"
        elif rep and (rep.startswith("UJOINT") or rep == "CARDAN"):
            t = "universal"
        if t == "fixed":
            welds.append((j.parent, j.child, None))
            continue
        point = direction = direction2 = None
        if model.existJointName(j.name):
            jid = model.getJointId(j.name)
            M = state.joint_placement(jid)
            point = M.translation.copy()
            if t in ("revolute", "continuous", "prismatic", "planar"):
                direction = M.rotation @ np.asarray(j.axis)
            elif t == "universal":  # a native universal joint from a sidecar replacement
                a1, a2 = axis_letters(rep)
                base = state.joint_placement(model.parents[jid]) * model.jointPlacements[jid]
                direction, direction2 = base.rotation @ a1, M.rotation @ a2
        dof = {"spherical": 3, "universal": 2}.get(t, j.dof)
        edges.append(_Edge(j.name, t, dof, j.parent, j.child, False, point, direction, direction2))
    specs = {s.name: s for s in mech.spec.cut_joints}
    for c in mech.cuts:
        a = frame_link(mech, c.link1)
        b = frame_link(mech, c.link2)
        if c.pair is not None:  # one higher (or screw) pair between the two links, at F1
            M1 = state.frame_placement(model.getFrameId(f"{c.name}@F1"))
            s = specs.get(c.name)
            profile = f"{s.profile1[0]}-{s.profile2[0]}" if s is not None and s.profile1 else None
            edges.append(_Edge(c.name, c.pair, CUT_JOINT_DOF[c.pair], a, b, True, M1.translation.copy(),
                               M1.rotation @ np.asarray(c.axis), None, profile))
            continue
        if c.type == "fixed":
            welds.append((a, b, c.name))
            continue
        M1 = state.frame_placement(c.frame1)
        direction = direction2 = None
        if c.type in ("revolute", "continuous", "prismatic", "cylindrical", "planar", "universal"):
            direction = M1.rotation @ np.asarray(c.axis)
        if c.type == "universal":
            direction2 = state.frame_placement(c.frame2).rotation @ np.asarray(c.axis2)
        edges.append(_Edge(c.name, c.type, c.dof, a, b, True, M1.translation.copy(), direction, direction2))
    return edges, welds


def _unit_vector(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _parallel(d1: np.ndarray, d2: np.ndarray, tol: float):
    return np.linalg.norm(np.cross(_unit_vector(d1), _unit_vector(d2))) < tol


def _line_distance(p1: np.ndarray, d1: np.ndarray, p2: np.ndarray, d2: np.ndarray, tol: float):
    n = np.cross(_unit_vector(d1), _unit_vector(d2))
    if np.linalg.norm(n) < tol:  # parallel: distance between the lines
        w = p2 - p1
        return np.linalg.norm(w - (w @ _unit_vector(d1)) * _unit_vector(d1))
    return abs((p2 - p1) @ _unit_vector(n))


def _compound_name(members: list, kind: str) -> str:
    """A readable name: the members' common prefix (e.g. 'ankle_rod_rev0..2' -> 'ankle_rod'), or all names."""

    prefix = os.path.commonprefix(members)
    for tail in ("_rev", "rev", "_"):
        if prefix.endswith(tail):
            prefix = prefix[: -len(tail)]
    if len(prefix) >= 3:
        return f"{prefix}[{SYMBOL[kind]}]"
    return "+".join(members)


def _classify_chain(chain: list, tol: float, scale, coupled: frozenset=frozenset()) -> str | None:
    """The compound type of a chain of 1-DOF edges through massless links, or None.
    coupled: the pairs of joint names one of which mimics the other."""
    kinds = [e.type for e in chain]
    if any(e.direction is None or e.point is None for e in chain):
        return None
    lt = tol * max(scale, 1.0)
    rev = [e for e in chain if e.type in ("revolute", "continuous")]
    pri = [e for e in chain if e.type == "prismatic"]
    if len(chain) == 2 and len(rev) == 2:
        a, b = rev
        if not _parallel(a.direction, b.direction, tol) and _line_distance(
            a.point, a.direction, b.point, b.direction, tol
        ) < lt:
            return "universal"
    if len(chain) == 2 and len(rev) == 1 and len(pri) == 1:
        if _parallel(rev[0].direction, pri[0].direction, tol):
            # a prismatic joint that mimics the revolute on its axis (or the other way) is a screw
            if frozenset((rev[0].name, pri[0].name)) in coupled:
                return "helical"
            return "cylindrical"
    if len(chain) == 3 and len(rev) == 3:
        dirs = np.array([_unit_vector(e.direction) for e in rev])
        if np.linalg.matrix_rank(dirs, tol=tol) == 3:
            _, dist = lines_point([e.point for e in rev], dirs, DEFAULT.equal)
            if dist < lt:
                return "spherical"
    del kinds
    return None


def _chain_through(start: str, candidates: set[str], incident: dict[str, list[int]], edges: list[_Edge],
                   body_name: dict[str, str]) -> tuple[set[str], list[_Edge], str, str] | None:
    """The run of candidate bodies through ``start`` and the chain of edges through it, in order from one end
    to the other: (run, chain, the body at its first end, the body at its last), or None when the run does not
    have exactly two ends."""
    run = {start}
    stack = [start]
    while stack:
        r = stack.pop()
        for k in incident[r]:
            other = edges[k].b if edges[k].a == r else edges[k].a
            if other in candidates and other not in run:
                run.add(other)
                stack.append(other)
    ends = []
    for r in sorted(run, key=lambda r: body_name[r]):  # not set order: the same output whatever the hash seed
        for k in incident[r]:
            other = edges[k].b if edges[k].a == r else edges[k].a
            if other not in run:
                ends.append((r, k))
    if len(ends) != 2:
        return None
    # walk from one end to the other
    chain, r, k = [], ends[0][0], ends[0][1]
    chain.append(edges[k])
    prev = k
    while True:
        nxt = [x for x in incident[r] if x != prev]
        k = nxt[0]
        chain.append(edges[k])
        other = edges[k].b if edges[k].a == r else edges[k].a
        if other not in run:
            break
        r, prev = other, k
    outer = [edges[ends[0][1]], edges[ends[1][1]]]
    end_a = outer[0].a if outer[0].a not in run else outer[0].b
    end_b = outer[1].a if outer[1].a not in run else outer[1].b
    return run, chain, end_a, end_b


def _compound_joint(chain: list[_Edge], kind: str, links: tuple[str, str]) -> Joint:
    """The compound joint of type ``kind`` a chain of edges makes between ``links``: its centre and axes."""
    point = chain[0].point
    direction = direction2 = None
    if kind == "cylindrical":
        direction = next(e.direction for e in chain if e.type != "prismatic")
    elif kind == "spherical":
        point, _ = lines_point([e.point for e in chain], [e.direction for e in chain], DEFAULT.equal)
    elif kind == "universal":
        a, b = chain
        n = np.cross(_unit_vector(a.direction), _unit_vector(b.direction))
        # intersection point of the two axes
        A = np.stack([_unit_vector(a.direction), -_unit_vector(b.direction), n], axis=1)
        s = np.linalg.lstsq(A, b.point - a.point, rcond=None)[0]
        point = a.point + s[0] * _unit_vector(a.direction)
        # the first axis turns with the link at the start of the chain, the second with the end
        direction, direction2 = a.direction, b.direction
    return Joint(
        name=_compound_name([e.name for e in chain], kind),
        type=kind,
        dof=sum(e.dof for e in chain) - (1 if kind == "helical" else 0),
        links=links,
        members=tuple(e.name for e in chain),
        cut=any(e.cut for e in chain),
        point=tuple(point) if point is not None else None,
        direction=tuple(direction) if direction is not None else None,
        direction2=tuple(direction2) if direction2 is not None else None,
    )


def _bodies(mech: Any, welds: list) -> tuple[UnionFind, str, dict[str, list[str]], dict[str, str]]:
    """The rigid bodies the welds make of the links: (their union-find, the ground's root, root -> its links,
    root -> the body's name: its first URDF link, the ground's the root link)."""
    spec = mech.spec
    uf = UnionFind(list(spec.links))
    for a, b, _ in welds:
        uf.join(a, b)
    ground_root = uf.find(spec.root)
    groups: dict[str, list[str]] = {}
    for name in spec.links:
        groups.setdefault(uf.find(name), []).append(name)
    body_name = {r: (spec.root if r == ground_root else members[0]) for r, members in groups.items()}
    return uf, ground_root, groups, body_name


def build_topology(mech: Any, q: np.ndarray) -> Topology:
    """Links, joints (with compound joints recognized) and motion space at configuration q (``mech``: a
    model.mechanism.Mechanism, which imports this module)."""
    tol = mech.tolerances.geometry
    spec = mech.spec
    edges, welds = _edges(mech, q)
    uf, ground_root, groups, body_name = _bodies(mech, welds)
    for e in edges:
        e.a, e.b = uf.find(e.a), uf.find(e.b)
    scale = max([np.linalg.norm(e.point) for e in edges if e.point is not None] + [1e-3])

    # massless bodies of degree 2 between 1-DOF joints may be the inside of a compound joint
    incident: dict[str, list[int]] = {r: [] for r in groups}
    for k, e in enumerate(edges):
        incident[e.a].append(k)
        incident[e.b].append(k)
    dm = mech.tolerances.dummy_mass

    def massless(r: str) -> bool:
        return r != ground_root and all(spec.links[m].is_massless(dm) for m in groups[r])

    def one_dof(k: int) -> bool:
        return edges[k].type in ("revolute", "continuous", "prismatic")

    candidates = {r for r in groups if massless(r) and len(incident[r]) == 2 and all(one_dof(k) for k in incident[r])}
    coupled = frozenset(frozenset((c.joint, c.mimics)) for c in mech.couplings)
    consumed = set()
    used_edges: set[int] = set()
    dummies: set[str] = set()
    compounds = []
    for start in sorted(candidates, key=lambda r: body_name[r]):
        if start in dummies:
            continue
        found = _chain_through(start, candidates, incident, edges, body_name)
        if found is None:
            continue
        run, chain, end_a, end_b = found
        kind = _classify_chain(chain, tol, scale, coupled)
        if kind is None:
            continue
        dummies |= run
        used_edges |= {id(e) for e in chain}
        if kind == "helical":  # its coupling is the screw's lead: counted in the pair, not again
            consumed |= {c for c in mech.couplings if {c.joint, c.mimics} == {e.name for e in chain}}
        compounds.append(_compound_joint(chain, kind, (body_name[end_a], body_name[end_b])))
    joints = []
    for e in edges:
        if id(e) in used_edges:
            continue
        joints.append(
            Joint(e.name, e.type, e.dof, (body_name[e.a], body_name[e.b]), (e.name,), e.cut,
                  tuple(e.point) if e.point is not None else None,
                  tuple(e.direction) if e.direction is not None else None,
                  tuple(e.direction2) if e.direction2 is not None else None, e.profile)
        )
    joints += compounds
    links = tuple(body_name[r] for r in groups if r not in dummies)
    members = {body_name[r]: tuple(groups[r]) for r in groups if r not in dummies}
    dummy_links = tuple(m for r in sorted(dummies, key=lambda r: body_name[r]) for m in groups[r])
    space, detail, normal = _motion_space(joints, tol, scale)
    cut_welds = tuple(name for _, _, name in welds if name is not None)
    return Topology(links, members, body_name[ground_root], tuple(joints), space, detail, dummy_links, cut_welds,
                    normal, tuple(c for c in mech.couplings if c not in consumed))


def _motion_space(joints: list, tol: float, scale) -> tuple:
    """'planar' when every revolute axis is parallel to one normal and every
    prismatic axis perpendicular to it; 'spherical' when every joint is a
    rotation about one common point; 'spatial' otherwise."""
    lt = tol * max(scale, 1.0)
    if not joints:
        return "spatial", "no joints", None
    rot = [j for j in joints if j.type in ("revolute", "continuous")]
    pri = [j for j in joints if j.type == "prismatic"]
    other = [j for j in joints if j.type not in ("revolute", "continuous", "prismatic") + PLANAR_PAIRS]
    planar_pairs = [j for j in joints if j.type in PLANAR_PAIRS]
    if not other:
        normal = None
        if rot:
            normal = _unit_vector(np.asarray(rot[0].direction))
        elif planar_pairs:
            normal = _unit_vector(np.asarray(planar_pairs[0].direction))
        elif len(pri) >= 1:
            dirs = np.array([_unit_vector(np.asarray(j.direction)) for j in pri])
            u, s, vt = np.linalg.svd(dirs)
            if len(s) < 3 or s[-1] < tol:
                normal = vt[-1]
        if normal is not None:
            ok = all(_parallel(normal, np.asarray(j.direction), tol) for j in rot + planar_pairs)
            ok = ok and all(abs(normal @ _unit_vector(np.asarray(j.direction))) < tol for j in pri)
            if ok:
                normal = _unit_vector(normal)
                # one of the two normals, the same whatever the axes' signs: +z, else +y, else +x side
                for k in (2, 1, 0):
                    if abs(normal[k]) > DEFAULT.equal:
                        normal = normal * np.sign(normal[k])
                        break
                n = np.round(normal, 6) + 0.0
                return ("planar", f"every revolute axis is parallel to ({n[0]:g}, {n[1]:g}, {n[2]:g}) and every "
                        "prismatic axis perpendicular to it", tuple(normal))
    if not pri and not planar_pairs and all(j.type in ("revolute", "continuous", "spherical", "universal") for j in joints):
        lines = [(np.asarray(j.point), np.asarray(j.direction)) for j in rot]
        # a ball or universal joint's axes all pass through its centre: that centre is the common point
        centres = [np.asarray(j.point, float) for j in joints if j.type in ("spherical", "universal")
                   and j.point is not None]
        c = dist = None
        if centres:
            c = centres[0]
            dist = max([0.0] + [np.linalg.norm(np.cross(c - p, _unit_vector(d))) for p, d in lines])
        elif len(lines) >= 2:
            c, dist = lines_point([p for p, _ in lines], [d for _, d in lines], DEFAULT.equal)
        if c is not None and dist < lt and all(np.linalg.norm(p - c) < lt for p in centres):
            cc = np.round(c, 6) + 0.0
            return "spherical", f"every joint axis passes through ({cc[0]:g}, {cc[1]:g}, {cc[2]:g})", None
    axial = [j for j in joints if j.direction is not None and j.point is not None]
    if len(axial) == len(joints) and len(axial) >= 2:  # every joint's axis on one line: a screw, a slide along it
        p0, d0 = np.asarray(axial[0].point, float), _unit_vector(np.asarray(axial[0].direction, float))
        on_line = all(_parallel(d0, np.asarray(j.direction), tol)
                      and np.linalg.norm(np.cross(np.asarray(j.point, float) - p0, d0)) < lt for j in axial)
        if on_line:
            types = sorted({j.type for j in axial})
            return ("spatial", f"every joint axis lies on one line ({', '.join(types)}): the motion is a rotation "
                               "about and a translation along it, which neither the planar nor the spherical count "
                               "describes", None)
    parallel = all(_parallel(_unit_vector(np.asarray(rot[0].direction)), np.asarray(j.direction), tol) for j in rot) \
        if rot else False
    if parallel and pri:
        return ("spatial", "the revolute axes are parallel but a prismatic axis is not perpendicular to them (not "
                           "planar), and they meet in no point (not spherical)", None)
    return "spatial", "the joint axes are neither all parallel (planar) nor all concurrent (spherical)", None
