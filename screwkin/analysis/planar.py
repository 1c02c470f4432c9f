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
configuration is on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import UsageError
from .batch import TreeKinematics, Unbatchable

__all__ = ["LinkageInfo", "identify", "transmission_angles", "LinkAngles", "plane_basis"]


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

    def construction(self) -> dict:
        """JSON-ready: four-bar {transmission_angle, diagonal, alpha, beta}; slider-crank {transmission_angle}."""
        d = {"kind": self.kind, "transmission_angle": self.transmission_angle}
        if self.diagonal is not None:
            d.update(diagonal=self.diagonal, alpha=self.alpha, beta=self.beta)
        return d


def _rot(v, ang):
    c, s = np.cos(ang), np.sin(ang)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _cross(u, v):
    return u[0] * v[1] - u[1] * v[0]


def _angle(v):
    return float(np.arctan2(v[1], v[0]))


def _wrap(x):
    return float(np.mod(x + np.pi, 2 * np.pi) - np.pi)


def _interval(start, end, phi_now, q_in):
    """Joint values of the angle interval [start, end] (end > start) that contains phi_now."""
    k = np.floor((phi_now - start) / (2 * np.pi))
    start, end = start + 2 * np.pi * k, end + 2 * np.pi * k
    return (q_in + start - phi_now, q_in + end - phi_now)


def _circles(p, r, c, s):
    """Intersections of circle (p, r) and circle (c, s) in the plane."""
    d = np.linalg.norm(c - p)
    if d < 1e-15 or d > r + s + 1e-12 or d < abs(r - s) - 1e-12:
        return []
    along = (r * r - s * s + d * d) / (2 * d)
    h = np.sqrt(max(r * r - along * along, 0.0))
    u = (c - p) / d
    n = np.array([-u[1], u[0]])
    return [p + along * u + h * n, p + along * u - h * n]


def _roles(topo, input_joint):
    """(plane normal n, input joint, crank-coupler joint j_b, coupler-output joint j_c, output-ground
    joint j_d) of a planar four-bar or slider-crank driven from a ground joint, else None."""
    if topo.motion_space != "planar" or (topo.n_links, topo.n_joints, topo.loops) != (4, 4, 1):
        return None
    joints = {j.name: j for j in topo.joints}
    inp = joints.get(input_joint)
    ground = topo.ground
    if inp is None or ground not in inp.links or inp.type not in ("revolute", "continuous"):
        return None
    n = np.asarray(inp.direction) / np.linalg.norm(inp.direction)

    def other(link, joint):
        return next(j for j in topo.joints if j is not joint and link in j.links)

    moving = inp.links[1] if inp.links[0] == ground else inp.links[0]
    j_b = other(moving, inp)
    coupler = j_b.links[1] if j_b.links[0] == moving else j_b.links[0]
    return n, inp, j_b, other(coupler, j_b), other(ground, inp)


def _in_plane(n):
    """p2: world vectors -> plane coordinates (e1, e2), (e1, e2, n) right-handed: positive joint
    rotation is counterclockwise."""
    h = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = np.cross(n, h)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    return lambda v: np.asarray(v) @ np.stack([e1, e2], axis=-1)


def identify(mech, topo, q, input_joint):
    """A :class:`LinkageInfo` for a planar four-bar or slider-crank whose input
    joint is a ground joint, at the configuration ``topo`` was built at (q)."""
    roles = _roles(topo, input_joint)
    if roles is None:
        return None
    n, inp, j_b, j_c, j_d = roles
    p2 = _in_plane(n)
    coord = mech.coordinate(input_joint)
    q_in = float(np.arctan2(q[coord.idx_q + 1], q[coord.idx_q])) if coord.nq == 2 else float(q[coord.idx_q])
    A, B, C = p2(inp.point), p2(j_b.point), p2(j_c.point)
    a, b = np.linalg.norm(B - A), np.linalg.norm(C - B)
    if j_d.type in ("revolute", "continuous") and j_c.type in ("revolute", "continuous") \
            and j_b.type in ("revolute", "continuous"):
        return _four_bar(input_joint, q_in, A, B, C, p2(j_d.point), a, b)
    if j_d.type == "prismatic" or j_c.type == "prismatic":
        slide = j_d if j_d.type == "prismatic" else j_c
        pin_joint = j_c if slide is j_d else j_d
        if slide is j_c:  # the prismatic joint is between rod and slider: not the textbook slider-crank
            return None
        s = p2(np.asarray(slide.direction) + 0) - p2(np.zeros(3))
        return _slider_crank(input_joint, q_in, A, B, p2(pin_joint.point), s / np.linalg.norm(s), a, b)
    return None


