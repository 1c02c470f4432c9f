"""The geometry a skeleton diagram is drawn from, as plain data: the mechanism's links
numbered as textbooks do (ground = 1, then 2, 3, ... along the chain from the input), its
joints lettered A, B, C, ..., every joint centre and link outline projected into the plane
of motion, sliders' guide directions, higher pairs' profiles, the absolute link angles;
the kinematic chain (links as nodes, joints as edges); and the singular configurations
met along an input's range.

Numbering: a depth-first walk from the ground over the joints, the input joints first,
then the tree joints in the file's order, then the loop (cut) joints; each link is
numbered when first reached and each joint lettered when first crossed or met, so a
four-bar driven by its crank reads 1 ground, 2 crank, 3 coupler, 4 rocker, A the crank
pivot, B crank-coupler, C coupler-rocker, D the rocker pivot.

Projection: a planar mechanism is drawn in its plane of motion (x along the world x
axis projected into it, angles counterclockwise about the topology's normal: the frame
of :class:`~screwkin.analysis.motion.planar.LinkAngles`); a spherical or spatial one is
projected onto the plane of the two largest principal directions of its joint centres
(a schematic: lengths and angles are those of the projection).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ...errors import UsageError
from ...model.cuts import pair_contact
from ...model.geometry import TINY, line_foot, plane_basis
from ...model.state import KinematicState
from ..motion.planar import LinkAngles
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.files.description import CutJointSpec
    from screwkin.model.topology import Topology
    from screwkin.model.topology import Joint
    from collections.abc import Callable

__all__ = [
    "ChainEdge",
    "ChainNode",
    "KinematicChain",
    "Profile",
    "Skeleton",
    "SkeletonJoint",
    "SkeletonLink",
    "kinematic_chain",
    "letters",
    "numbering",
    "skeleton",
]


@dataclass(frozen=True)
class SkeletonLink:
    """A rigid link in the drawing plane.

    shape: "ground" (the fixed link: its pivots get the hatched ground symbol), "bar"
    (two distinct joint centres), "polygon" (three or more, not on one line: ternary,
    quaternary ... links), "block" (every joint centre at one point and a sliding joint:
    a slider), "stub" (one joint centre: a free end, drawn to its frame or its centre of
    mass), "point" (nothing to measure).  outline: the points to draw through [m, in the
    plane], the convex hull's corners for a polygon, in order."""

    number: int
    name: str
    shape: str
    outline: tuple
    joints: tuple  # letters of its joints
    ground: bool = False

    @property
    def degree(self) -> int:
        """Binary (2), ternary (3), ...: the number of joints on the link."""
        return len(self.joints)


@dataclass(frozen=True)
class SkeletonJoint:
    """A joint in the drawing plane.

    point: where its symbol goes (a pin's centre; a slider's position; a higher pair's
    contact point) [m, in the plane]; ends: its centre on each of its two links (a
    prismatic joint: the guide's reference point on the first link, the slider's on the
    second; a higher pair: the centres of its two profiles); direction: a unit vector in
    the plane along a prismatic joint's guide, or a spatial revolute's axis projected
    (None when it is normal to the plane or the joint has none); tilt: the angle between
    the joint's axis and the plane's normal [rad] (0 for every axis of a planar
    mechanism); value: its coordinate [rad or m] when it has one."""

    letter: str
    name: str
    type: str
    symbol: str
    links: tuple  # the numbers of its two links, in the file's order (parent, child / link1, link2)
    point: tuple
    ends: tuple
    direction: tuple | None
    tilt: float
    cut: bool
    input: bool
    value: float | None
    dof: int

    @property
    def ground(self) -> bool:
        return 1 in self.links


@dataclass(frozen=True)
class Profile:
    """One element of a higher pair: a circle (centre, radius), a line (a point on it and its
    direction) or a point, fixed on link ``link``, in the drawing plane [m]."""

    joint: str  # letter
    link: int
    shape: str  # "circle" | "line" | "point"
    centre: tuple
    radius: float | None = None
    direction: tuple | None = None


