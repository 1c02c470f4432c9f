"""Textbook extras for planar four-bars and slider-cranks driven from a ground joint.

Recognized from the topology (4 links, 4 joints, planar, one loop; four
revolutes, or three revolutes and a prismatic joint to the ground), with
lengths measured between joint centres in the plane of motion:

- Grashof class: s + l against p + q (four-bar); full crank rotation when
  crank + |offset| <= rod (slider-crank);
- transmission angle mu: four-bar, the angle at the coupler-output joint
  between coupler and output link; slider-crank, the angle between the rod and
  the normal of the slide.  90 deg transmits force best in both;
- the input range, from the circle condition |b - c| <= |BD| <= b + c (or the
  rod reaching the slide), and the input values at the output's limit
  positions (input and coupler collinear: dead centres of the output).

Angles are returned as input *joint values* [rad] of the circuit the
configuration is on.  :func:`transmission_angles` gives mu at a stack of configurations
from one identification (the joint centres by forward kinematics, the angles all at once).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ...errors import UsageError
from ...model._pin import joint_axis
from ...model.state import KinematicState
from ...model.geometry import wrap_angle as _wrap
from ...model.manifold import continuous_angle
from ...model.geometry import (
    circle_intersections,
    cross2,
    line_circle,
    perpendicular_basis,
    plane_basis,
    vector_angle,
)
from ...model.kernel.stacks import tree_kinematics
from .transmission import (FOUR_BAR_CLASSES, four_bar_classes, slide_transmission_angle, transmission_angle,
                           transmission_range)
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.model.topology import Joint
    from screwkin.model.topology import Topology
    from screwkin.tolerances import Tolerances

__all__ = ["LinkageInfo", "identify", "transmission_angles", "LinkAngles"]


@dataclass(frozen=True)
class LinkageInfo:
    kind: str  # "four-bar" | "slider-crank"
    lengths: dict  # [m]
    grashof: str
    input_joint: str
    input_range: tuple | None  # (low, high) joint values; None: the input turns fully
    limit_inputs: tuple  # input joint values where the output is at a limit position
    transmission_angle: float  # mu [rad] at the configuration analysed
    # four-bar: the textbook's diagonal construction at the configuration analysed: diagonal z from the
    # crank tip to the output pivot [m]; at the output pivot, alpha between the diagonal and the output
    # link and beta between the diagonal and the ground link [rad, 0..pi]
    diagonal: float | None = None
    alpha: float | None = None
    beta: float | None = None
    # where transmission_angles finds the centres of the joints A (input), B, C, D at any
    # configuration, the plane's normal and the slide's direction (slider-crank), in the world
    centres: tuple = field(default=(), compare=False, repr=False)
    normal: tuple | None = field(default=None, compare=False, repr=False)
    slide: tuple | None = field(default=None, compare=False, repr=False)
    # the input's joint value and its angle (four-bar: from the ground line A -> D; slider-crank: from the
    # slide's direction) at the configuration analysed [rad]; a slider-crank's slide offset with its sign
    # (the distance of the slide line from the crank's pivot, along the slide's normal) [m]
    input_value: float | None = None
    input_angle: float | None = None
    signed_offset: float | None = None
    # the transmission angle over the input's whole motion, located in closed form (analysis.motion.transmission)
    transmission: object = field(default=None, compare=False)

    def construction(self) -> dict:
        """JSON-ready: four-bar {transmission_angle, diagonal, alpha, beta}; slider-crank {transmission_angle}."""
        d = {"kind": self.kind, "transmission_angle": self.transmission_angle}
        if self.diagonal is not None:
            d.update(diagonal=self.diagonal, alpha=self.alpha, beta=self.beta)
        return d


def _rot(v: np.ndarray, ang: float) -> np.ndarray:
    c, s = np.cos(ang), np.sin(ang)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _angle(v: np.ndarray) -> float:
    return float(np.arctan2(v[1], v[0]))


def _interval(start: float, end: float, phi_now: float, q_in: np.ndarray) -> tuple:
    """Joint values of the angle interval [start, end] (end > start) that contains phi_now."""
    k = np.floor((phi_now - start) / (2 * np.pi))
    start, end = start + 2 * np.pi * k, end + 2 * np.pi * k
    return (q_in + start - phi_now, q_in + end - phi_now)


def identify(mech: Mechanism, topo: Topology, q: np.ndarray, input_joint: str) -> LinkageInfo | None:
    """A :class:`LinkageInfo` for a planar four-bar or slider-crank whose input
    joint is a ground joint, at the configuration ``topo`` was built at (q)."""
    if topo.motion_space != "planar" or (topo.n_links, topo.n_joints, topo.loops) != (4, 4, 1):
        return None
    joints = {j.name: j for j in topo.joints}
    inp = joints.get(input_joint)
    ground = topo.ground
    if inp is None or ground not in inp.links or inp.type not in ("revolute", "continuous"):
        return None
    n = np.asarray(inp.direction) / np.linalg.norm(inp.direction)
    e1, e2 = perpendicular_basis(n)  # (e1, e2, n) right-handed: positive joint rotation is counterclockwise

    def p2(v: np.ndarray) -> np.ndarray:
        v = np.asarray(v)
        return np.array([v @ e1, v @ e2])

    def other(link: str, joint):
        return next(j for j in topo.joints if j is not joint and link in j.links)

    moving = inp.links[1] if inp.links[0] == ground else inp.links[0]
    j_b = other(moving, inp)
    coupler = j_b.links[1] if j_b.links[0] == moving else j_b.links[0]
    j_c = other(coupler, j_b)
    j_d = other(ground, inp)
    coord = mech.coordinate(input_joint)
    q_in = float(continuous_angle(q, coord.idx_q)) if coord.nq == 2 else float(q[coord.idx_q])
    A, B, C = p2(inp.point), p2(j_b.point), p2(j_c.point)
    a, b = np.linalg.norm(B - A), np.linalg.norm(C - B)
    where = {"centres": tuple(_locator(mech, j) for j in (inp, j_b, j_c, j_d)), "normal": tuple(n)}
    if j_d.type in ("revolute", "continuous") and j_c.type in ("revolute", "continuous") \
            and j_b.type in ("revolute", "continuous"):
        info = _four_bar(input_joint, q_in, A, B, C, p2(j_d.point), a, b, mech.tolerances)
        return replace(info, transmission=transmission_range(info, mech.tolerances.equal), **where)
    if j_d.type == "prismatic" or j_c.type == "prismatic":
        slide = j_d if j_d.type == "prismatic" else j_c
        pin_joint = j_c if slide is j_d else j_d
        if slide is j_c:  # the prismatic joint is between rod and slider: not the textbook slider-crank
            return None
        s = p2(np.asarray(slide.direction) + 0) - p2(np.zeros(3))
        s = s / np.linalg.norm(s)
        info = _slider_crank(input_joint, q_in, A, B, p2(pin_joint.point), s, a, b)
        return replace(info, slide=tuple(s[0] * e1 + s[1] * e2), transmission=transmission_range(info, mech.tolerances.equal),
                       **where)
    return None


def _locator(mech: Mechanism, joint: Joint) -> tuple:
    """How to find ``joint``'s centre at any configuration: ("frame", id) of a cut joint's F1,
    ("joint", id) of a simple tree joint, or ("topology", name) for a compound joint (its
    centre is the topology's, rebuilt at each configuration)."""
    cuts = {c.name: c for c in mech.cuts}
    if joint.cut and joint.name in cuts:
        return ("frame", cuts[joint.name].frame1)
    if not joint.cut and len(joint.members) == 1 and mech.model.existJointName(joint.members[0]):
        return ("joint", mech.model.getJointId(joint.members[0]))
    return ("topology", joint.name)


def transmission_angles(mech: Mechanism, info: LinkageInfo, Q: np.ndarray) -> np.ndarray:
    """Transmission angles mu [rad] of the linkage ``info`` (from :func:`identify`, computed
    once) at the configurations Q (N, nq): shape (N,).  Four-bar: the angle at the
    coupler-output joint C between C -> B and C -> D; slider-crank: the angle between the rod
    B -> C and the normal of the slide; both in the plane of motion."""
    Q = np.atleast_2d(np.asarray(Q, float))
    P = np.empty((len(Q), 4, 3))
    tree = tree_kinematics(mech) if all(kind != "topology" for kind, _ in info.centres) else None
    if tree is not None:  # the centres' stacked form: one pass down the tree for the whole stack
        at = tree.centres(Q, info.centres)
        for i, ref in enumerate(info.centres):
            P[:, i] = at[ref]
    for k, q in enumerate(Q if tree is None else ()):
        state, topo = KinematicState(mech, q), None
        for i, (kind, ident) in enumerate(info.centres):
            if kind == "topology":
                topo = topo or mech.topology(q)
                P[k, i] = next(j.point for j in topo.joints if j.name == ident)
            else:
                P[k, i] = state.centre((kind, ident))
    return _transmission(info.kind, P, np.asarray(info.normal, float),
                         None if info.slide is None else np.asarray(info.slide, float))


def _transmission(kind: str, P: np.ndarray, n: np.ndarray, slide: np.ndarray | None=None):
    """mu [rad] from the joint centres P (..., 4, 3) = A, B, C, D projected on the plane with
    unit normal n (slide: the slide's unit direction, slider-crank)."""
    P = P - (P @ n)[..., None] * n
    B, C, D = P[..., 1, :], P[..., 2, :], P[..., 3, :]
    if kind == "four-bar":
        return transmission_angle(B, C, D)
    return slide_transmission_angle(B, C, np.cross(n, slide))


def _four_bar(name: str, q_in: np.ndarray | float, A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, a: float, b: float, tol: Tolerances) -> LinkageInfo:
    g, c = np.linalg.norm(D - A), np.linalg.norm(D - C)
    lengths = {"ground": g, "input": a, "coupler": b, "output": c}
    cls = FOUR_BAR_CLASSES[int(four_bar_classes(g, a, b, c, tol.equal))]
    u_ad = (D - A) / g
    phi_now = _angle(_rot(B - A, -_angle(u_ad)))  # input angle from AD
    circuit = np.sign(cross2(C - B, D - C)) or 1.0

    lo = (a * a + g * g - (b + c) ** 2) / (2 * a * g)
    hi = (a * a + g * g - (b - c) ** 2) / (2 * a * g)
    rng = None
    if hi < 1 and lo > -1:  # two intervals, one for each sign of phi
        x, y = np.arccos(hi), np.arccos(lo)
        rng = _interval(x, y, phi_now, q_in) if np.sin(phi_now) >= 0 else _interval(-y, -x, phi_now, q_in)
    elif lo > -1:  # passes through phi = 0
        rng = _interval(-np.arccos(lo), np.arccos(lo), phi_now, q_in)
    elif hi < 1:  # passes through phi = pi
        rng = _interval(np.arccos(hi), 2 * np.pi - np.arccos(hi), phi_now, q_in)
    # the output is at a limit where input and coupler are collinear (B on line AC), on this circuit
    limits = []
    for dist, folded in ((a + b, False), (abs(b - a), True)):
        for Cc in circle_intersections(A, dist, D, c, slack=tol.zero, concentric=1e-15):
            u = (Cc - A) / max(np.linalg.norm(Cc - A), 1e-300)
            Bc = A - a * u if folded and b > a else A + a * u
            if (np.sign(cross2(Cc - Bc, D - Cc)) or circuit) != circuit:
                continue
            limits.append(q_in + _wrap(_angle(_rot(Bc - A, -_angle(u_ad))) - phi_now))
    mu = float(transmission_angle(B, C, D))
    z = float(np.linalg.norm(B - D))
    # an angle with a vanishing side has no value (None, not NaN): the diagonal vanishes when the crank
    # tip sits on the output pivot, the output link or the ground when their two pivots coincide
    alpha = float(vector_angle(B - D, C - D)) if z > 0 and c > 0 else None
    beta = float(vector_angle(B - D, A - D)) if z > 0 and g > 0 else None
    return LinkageInfo("four-bar", lengths, cls, name, rng, tuple(sorted(limits)), mu, z, alpha, beta,
                       input_value=float(q_in), input_angle=float(phi_now))


def _slider_crank(name: str, q_in: np.ndarray | float, A: np.ndarray, B: np.ndarray, C: np.ndarray, s: np.ndarray, a: float, b: float) -> LinkageInfo:
    nrm = np.array([-s[1], s[0]])
    e = float((C - A) @ nrm)  # offset of the slide line from the crank pivot
    lengths = {"crank": a, "rod": b, "offset": abs(e)}
    full = a + abs(e) <= b
    cls = ("crank turns fully (crank + |offset| <= rod)" if full
           else "crank cannot turn fully (crank + |offset| > rod): it rocks")
    phi_now = _angle(np.array([(B - A) @ s, (B - A) @ nrm]))  # crank angle from the slide direction

    rng = None
    if not full:  # the rod reaches the slide line while |e - a sin(phi)| <= b
        lo, hi = (e - b) / a, (e + b) / a
        if lo > -1 and hi < 1:
            x, y = np.arcsin(lo), np.arcsin(hi)
            rng = _interval(x, y, phi_now, q_in) if np.cos(phi_now) >= 0 else _interval(np.pi - y, np.pi - x, phi_now, q_in)
        elif hi < 1:
            rng = _interval(np.pi - np.arcsin(hi), 2 * np.pi + np.arcsin(hi), phi_now, q_in)
        elif lo > -1:
            rng = _interval(np.arcsin(lo), np.pi - np.arcsin(lo), phi_now, q_in)
    side = np.sign((C - A) @ s) or 1.0
    limits = []
    for dist, folded in ((a + b, False), (abs(b - a), True)):
        meets = line_circle(A + e * nrm, s, A, dist)  # the slider's pin where the rod and crank are in line
        if not meets:
            continue
        Cc = meets[1] if side > 0 else meets[0]
        u = (Cc - A) / np.linalg.norm(Cc - A)
        Bc = A + (-a if folded and b > a else a) * u
        limits.append(q_in + _wrap(_angle(np.array([(Bc - A) @ s, (Bc - A) @ nrm])) - phi_now))
    mu = float(slide_transmission_angle(B, C, nrm))
    return LinkageInfo("slider-crank", lengths, cls, name, rng, tuple(sorted(limits)), mu, input_value=float(q_in),
                       input_angle=float(phi_now), signed_offset=e)


class LinkAngles:
    """Absolute angles of the links of a planar mechanism: the theta_i of the vector-loop
    method, measured in the plane from the ground's x axis, counterclockwise about the
    plane's normal (the topology's normal: its +z side, else +y, else +x).

    Each link's vector goes from the centre of the joint that carries it (its joint
    towards the ground in the file's tree) to the centre of the first other joint on it:
    the first joint it carries in the file's order, else the first loop joint on it.  A
    link with no second joint centre (a slider whose pin sits on its own axis, a free
    tip) is measured by its frame's x axis.  The ground's vector goes from its first
    joint centre to its first other one.  A joint a link carries is placed where it is
    mounted on that link (its placement in the parent, before its own motion): a prismatic
    child's slide does not turn its parent (the ground of a slider-crank kept a constant
    angle only while the slider stood still)."""

    def __init__(self, mech: Mechanism, topo: Topology) -> None:
        if topo.motion_space != "planar" or topo.normal is None:
            raise UsageError(f"{mech.path}: absolute link angles are for planar mechanisms; this one is "
                             f"{topo.motion_space}")
        self.mech = mech
        self.ground = topo.ground
        self.e1, self.e2, self.n = plane_basis(topo.normal)
        model = mech.model
        cut_frames = {}
        for c in mech.cuts:
            for f in (c.frame1, c.frame2):
                cut_frames.setdefault(model.frames[f].parentJoint, []).append(f)
        self.links = {}  # link name -> (start joint id, ("joint" | "frame" | "axis", id))
        for link in topo.links:
            fid = mech.link_frame(link)
            jid = model.frames[fid].parentJoint
            if link == topo.ground:
                starts = [k for k in range(1, model.njoints) if model.parents[k] == 0]
                if not starts:
                    continue
                start, candidates = ("mount", starts[0]), [("mount", k) for k in starts[1:]]
            else:
                start = ("joint", jid)
                candidates = [("mount", k) for k in model.children[jid]]
            candidates += [("frame", f) for f in cut_frames.get(jid, [])]
            self.links[link] = (start, candidates, fid)
        ends = self._ends(KinematicState(mech, mech.neutral()))
        self.links = {k: (start, ends[k], fid) for k, (start, _, fid) in self.links.items()}

    def _ends(self, state: KinematicState) -> dict:
        """Choose each link's second point (KinematicState.centre's references, or ("axis", its frame)): the
        first candidate away from its first point at the configuration of ``state``."""
        out = {}
        tiny = 1e-9 * self.mech.length
        for link, (start, candidates, fid) in self.links.items():
            p0 = state.centre(start)
            out[link] = next((c for c in candidates if np.linalg.norm(state.centre(c) - p0) > tiny), ("axis", fid))
        return out

    def __call__(self, q: np.ndarray | tuple, state: KinematicState | None=None) -> dict:
        """link name -> absolute angle [rad] in (-pi, pi] at q (read from ``state``, a KinematicState at q,
        when the caller has one)."""
        state = state or KinematicState(self.mech, q)
        out = {}
        for link, (start, end, fid) in self.links.items():
            if end[0] == "axis":
                v = state.frame_placement(fid).rotation[:, 0]
            else:
                v = state.centre(end) - state.centre(start)
            out[link] = float(np.arctan2(v @ self.e2, v @ self.e1))
        return out

    def guides(self, state: KinematicState) -> dict:
        """Prismatic joint (tree or loop) -> the angle of its slide in the plane [rad], from the
        ground's x axis, counterclockwise about the plane's normal, at the configuration of
        ``state`` (a model.state.KinematicState): a slider coordinate is a distance along it."""
        mech, model = self.mech, self.mech.model
        out = {}
        for c in mech.coordinates:
            if c.nq == 1 and c.nv == 1 and mech.translational[c.idx_v]:
                u = state.joint_placement(c.joint_id).rotation @ joint_axis(model.joints[c.joint_id])
                out[c.joint] = float(np.arctan2(u @ self.e2, u @ self.e1))
        for cut in mech.cuts:
            if cut.type == "prismatic" and cut.pair is None:
                u = state.frame_placement(cut.frame1).rotation @ np.asarray(cut.axis, float)
                out[cut.name] = float(np.arctan2(u @ self.e2, u @ self.e1))
        return out

    def along(self) -> dict:
        """link name -> (from, to): the two points its angle is measured along, by name -- the joint that
        carries it (the ground: its first joint), and the joint or loop joint its vector points to, or
        "x axis" where it is measured by its frame's x axis (no second joint centre on it).  A ternary
        link's angle is that of one of its sides: the Watt rocker's is along O4 -> the joint it carries in
        the file, not along O4 -> the loop joint; this names which."""
        names = self.mech.model.names
        loops = {f: c.name for c in self.mech.cuts for f in (c.frame1, c.frame2)}
        def named(ref):
            kind, i = ref
            return "x axis" if kind == "axis" else loops.get(i, str(i)) if kind == "frame" else str(names[i])
        return {link: (named(start), named(end)) for link, (start, end, _) in self.links.items()}

    def batch(self, Q: np.ndarray) -> dict:
        """link name -> (N,) absolute angles [rad] at every row of Q: __call__ on the stack, from one
        batched forward-kinematics pass (a loop over Q where the tree has joints of two coordinates)."""
        Q = np.atleast_2d(Q)
        tree = tree_kinematics(self.mech)
        if tree is None:
            rows = [self(q) for q in Q]
            return {link: np.array([r[link] for r in rows]) for link in self.links}
        at = tree.centres(Q, {r for start, end, _ in self.links.values() for r in (start, end) if r[0] != "axis"})
        by_axis = sorted({fid for _, end, fid in self.links.values() if end[0] == "axis"})
        axes = tree.frames(Q, by_axis, jacobian=False) if by_axis else {}
        out = {}
        for link, (start, end, fid) in self.links.items():
            v = axes[fid][0][:, :, 0] if end[0] == "axis" else at[end] - at[start]
            out[link] = np.arctan2(v @ self.e2, v @ self.e1)
        first = self(Q[0])  # a link along -e1 (+-pi) could come out with the other sign: then the loop
        if any(abs(out[link][0] - first[link]) > self.mech.tolerances.equal for link in out):
            rows = [self(q) for q in Q]
            return {link: np.array([r[link] for r in rows]) for link in self.links}
        return out

    def check(self, link: str) -> None:
        """A usage error unless ``link`` is a moving link of the mechanism (the ground's angle is fixed)."""
        moving = [k for k in self.links if k != self.ground]
        if link == self.ground:
            raise UsageError(f"{self.mech.path}: '{link}' is the ground: its angle is fixed (links: {', '.join(moving)})")
        if link not in self.links:
            try:
                jid = self.mech.model.frames[self.mech.link_frame(link)].parentJoint
            except UsageError:
                jid = None
            if jid == 0:
                raise UsageError(f"{self.mech.path}: '{link}' is fixed to the ground: its angle is fixed")
            body = next((k for k, (start, _, _) in self.links.items()
                         if k != self.ground and start == ("joint", jid)), None)
            if body is not None:
                raise UsageError(f"{self.mech.path}: '{link}' is fixed to '{body}' (its angle is that link's plus a "
                                 f"constant): give '{body}'")
            raise UsageError(f"{self.mech.path}: no moving link named '{link}' (links: {', '.join(moving)})")

    def pivoted(self, link: str) -> bool:
        """Whether ``link`` turns on a one-coordinate revolute joint to the ground (its angle is that
        joint's value plus a constant: joint_value); checked as ``check``."""
        self.check(link)
        model = self.mech.model
        jid = self.links[link][0][1]
        return (model.parents[jid] == 0 and model.joints[jid].shortname().startswith("JointModelR")
                and self.mech.coordinate(model.names[jid]).nv == 1)

    def pivot(self, link: str) -> tuple:
        """(joint name, sign) of the revolute joint that pivots ``link`` on the ground: the link's
        angle is sign * the joint's value + a constant, its angular velocity sign * the joint's rate."""
        mech, model = self.mech, self.mech.model
        if not self.pivoted(link):
            raise UsageError(f"{mech.path}: the absolute angle of '{link}' is not the value of one joint (it does "
                             "not turn on a revolute joint to the ground): set a joint with --set")
        jid = self.links[link][0][1]
        name = model.names[jid]
        axis = np.asarray(next(j.axis for j in mech.spec.joints if j.name == name), float)
        sign = float(np.sign((KinematicState(mech, mech.neutral()).joint_placement(jid).rotation @ axis) @ self.n))
        if sign == 0:
            raise UsageError(f"{mech.path}: joint '{name}' does not turn about the plane's normal")
        return name, sign

    def joint_value(self, link: str, angle: float) -> tuple:
        """(joint name, joint value) that gives ``link`` the absolute angle ``angle`` [rad]: the
        link must turn about the plane's normal on a joint to the ground."""
        name, sign = self.pivot(link)
        theta0 = self(self.mech.neutral())[link]
        value = sign * _wrap(angle - theta0)
        return name, value