def transmission_angles(mech, topo, Q, input_joint):
    """identify(mech, topology at q, q, input_joint).transmission_angle for every row of Q, at once
    (the joints' points from one batched forward-kinematics pass); None where ``identify`` gives
    None at Q's first configuration (``topo``'s) or for compound joints."""
    info = identify(mech, topo, Q[0], input_joint)
    roles = _roles(topo, input_joint)
    if info is None or any(len(j.members) != 1 for j in roles[1:]):
        return None
    n, inp, j_b, j_c, j_d = roles
    model = mech.model
    cuts = {c.name: c for c in mech.cuts}
    frames = []
    for j in (j_b, j_c, j_d):
        name = j.members[0]
        frames.append(cuts[name].frame1 if name in cuts else model.getFrameId(name, pin.FrameType.JOINT))
    try:
        placed = TreeKinematics(mech).frames(Q, frames, jacobian=False)
        pts = [placed[f][1] for f in frames]
    except Unbatchable:
        data = mech.data
        pts = [np.empty((len(Q), 3)) for _ in frames]
        for k, q in enumerate(Q):
            pin.framesForwardKinematics(model, data, q)
            for p, f in zip(pts, frames):
                p[k] = data.oMf[f].translation
    p2 = _in_plane(n)
    B, C, D = (p2(p) for p in pts)
    b = np.linalg.norm(C - B, axis=1)
    if info.kind == "four-bar":
        c = np.linalg.norm(D - C, axis=1)
        return np.arccos(np.clip(np.einsum("ij,ij->i", B - C, D - C) / (b * c), -1, 1))
    s = p2(np.asarray(j_d.direction) + 0) - p2(np.zeros(3))
    s = s / np.linalg.norm(s)
    nrm = np.array([-s[1], s[0]])
    return np.arccos(np.clip(np.abs((C - B) / b[:, None] @ nrm), 0, 1))


def _four_bar(name, q_in, A, B, C, D, a, b):
    g, c = np.linalg.norm(D - A), np.linalg.norm(D - C)
    lengths = {"ground": g, "input": a, "coupler": b, "output": c}
    s, l = min(lengths.values()), max(lengths.values())
    p_q = g + a + b + c - s - l
    if abs(s + l - p_q) < 1e-9 * l:
        cls = "change point (s + l = p + q): the linkage can fold flat"
    elif s + l > p_q:
        cls = "non-Grashof (triple rocker): no link turns fully"
    else:
        shortest = min((a, 1, "input"), (g, 0, "ground"), (b, 2, "coupler"), (c, 3, "output"))[2]
        cls = {"input": "Grashof crank-rocker: the input turns fully",
               "ground": "Grashof double crank (drag link): input and output turn fully",
               "coupler": "Grashof double rocker: only the coupler turns fully",
               "output": "Grashof rocker-crank: the output turns fully, the input rocks"}[shortest]
    u_ad = (D - A) / g
    phi_now = _angle(_rot(B - A, -_angle(u_ad)))  # input angle from AD
    circuit = np.sign(_cross(C - B, D - C)) or 1.0

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
        for Cc in _circles(A, dist, D, c):
            u = (Cc - A) / max(np.linalg.norm(Cc - A), 1e-300)
            Bc = A - a * u if folded and b > a else A + a * u
            if (np.sign(_cross(Cc - Bc, D - Cc)) or circuit) != circuit:
                continue
            limits.append(q_in + _wrap(_angle(_rot(Bc - A, -_angle(u_ad))) - phi_now))
    mu = float(np.arccos(np.clip(np.dot(B - C, D - C) / (b * c), -1, 1)))
    z = float(np.linalg.norm(B - D))
    alpha = beta = None
    if z > 0:  # (the diagonal vanishes when the crank tip sits on the output pivot)
        alpha = float(np.arccos(np.clip(np.dot(B - D, C - D) / (z * c), -1, 1)))
        beta = float(np.arccos(np.clip(np.dot(B - D, A - D) / (z * g), -1, 1)))
    return LinkageInfo("four-bar", lengths, cls, name, rng, tuple(sorted(limits)), mu, z, alpha, beta)


def _slider_crank(name, q_in, A, B, C, s, a, b):
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
        if dist < abs(e):
            continue
        x = side * np.sqrt(dist * dist - e * e)
        Cc = A + x * s + e * nrm
        u = (Cc - A) / np.linalg.norm(Cc - A)
        Bc = A + (-a if folded and b > a else a) * u
        limits.append(q_in + _wrap(_angle(np.array([(Bc - A) @ s, (Bc - A) @ nrm])) - phi_now))
    rod = (C - B) / b
    mu = float(np.arccos(np.clip(abs(rod @ nrm), 0, 1)))
    return LinkageInfo("slider-crank", lengths, cls, name, rng, tuple(sorted(limits)), mu)


def plane_basis(normal):
    """(e1, e2, n): e1 the world x axis projected into the plane (the world y axis when x is
    normal to it), e2 = n x e1, so angles from e1 are counterclockwise seen from +n."""
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    for axis in np.eye(3):
        e1 = axis - (axis @ n) * n
        if np.linalg.norm(e1) > 1e-6:
            e1 /= np.linalg.norm(e1)
            return e1, np.cross(n, e1), n
    raise ValueError("degenerate normal")  # pragma: no cover