@dataclass(frozen=True)
class Skeleton:
    """Everything a skeleton diagram shows, in the drawing plane (e1, e2) [m]."""

    path: str
    motion_space: str
    planar: bool  # drawn in the plane of motion; False: a schematic projection
    basis: tuple  # (e1, e2, n) world unit vectors: drawing x, drawing y, the view direction
    links: tuple  # SkeletonLink, by number
    joints: tuple  # SkeletonJoint, by letter
    profiles: tuple  # Profile
    inputs: dict  # input joint name -> value [rad or m]
    units: dict  # input joint name -> "rad" | "m"
    size: float  # the extent of the joint centres [m] (at least the characteristic length / 2)
    angles: dict | None  # planar: link number -> absolute angle [rad] (LinkAngles); None otherwise
    angle_origins: dict | None  # planar: link number -> the point its angle is measured at

    def link(self, number: int) -> SkeletonLink:
        return self.links[number - 1]

    def joint(self, letter: str) -> SkeletonJoint:
        return next(j for j in self.joints if j.letter == letter)


@dataclass(frozen=True)
class ChainNode:
    number: int
    name: str
    degree: int  # joints on the link
    ground: bool


@dataclass(frozen=True)
class ChainEdge:
    letter: str
    name: str
    type: str
    symbol: str
    dof: int
    links: tuple  # (number, number)
    cut: bool


@dataclass(frozen=True)
class KinematicChain:
    """The kinematic chain as a graph: a node per link, an edge per joint (a multigraph: two
    links may share several joints), with the structural counts."""

    path: str
    nodes: tuple
    edges: tuple
    loops: int
    motion_space: str
    count: int  # the mobility count in its motion space (Gruebler, spherical or Kutzbach)
    count_name: str


#: Joint names of at most this many letters and digits, the first a capital (A, B, O2, O4), are kept as
#: the joints' letters in drawings.
SHORT_NAME = 3


def letters(k: int) -> str:
    """0 -> A, 25 -> Z, 26 -> AA, ..."""
    s = ""
    k += 1
    while k:
        k, r = divmod(k - 1, 26)
        s = chr(ord("A") + r) + s
    return s


def _is_input(joint: Joint, inputs: set | list) -> bool:
    return any(m in inputs for m in joint.members)


def numbering(topo: Topology, inputs: list=()) -> tuple:
    """(link name -> number, joint name -> letter, joints in letter order) for a topology:
    ground 1 and a depth-first walk from it (see the module docstring).  A joint whose name is at
    most SHORT_NAME letters and digits, the first a capital (A, B, O2), keeps it as its letter; the others are lettered
    A, B, C, ... skipping the letters so taken."""
    inputs = set(inputs)
    order = sorted(range(len(topo.joints)),
                   key=lambda k: (not _is_input(topo.joints[k], inputs), topo.joints[k].cut, k))
    joints = [topo.joints[k] for k in order]
    number, letter, lettered = {topo.ground: 1}, {}, []
    # the user's own short joint names (A, B, O2, O4: up to 3 characters) are their letters; the others
    # get the next free letter (a legend names them)
    own = {j.name for j in joints if re.fullmatch(rf"[A-Z][A-Za-z0-9]{{0,{SHORT_NAME - 1}}}", j.name)}
    taken, next_letter = set(own), [0]

    def mark(j) -> None:
        if j.name not in letter:
            if j.name in own:
                letter[j.name] = j.name
            else:
                while letters(next_letter[0]) in taken:
                    next_letter[0] += 1
                letter[j.name] = letters(next_letter[0])
                taken.add(letter[j.name])
            lettered.append(j)

    def visit(link: str | int) -> None:
        for j in joints:
            if link not in j.links:
                continue
            other = j.links[1] if j.links[0] == link else j.links[0]
            mark(j)
            if other not in number:
                number[other] = len(number) + 1
                visit(other)

    visit(topo.ground)
    for link in topo.links:  # links not connected to the ground (a floating body)
        if link not in number:
            number[link] = len(number) + 1
            visit(link)
    for j in joints:
        mark(j)
    return number, letter, tuple(lettered)