class LinkAngles:
    """Absolute angles of the links of a planar mechanism: the theta_i of the vector-loop
    method, measured in the plane from the ground's x axis, counterclockwise about the
    plane's normal (the topology's normal: its +z side, else +y, else +x).

    Each link's vector goes from the centre of the joint that carries it (its joint
    towards the ground in the file's tree) to the centre of the first other joint on it:
    the first joint it carries in the file's order, else the first loop joint on it.  A
    link with no second joint centre (a slider whose pin sits on its own axis, a free
    tip) is measured by its frame's x axis.  The ground's vector goes from its first
    joint centre to its first other one."""

    def __init__(self, mech, topo):
        if topo.motion_space != "planar" or topo.normal is None:
            raise UsageError(f"{mech.path}: absolute link angles are for planar mechanisms; this one is "
                             f"{topo.motion_space}")
        self.mech = mech
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
                start, candidates = ("joint", starts[0]), [("joint", k) for k in starts[1:]]
            else:
                start = ("joint", jid)
                candidates = [("joint", k) for k in model.children[jid]]
            candidates += [("frame", f) for f in cut_frames.get(jid, [])]
            self.links[link] = (start, candidates, fid)
        self._data = mech.data
        ends = self._ends(mech.neutral())
        self.links = {k: (start, ends[k], fid) for k, (start, _, fid) in self.links.items()}

    def _point(self, ref):
        kind, i = ref
        d = self._data
        return d.oMi[i].translation if kind == "joint" else d.oMf[i].translation

    def _ends(self, q):
        """Choose each link's second point: the first candidate away from its first point."""
        pin.framesForwardKinematics(self.mech.model, self._data, q)
        out = {}
        tiny = 1e-9 * self.mech.length
        for link, (start, candidates, fid) in self.links.items():
            p0 = self._point(start)
            out[link] = next((c for c in candidates if np.linalg.norm(self._point(c) - p0) > tiny), ("axis", fid))
        return out

    def __call__(self, q) -> dict:
        """link name -> absolute angle [rad] in (-pi, pi]."""
        pin.framesForwardKinematics(self.mech.model, self._data, q)
        out = {}
        for link, (start, end, fid) in self.links.items():
            if end[0] == "axis":
                v = self._data.oMf[fid].rotation[:, 0]
            else:
                v = self._point(end) - self._point(start)
            out[link] = float(np.arctan2(v @ self.e2, v @ self.e1))
        return out

    def batch(self, Q) -> dict:
        """link name -> (N,) absolute angles [rad] at every row of Q: __call__ on the stack, from one
        batched forward-kinematics pass (a loop over Q where the tree has joints of two coordinates)."""
        Q = np.atleast_2d(Q)
        refs = {r for start, end, fid in self.links.values() for r in (start, end if end[0] != "axis" else ("frame", fid))}
        model = self.mech.model
        fids = {r: (r[1] if r[0] == "frame" else model.getFrameId(model.names[r[1]], pin.FrameType.JOINT)) for r in refs}
        try:
            placed = TreeKinematics(self.mech).frames(Q, sorted(set(fids.values())), jacobian=False)
        except Unbatchable:
            rows = [self(q) for q in Q]
            return {link: np.array([r[link] for r in rows]) for link in self.links}
        out = {}
        for link, (start, end, fid) in self.links.items():
            if end[0] == "axis":
                v = placed[fids[("frame", fid)]][0][:, :, 0]
            else:
                v = placed[fids[end]][1] - placed[fids[start]][1]
            out[link] = np.arctan2(v @ self.e2, v @ self.e1)
        first = self(Q[0])  # a link along -e1 (+-pi) could come out with the other sign: then the loop
        if any(abs(out[link][0] - first[link]) > 1e-9 for link in out):
            rows = [self(q) for q in Q]
            return {link: np.array([r[link] for r in rows]) for link in self.links}
        return out

    def joint_value(self, link: str, angle: float) -> tuple:
        """(joint name, joint value) that gives ``link`` the absolute angle ``angle`` [rad]: the
        link must turn about the plane's normal on a joint to the ground."""
        mech, model = self.mech, self.mech.model
        if link not in self.links:
            raise UsageError(f"{mech.path}: no moving link named '{link}' (links: {', '.join(self.links)})")
        start = self.links[link][0]
        jid = start[1]
        short = model.joints[jid].shortname()
        name = model.names[jid]
        if model.parents[jid] != 0 or not short.startswith("JointModelR") or mech.coordinate(name).nv != 1:
            raise UsageError(f"{mech.path}: the absolute angle of '{link}' is not the value of one joint (it does "
                             "not turn on a revolute joint to the ground): set a joint with --set")
        q = mech.neutral()
        axis = np.asarray(next(j.axis for j in mech.spec.joints if j.name == name), float)
        pin.framesForwardKinematics(model, self._data, q)
        sign = float(np.sign((self._data.oMi[jid].rotation @ axis) @ self.n))
        if sign == 0:
            raise UsageError(f"{mech.path}: joint '{name}' does not turn about the plane's normal")
        theta0 = self(q)[link]
        value = sign * float(np.mod(angle - theta0 + np.pi, 2 * np.pi) - np.pi)
        return name, value