def _frame_point(state: KinematicState, name: str):
    return state.frame_placement(state.mech.model.getFrameId(name))


def _joint_ends(state: KinematicState, j) -> tuple:
    """(point on links[0], point on links[1], axis or None) of a topology joint, in the world, at
    the configuration of ``state`` (a model.state.KinematicState)."""
    model = state.mech.model
    p = np.asarray(j.point, float) if j.point is not None else None
    axis = np.asarray(j.direction, float) if j.direction is not None else None
    if len(j.members) == 1:
        name = j.members[0]
        if j.cut:
            a, b = _frame_point(state, f"{name}@F1"), _frame_point(state, f"{name}@F2")
            return a.translation.copy(), b.translation.copy(), axis
        if model.existJointName(name):
            jid = model.getJointId(name)
            child = state.joint_placement(jid).translation.copy()
            parent = (state.joint_placement(model.parents[jid]) * model.jointPlacements[jid]).translation.copy()
            return parent, child, axis
    return p, p, axis


def _hull(points: list) -> list:
    """Convex hull corners of 2-D points, counterclockwise (monotone chain)."""
    pts = sorted(set(points))
    if len(pts) <= 2:
        return pts

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def _distinct(points: list, tol: float) -> list:
    out = []
    for p in points:
        if all(np.hypot(p[0] - r[0], p[1] - r[1]) > tol for r in out):
            out.append(p)
    return out


def _basis(mech: Mechanism, topo: Topology, centres: list) -> tuple:
    if topo.motion_space == "planar" and topo.normal is not None:
        return plane_basis(topo.normal), True
    P = np.array(centres) if centres else np.zeros((1, 3))
    if len(P) >= 3:
        _, _, vt = np.linalg.svd(P - P.mean(axis=0))
        n = vt[-1] if vt.shape[0] == 3 else np.cross(vt[0], vt[1])
    else:
        n = np.array([0.0, 0.0, 1.0])
    k = int(np.argmax(np.abs(n)))
    n = n * np.sign(n[k])
    e1, e2, n = plane_basis(n)
    if e2[2] < -mech.tolerances.equal:  # the world's +z drawn upwards where it can be
        e1, e2, n = plane_basis(-n)
    return (e1, e2, n), False


def skeleton(mech: Mechanism, q: np.ndarray, inputs: list[str] | None=None, basis=None) -> Skeleton:
    """The :class:`Skeleton` of ``mech`` at configuration ``q``; ``inputs``: the input joints
    (default: the actuated ones), marked and listed with their values; ``basis``: the drawing
    plane (e1, e2, n) of another skeleton (the frames of an animation: a spatial mechanism's
    projection plane is otherwise fitted to each configuration)."""
    q = np.asarray(q, float)
    inputs = list(inputs) if inputs else list(mech.actuated)
    topo = mech.topology(q)
    state = KinematicState(mech, q)
    number, letter, ordered = numbering(topo, inputs)
    ends3 = {j.name: _joint_ends(state, j) for j in ordered}
    centres = [p for a, b, _ in ends3.values() for p in (a, b) if p is not None]
    (e1, e2, n), planar = _basis(mech, topo, centres)
    if basis is not None:
        e1, e2, n = (np.asarray(v, float) for v in basis)

    def p2(v: np.ndarray) -> tuple[float, float]:
        return (float(np.asarray(v) @ e1), float(np.asarray(v) @ e2))

    values = mech.joint_values(q)
    tolerances = mech.tolerances
    tol = tolerances.geometry * mech.length
    specs = {s.name: s for s in mech.spec.cut_joints}
    joints, profiles = [], []
    for j in ordered:
        a, b, axis = ends3[j.name]
        if a is None:  # no geometry (a floating joint): at the child's frame
            a = b = state.frame_placement(mech.link_frame(j.links[1])).translation.copy()
        direction, tilt = None, 0.0
        if axis is not None:
            u = axis / np.linalg.norm(axis)
            tilt = float(np.arccos(np.clip(abs(u @ n), 0.0, 1.0)))
            if j.type == "prismatic" or (not planar and tilt > tolerances.geometry):
                d = np.array([u @ e1, u @ e2])
                if np.linalg.norm(d) > tolerances.equal:
                    direction = tuple(float(x) for x in d / np.linalg.norm(d))
        point = p2(b) if j.type == "prismatic" else p2(a)
        if j.cut and j.type in ("rolling", "gear", "contact") and j.name in specs:
            point, pair_profiles = _higher_pair(state, specs[j.name], letter[j.name],
                                                (number[j.links[0]], number[j.links[1]]), p2, e1, e2)
            profiles += pair_profiles
        value = values.get(j.members[0]) if len(j.members) == 1 else None
        joints.append(SkeletonJoint(letter[j.name], j.name, j.type, j.symbol, (number[j.links[0]], number[j.links[1]]),
                                    point, (p2(a), p2(b)), direction, tilt, j.cut, _is_input(j, inputs), value, j.dof))
    links = []
    for name in sorted(number, key=number.get):
        mine = [s for s in joints if number[name] in s.links]
        pts = [s.ends[s.links.index(number[name])] if s.links[0] != s.links[1] else s.point for s in mine]
        pts = _distinct(pts, tol)
        if name == topo.ground:
            shape, outline = "ground", tuple(pts)
        elif len(pts) >= 3:
            hull = _hull([(round(x, 12), round(y, 12)) for x, y in pts])
            if len(hull) >= 3 and _area(hull) > tolerances.geometry * mech.length ** 2:
                shape, outline = "polygon", tuple(hull)
            else:
                shape, outline = "bar", _extremes(pts)
        elif len(pts) == 2:
            shape, outline = "bar", tuple(pts)
        elif len(pts) == 1 and any(s.type in ("prismatic", "cylindrical") for s in mine):
            shape, outline = "block", tuple(pts)
        else:
            shape, outline = _stub(state, name, pts, p2, tol)
        links.append(SkeletonLink(number[name], name, shape, outline, tuple(s.letter for s in mine),
                                  name == topo.ground))
    allpts = [p for s in joints for p in (s.point, *s.ends)] + [p for lk in links for p in lk.outline]
    allpts += [(p.centre[0] + sx * (p.radius or 0.0), p.centre[1] + sy * (p.radius or 0.0))
               for p in profiles for sx in (-1, 1) for sy in (-1, 1)]
    P = np.array(allpts) if allpts else np.zeros((1, 2))
    size = float(max(np.max(P.max(axis=0) - P.min(axis=0)), 0.5 * mech.length))
    angles = origins = None
    if planar:
        try:
            la = LinkAngles(mech, topo)
        except UsageError:
            la = None
        if la is not None:
            th = la(q, state)
            angles = {number[k]: v for k, v in th.items() if k in number}
            origins = {}
            for k in th:
                if k in number:
                    start = la.links[k][0]
                    origins[number[k]] = p2(state.centre(start))
    units = {k: ("m" if mech.translational[mech.coordinate(k).idx_v] else "rad") for k in inputs}
    return Skeleton(str(mech.path), topo.motion_space, planar, (tuple(e1), tuple(e2), tuple(n)), tuple(links),
                    tuple(joints), tuple(profiles), {k: values[k] for k in inputs}, units, size, angles, origins)


def _area(hull: list) -> float:
    x = np.array([p[0] for p in hull])
    y = np.array([p[1] for p in hull])
    return 0.5 * abs(float(x @ np.roll(y, -1) - y @ np.roll(x, -1)))


def _extremes(pts: np.ndarray | list) -> tuple[tuple, tuple]:
    P = np.array(pts)
    c = P.mean(axis=0)
    _, _, vt = np.linalg.svd(P - c)
    s = (P - c) @ vt[0]
    return (tuple(P[int(np.argmin(s))]), tuple(P[int(np.argmax(s))]))


def _stub(state: KinematicState, name: str, pts: np.ndarray | list, p2: Callable[[np.ndarray], tuple[float, float]], tol: float) -> tuple[str, tuple]:
    """A link with one joint centre: drawn to its frame's origin, else its centre of mass,
    else a short stub along its frame's x axis."""
    mech = state.mech
    M = state.frame_placement(mech.link_frame(name))
    if not pts:
        return "point", (p2(M.translation),)
    jid = mech.model.frames[mech.link_frame(name)].parentJoint
    cands = [p2(M.translation), p2(state.joint_placement(jid).act(mech.model.inertias[jid].lever))]
    for c in cands:
        if np.hypot(c[0] - pts[0][0], c[1] - pts[0][1]) > 100 * tol:
            return "stub", (pts[0], c)
    x = M.rotation[:, 0] * 0.2 * mech.length
    end = p2(M.translation + x)
    return "stub", (pts[0], end)


def _higher_pair(state: KinematicState, spec: CutJointSpec, letter: str, nums: tuple, p2: Callable[[np.ndarray], tuple[float, float]], e1: np.ndarray, e2: np.ndarray) -> tuple:
    """(contact point, profiles) of a rolling, gear or contact pair in the plane."""
    F1, F2 = _frame_point(state, f"{spec.name}@F1"), _frame_point(state, f"{spec.name}@F2")
    c1, c2 = np.array(p2(F1.translation)), np.array(p2(F2.translation))

    def along_x(M):
        d = np.array([M.rotation[:, 0] @ e1, M.rotation[:, 0] @ e2])
        return d / max(np.linalg.norm(d), 1e-300)

    if spec.type in ("rolling", "gear"):
        shapes = [("line", None) if np.isinf(spec.radius1) else ("circle", spec.radius1), ("circle", spec.radius2)]
    else:
        shapes = [spec.profile1, spec.profile2]
    out = []
    for (shape, r), c, M, num in zip(shapes, (c1, c2), (F1, F2), nums):
        d = tuple(float(x) for x in along_x(M)) if shape == "line" else None
        out.append(Profile(letter, num, shape, (float(c[0]), float(c[1])), float(r) if shape == "circle" else None, d))
    if spec.type in ("rolling", "gear"):  # where the pitch curves touch: model.cuts.pair_contact, the one place
        return p2(pair_contact(spec, F1, F2)[0]), out
    contact = _contact_point(out[0], out[1])
    return (float(contact[0]), float(contact[1])), out


def _contact_point(a: Profile, b: Profile):
    """Where two profiles of a sliding contact (point, line, circle) touch, in the plane."""
    ca, cb = np.array(a.centre), np.array(b.centre)
    if a.shape == "point":
        return ca
    if b.shape == "point":
        return cb
    if a.shape == "line" and b.shape == "circle":
        return line_foot(cb, ca, a.direction)
    if b.shape == "line" and a.shape == "circle":
        return line_foot(ca, cb, b.direction)
    u = cb - ca
    dist = np.linalg.norm(u)
    if dist < TINY:  # division guard
        return ca
    u = u / dist
    return ca + a.radius * u  # on circle 1 towards circle 2's centre (outside, or inside it: internal)


def kinematic_chain(mech: Mechanism, q: np.ndarray | None = None, inputs: list[str] | None=None) -> KinematicChain:
    """The kinematic chain of ``mech`` (numbered as :func:`skeleton` numbers it)."""
    inputs = list(inputs) if inputs else list(mech.actuated)
    topo = mech.topology(q)
    number, letter, ordered = numbering(topo, inputs)
    degree = {name: sum(1 for j in topo.joints for link in j.links if link == name) for name in topo.links}
    nodes = tuple(ChainNode(number[name], name, degree[name], name == topo.ground)
                  for name in sorted(number, key=number.get))
    edges = tuple(ChainEdge(letter[j.name], j.name, j.type, j.symbol, j.dof, (number[j.links[0]], number[j.links[1]]),
                            j.cut) for j in ordered)
    name = {"planar": "Gruebler", "spherical": "spherical count"}.get(topo.motion_space, "Kutzbach")
    return KinematicChain(str(mech.path), nodes, edges, topo.loops, topo.motion_space, topo.count_in_motion_space, name)


