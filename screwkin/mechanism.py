"""Loading a mechanism file into a :class:`Mechanism`.

A Mechanism is the Pinocchio model of the spanning tree (built by Pinocchio's
URDF parser), the cut joints bound to frames of that model, the actuated
joints, and the map between joint names and coordinates.  Analyses (assembly,
mobility, and later position, velocity and singularity analysis) work on it.
"""

from __future__ import annotations

import os
import sys
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from .closure import Assembly, ClosureSystem, CutJoint
from .description import LIMITS, MechanismSpec, placement, resolve_actuation
from .errors import AssemblyError, MechanismFileError, UsageError, quote, shorten
from .linalg import null_space, rank
from .tolerances import DEFAULT, Tolerances
from .urdf import check_sizes, read_urdf, read_yaml_sidecar
from .xmlsafe import parse_xml_text, read_regular_file

__all__ = ["load", "Mechanism", "Coordinate", "characteristic_length", "frame_id"]


@dataclass(frozen=True)
class Coordinate:
    """Where a tree joint's coordinates live in q (nq entries) and in velocities (nv)."""

    joint: str
    joint_id: int
    idx_q: int
    nq: int
    idx_v: int
    nv: int


def _read_text(path: Path) -> str:
    """The text of a mechanism file: a regular file of at most ``LIMITS.file_bytes``, in UTF-8."""
    raw = read_regular_file(path, LIMITS.file_bytes, "mechanism file")
    if not raw.strip():
        raise MechanismFileError(path, "the file is empty")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise MechanismFileError(path, "not a text file (not UTF-8)") from None


def _find_sidecar(path: Path):
    """``FILE.yaml`` or ``FILE.yml`` beside the file, if there is one (whatever it is:
    a pipe or a directory of that name is then refused when read, not skipped)."""
    for suffix in (".yaml", ".yml"):
        cand = path.with_suffix(suffix)
        try:
            if cand.exists():
                return cand
        except (OSError, ValueError):
            continue
    return None


#: Frame types in the order a bare name is taken when several frames share it (a URDF
#: may name a joint like a link: Pinocchio then has a JOINT and a BODY frame of that name).
FRAME_PREFERENCE = (pin.FrameType.BODY, pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT, pin.FrameType.OP_FRAME,
                    pin.FrameType.SENSOR)


def frame_id(model, name: str, prefer=FRAME_PREFERENCE):
    """Id of the frame named ``name`` (None when there is none).  When several frames
    share the name, the first of the types in ``prefer`` wins -- by default the BODY
    frame (the link), where ``model.getFrameId(name)`` raises "Several frames match"."""
    matches = [k for k, f in enumerate(model.frames) if f.name == name]
    if not matches:
        return None
    if len(matches) > 1:
        for t in prefer:
            for k in matches:
                if model.frames[k].type == t:
                    return k
    return matches[0]


def _frame_bodies(model) -> dict:
    """Frame name -> the Pinocchio joint carrying it (of the preferred frame when several share the name)."""
    rank = {t: k for k, t in enumerate(FRAME_PREFERENCE)}
    best = {}
    for f in model.frames:
        r = rank.get(f.type, len(rank))
        if f.name not in best or r < best[f.name][0]:
            best[f.name] = (r, f.parentJoint)
    return {name: joint for name, (_, joint) in best.items()}


#: Most warnings printed for one file (the rest are counted).
MAX_WARNINGS = 20


def _check_cut_bodies(model, spec) -> None:
    """Refuse a cut joint whose two frames are on the same rigid body (fixed together):
    it closes no loop."""
    for c in spec.cut_joints:
        f1, f2 = frame_id(model, c.frame1), frame_id(model, c.frame2)
        if f1 is None or f2 is None:
            continue  # reported when the cut is bound
        if model.frames[f1].parentJoint == model.frames[f2].parentJoint:
            yaml = c.source == "yaml" and spec.yaml_path
            what = "closed_loop pair" if yaml else f"loop joint {quote(c.name)}"
            raise MechanismFileError(spec.yaml_path if yaml else spec.path,
                                     f"{what} connects {quote(c.frame1)} and {quote(c.frame2)}, which are fixed "
                                     "together (on the same body): it closes no loop")


def _axis_letters(t: str):
    unit = {"X": (1.0, 0, 0), "Y": (0, 1.0, 0), "Z": (0, 0, 1.0)}
    letters = t.split("_", 1)[1] if "_" in t else "XY"
    if len(letters) != 2 or any(c not in unit for c in letters):
        letters = "XY"
    return np.array(unit[letters[0]]), np.array(unit[letters[1]])


_UNBOUNDED = {"JointModelRUBX": pin.JointModelRX, "JointModelRUBY": pin.JointModelRY,
              "JointModelRUBZ": pin.JointModelRZ}


def _revolute_for(jm):
    """The one-coordinate revolute joint model about the axis of an unbounded (continuous)
    revolute joint model, or None for other joint models."""
    short = jm.shortname()
    if short in _UNBOUNDED:
        return _UNBOUNDED[short]()
    if short == "JointModelRevoluteUnboundedUnaligned":  # its axis: the angular part of its motion subspace
        jd = jm.createData()
        jm.calc(jd, np.array([1.0, 0.0]))
        return pin.JointModelRevoluteUnaligned(np.asarray(jd.S, float).ravel()[3:6].copy())
    return None


def _order(model, first=()):
    """The model's joints in a depth-first order with, among siblings, the subtrees that hold a
    joint of ``first`` before the others: Pinocchio needs a mimicked joint before its mimics."""
    children = {j: [] for j in range(model.njoints)}
    for j in range(1, model.njoints):
        children[model.parents[j]].append(j)
    first = set(first)
    holds = {j: model.names[j] in first for j in range(model.njoints)}
    for j in range(model.njoints - 1, 0, -1):  # children come after their parents in Pinocchio's order
        if holds[j]:
            holds[model.parents[j]] = True
    order, stack = [], [0]
    while stack:
        j = stack.pop()
        if j:
            order.append(j)
        kids = sorted(children[j], key=lambda c: (not holds[c], c))
        stack.extend(reversed(kids))
    return order


def _rebuild(model, replacements=(), first=()):
    """The model with continuous joints as revolute joints without limits (one coordinate, the
    angle, which counts turns: Pinocchio's (cos, sin) pair cannot, and a gear train or a lead
    screw turned twice must move twice as far), the sidecar's joint replacements (SPHERICAL,
    UJOINT_ab / CARDAN_ab as a native universal joint, FIXED as locked), and the joints named in
    ``first`` (mimicked ones) ordered before their mimics.  The limits of the other
    one-coordinate joints are kept."""
    rep = dict(replacements)
    order = _order(model, first)
    if not rep and order == list(range(1, model.njoints)) and not any(
            _revolute_for(model.joints[j]) is not None for j in range(1, model.njoints)):
        return model
    new = pin.Model()
    new.name = model.name
    locked = []
    inf = np.inf
    for jid in order:
        name = model.names[jid]
        parent = new.getJointId(model.names[model.parents[jid]]) if model.parents[jid] else 0
        jm = model.joints[jid]
        t = rep.get(name)
        lo = hi = None
        if t == "SPHERICAL":
            jm = pin.JointModelSpherical()
        elif t and t.startswith(("UJOINT", "CARDAN")):
            a1, a2 = _axis_letters(t)
            jm = pin.JointModelUniversal(a1, a2)
        elif _revolute_for(jm) is not None:
            jm, lo, hi = _revolute_for(jm), -inf, inf
        elif model.nqs[jid] == 1:
            lo, hi = model.lowerPositionLimit[model.idx_qs[jid]], model.upperPositionLimit[model.idx_qs[jid]]
        if lo is not None:
            i = model.idx_vs[jid]
            nid = new.addJoint(parent, jm, model.jointPlacements[jid], name, model.effortLimit[i:i + 1],
                               model.velocityLimit[i:i + 1], np.array([lo]), np.array([hi]))
        else:
            nid = new.addJoint(parent, jm, model.jointPlacements[jid], name)
        new.appendBodyToJoint(nid, model.inertias[jid], pin.SE3.Identity())
        if t == "FIXED":
            locked.append(nid)
    for f in list(model.frames)[1:]:
        parent = new.getJointId(model.names[f.parentJoint]) if f.parentJoint else 0
        new.addFrame(pin.Frame(f.name, parent, f.parentFrame, f.placement, f.type), False)
    if locked:
        new = pin.buildReducedModel(new, locked, pin.neutral(new))
    return new


def _couple(model, couplings, path):
    """The model with each coupled joint turned into a Pinocchio mimic joint (no coordinate of
    its own; its motion is m times its primary's plus o)."""
    for c in couplings:
        if not (model.existJointName(c.joint) and model.existJointName(c.mimics)):
            raise MechanismFileError(path, f"joint {quote(c.joint)} mimics {quote(c.mimics)}, which the model "
                                           "does not have as a moving joint (a sidecar replaced it?)")
        a, b = model.getJointId(c.mimics), model.getJointId(c.joint)
        if a > b:  # the primary lies below its mimic in the tree: no order puts it first
            raise MechanismFileError(path, f"joint {quote(c.joint)} mimics {quote(c.mimics)}, a joint further from "
                                           "the ground on its own branch: Pinocchio cannot couple them that way round")
        if model.nvs[a] != 1 or model.nvs[b] != 1:
            raise MechanismFileError(path, f"joint {quote(c.joint)} mimics {quote(c.mimics)}: both must be "
                                           "one-coordinate joints in the model")
        try:
            model = pin.transformJointIntoMimic(model, a, b, c.multiplier, c.offset)
        except (ValueError, RuntimeError) as exc:
            raise MechanismFileError(path, f"Pinocchio cannot make joint {quote(c.joint)} mimic "
                                           f"{quote(c.mimics)}: {shorten(str(exc).splitlines()[-1], 100)}") from None
    return model


def link_lengths(model, cuts) -> list:
    """The length of each rigid body of the model that has one: the largest distance between
    two joint centres on it (the origin of the joint that carries it, the origins of the
    joints it carries, and the frames of the cut joints on it), as written in the file --
    the same whatever the configuration.  Bodies whose joints all sit at one point (the
    massless links inside compound joints) have none."""
    points = {j: [] for j in range(model.njoints)}
    for j in range(1, model.njoints):
        points[j].append(np.zeros(3))
        points[model.parents[j]].append(np.array(model.jointPlacements[j].translation))
    for c in cuts:
        for f in (c.frame1, c.frame2):
            fr = model.frames[f]
            points[fr.parentJoint].append(np.array(fr.placement.translation))
    lengths = []
    for pts in points.values():
        if len(pts) < 2:
            continue
        P = np.array(pts[:200])  # a body carrying more joints than that: its first 200 decide
        d = float(np.sqrt(np.max(np.sum((P[:, None, :] - P[None, :, :]) ** 2, axis=2))))
        if d > 1e-9:
            lengths.append(d)
    return lengths


def characteristic_length(model, cuts) -> float:
    """The characteristic length L of a mechanism [m]: the mean length of its links
    (:func:`link_lengths`), 1 m when no link has a length.  Every measure that mixes
    translations and rotations divides translations by L (and multiplies the rates of
    sliding joints by it), so it is dimensionless and the same in every command."""
    lengths = link_lengths(model, cuts)
    return float(np.mean(lengths)) if lengths else 1.0


class Mechanism:
    """A mechanism: Pinocchio model of the spanning tree, cut joints, actuation.

    Attributes
    ----------
    path:       the file it was read from.
    spec:       the :class:`~screwkin.description.MechanismSpec` read from the file.
    model:      ``pinocchio.Model`` of the spanning tree (with frames F1, F2 of every cut joint).
    cuts:       list of :class:`~screwkin.closure.CutJoint`.
    closure:    the :class:`~screwkin.closure.ClosureSystem` r(q) = 0.
    coordinates: list of :class:`Coordinate`, one per tree joint with coordinates.
    actuated:   actuated joint names; ``actuation_source`` says where they came from.
    """

    def __init__(self, spec: MechanismSpec, model, actuated=None, tolerances: Tolerances = DEFAULT):
        self.spec = spec
        self.path = spec.path
        self.tolerances = tolerances
        self.model = model
        self.coordinates = [
            Coordinate(model.names[j], j, model.idx_qs[j], model.nqs[j], model.idx_vs[j], model.nvs[j])
            for j in range(1, model.njoints)
            if model.nvs[j] > 0
        ]
        self._coord = {c.joint: c for c in self.coordinates}
        self.couplings = tuple(spec.couplings)  # <mimic> joints: no coordinate of their own
        self._coupled = {c.joint: c for c in self.couplings}
        self.cuts = [self._bind_cut(c) for c in spec.cut_joints]
        # a ground frame for targets (inverse kinematics); every frame must exist
        # before the pinocchio.Data is made from the model
        self.target_frame = model.addFrame(
            pin.Frame("screwkin@target", 0, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME), False)
        # ONE Data for every analysis of this mechanism: Pinocchio 4.1 allocates nv^3-sized
        # tensors in it (one Data of a 500-joint chain: 17 s and 7.9 GB here).  Whoever uses it
        # runs Pinocchio's pass for its own configuration first.
        self.data = model.createData()
        self.closure = ClosureSystem(model, self.cuts, tolerances, self.path, data=self.data)
        self.set_actuated(actuated)
        self._assembly = None
        self._limits = None
        self._generic = None
        self._length = None
        self._rule_length = characteristic_length(model, self.cuts)
        self._translational = self._translational_coordinates()

    # ------------------------------------------------------------------ binding
    def _frame_id(self, name: str, what: str) -> int:
        fid = frame_id(self.model, name)
        if fid is None:
            raise MechanismFileError(self.path, f"{what} names frame {quote(name)}, which is not in the model")
        return fid

    def _bind_cut(self, c) -> CutJoint:
        ids = []
        for k, (frame, xyz, rpy) in enumerate(((c.frame1, c.xyz1, c.rpy1), (c.frame2, c.xyz2, c.rpy2)), 1):
            fid = self._frame_id(frame, f"loop joint '{c.name}'")
            parent = self.model.frames[fid]
            frame_placement = parent.placement * placement(xyz, rpy)
            new = pin.Frame(f"{c.name}@F{k}", parent.parentJoint, fid, frame_placement, pin.FrameType.OP_FRAME)
            ids.append(self.model.addFrame(new, False))
        return CutJoint(c.name, c.type, c.dof, ids[0], ids[1], c.frame1, c.frame2, tuple(c.axis),
                        tuple(c.axis2) if c.axis2 is not None else None)

    def set_actuated(self, actuated=None):
        """Choose the actuated joints (None: the file's declaration)."""
        names, source = resolve_actuation(self.spec, actuated)
        unknown = [n for n in names if n not in self._coord]
        if unknown and unknown[0] in self._coupled:
            c = self._coupled[unknown[0]]
            msg = (f"actuated joint {quote(unknown[0])} mimics {quote(c.mimics)}: it moves with it and cannot be "
                   "an input of its own")
            raise (UsageError(f"{self.path}: {msg}") if source == "command line" else MechanismFileError(self.path, msg))
        if unknown:
            known = ", ".join(c.joint for c in self.coordinates)
            msg = f"actuated joint '{unknown[0]}' is not a moving joint of the mechanism (joints: {known})"
            if source == "command line":
                raise UsageError(f"{self.path}: {msg}")
            raise MechanismFileError(self.path, msg)
        if len(set(names)) != len(names):
            raise UsageError(f"{self.path}: an actuated joint is named twice: {', '.join(names)}")
        self.actuated = names
        self.actuation_source = source

    # ------------------------------------------------------------------ coordinates
    @property
    def nq(self) -> int:
        return self.model.nq

    @property
    def nv(self) -> int:
        return self.model.nv

    def coordinate(self, joint: str) -> Coordinate:
        try:
            return self._coord[joint]
        except KeyError:
            if joint in self._coupled:
                c = self._coupled[joint]
                raise UsageError(f"{self.path}: joint {quote(joint)} mimics {quote(c.mimics)} ({joint} = "
                                 f"{c.multiplier:g} {c.mimics} + {c.offset:g}): it has no value of its own; "
                                 f"give {quote(c.mimics)}") from None
            known = ", ".join(c.joint for c in self.coordinates)
            raise UsageError(f"{self.path}: no moving joint named '{joint}' (joints: {known})") from None

    def velocity_indices(self, joints) -> np.ndarray:
        """Velocity (tangent) indices of the named joints, in order."""
        idx = []
        for j in joints:
            c = self.coordinate(j)
            idx.extend(range(c.idx_v, c.idx_v + c.nv))
        return np.asarray(idx, int)

    def _value_layout(self):
        """(1-coordinate joints (name, q index, wrap), continuous joints (name, q index), the
        coordinates of multi-DOF joints (name, q index), order of the names)."""
        if getattr(self, "_layout", None) is None:
            single, continuous, multi, order = [], [], [], []
            for c in self.coordinates:
                short = self.model.joints[c.joint_id].shortname()
                if c.nq == 1:
                    single.append((c.joint, c.idx_q, short.startswith("JointModelR")))
                    order.append(c.joint)
                elif c.nq == 2 and c.nv == 1:
                    continuous.append((c.joint, c.idx_q))
                    order.append(c.joint)
                else:
                    names = [(f"{c.joint}[q{k}]", c.idx_q + k) for k in range(c.nq)]
                    multi += names
                    order += [n for n, _ in names]
            idx = np.array([i for _, i, _ in single], int)
            wrap = np.array([w for _, _, w in single], bool)
            self._angle_v = np.array([self.coordinate(n).idx_v for n, _, w in single if w], int)
            self._layout = (single, continuous, multi, order, idx, wrap)
        return self._layout

    def coupled_values(self, q) -> dict:
        """The value of every coupled (<mimic>) joint: multiplier * its primary's + offset
        [rad or m]; angles in [-pi, pi)."""
        out = {}
        for c in self.couplings:
            p = self.coordinate(c.mimics)
            v = c.multiplier * float(q[p.idx_q]) + c.offset
            if self._revolute_like(c.joint):
                v = float(np.mod(v + np.pi, 2 * np.pi) - np.pi)
            out[c.joint] = v
        return out

    def _revolute_like(self, joint: str) -> bool:
        return next((j.type for j in self.spec.joints if j.name == joint), "") in ("revolute", "continuous")

    def difference(self, q0, q1) -> np.ndarray:
        """The velocity-space step from q0 to q1 (pinocchio.difference), with the angles of
        bounded revolute joints taken the short way round (-pi, pi]."""
        d = pin.difference(self.model, q0, q1)
        _, _, _, _, idx, wrap = self._value_layout()
        if wrap.any():
            v = self._angle_v
            d[v] = np.mod(d[v] + np.pi, 2 * np.pi) - np.pi
        return d

    def joint_values(self, q) -> dict:
        """Every joint coordinate name -> value [rad or m], in the order of the joints:
        revolute angles in [-pi, pi), continuous joints as atan2(sin, cos), the coordinates
        of multi-DOF joints as ``joint[qk]``."""
        q = np.asarray(q, float)
        single, continuous, multi, order, idx, wrap = self._value_layout()
        v = q[idx]
        v[wrap] = np.mod(v[wrap] + np.pi, 2 * np.pi) - np.pi
        out = dict(zip((n for n, _, _ in single), v.tolist()))
        for name, i in continuous:
            out[name] = float(np.arctan2(q[i + 1], q[i]))
        for name, i in multi:
            out[name] = float(q[i])
        return {n: out[n] for n in order}

    @property
    def coordinate_names(self) -> list:
        names = []
        for c in self.coordinates:
            names += [c.joint] if c.nv == 1 else [f"{c.joint}[{k}]" for k in range(c.nv)]
        return names

    def limited_coordinates(self):
        """(names, q indices, lower, upper, is an angle) of the one-coordinate joints with a
        finite <limit> range, as arrays (for checking many configurations quickly)."""
        if self._limits is None:
            model, rows = self.model, []
            for c in self.coordinates:
                if c.nq != 1:
                    continue
                lo, hi = model.lowerPositionLimit[c.idx_q], model.upperPositionLimit[c.idx_q]
                if np.isfinite(lo) and np.isfinite(hi) and hi - lo > 0:
                    angle = model.joints[c.joint_id].shortname().startswith("JointModelR")
                    rows.append((c.joint, c.idx_q, lo, hi, angle))
            names = tuple(r[0] for r in rows)
            self._limits = (names,) + tuple(np.array([r[k] for r in rows]) for k in range(1, 5))
        return self._limits

    def link_frame(self, link: str) -> int:
        """Frame id of a link (its body frame)."""
        for fid, f in enumerate(self.model.frames):
            if f.name == link and f.type == pin.FrameType.BODY:
                return fid
        links = ", ".join(self.spec.links)
        raise UsageError(f"{self.path}: no link named '{link}' (links: {links})")

    def neutral(self) -> np.ndarray:
        """The configuration written in the file (every joint at zero)."""
        return pin.neutral(self.model)

    # ------------------------------------------------------------------ length
    @property
    def length(self) -> float:
        """The characteristic length L [m] that makes mixed translation/rotation measures
        dimensionless: the mean link length (:func:`characteristic_length`) unless set."""
        return self._length if self._length is not None else self._rule_length

    @length.setter
    def length(self, value):
        if value is not None and not (np.isfinite(value) and value > 0):
            raise UsageError(f"{self.path}: the characteristic length must be a positive length, got {value!r}")
        self._length = None if value is None else float(value)

    @property
    def length_rule(self) -> str:
        """How :attr:`length` was chosen, in words."""
        if self._length is not None:
            return "given"
        return "mean link length" if link_lengths(self.model, self.cuts) else "no link has a length: 1 m"

    def _translational_coordinates(self) -> np.ndarray:
        """Mask of the velocity coordinates that are lengths (prismatic joints, the translations
        of planar, translation and free-flyer joints)."""
        mask = np.zeros(self.model.nv, bool)
        for c in self.coordinates:
            short = self.model.joints[c.joint_id].shortname()
            if "JointModelP" in short and "Planar" not in short:
                mask[c.idx_v:c.idx_v + c.nv] = True
            elif short in ("JointModelPlanar",):
                mask[c.idx_v:c.idx_v + 2] = True
            elif short in ("JointModelTranslation", "JointModelFreeFlyer"):
                mask[c.idx_v:c.idx_v + 3] = True
        return mask

    @property
    def translational(self) -> np.ndarray:
        """Mask (nv,) of the velocity coordinates that are lengths [m]; the others are angles."""
        return self._translational

    # ------------------------------------------------------------------ configurations
    def random_configuration(self, rng, around=None, spread: float = 0.3) -> np.ndarray:
        """A random configuration.

        Without ``around``: every joint uniform within its limits -- angles over their
        <limit> range when it is finite and at most a turn, else over a full turn; lengths
        over their range when finite and at most 100 L, else over [-L, L] (L = :attr:`length`);
        ball and free joints uniform over the rotations.  With ``around``: that configuration
        moved by a normal random step of ``spread`` rad (``spread * L`` for lengths)."""
        model = self.model
        if around is not None:
            dq = rng.normal(size=model.nv) * spread
            dq[self._translational] *= self.length
            return pin.integrate(model, np.asarray(around, float), dq)
        L = self.length
        q = pin.neutral(model)
        lo_all, hi_all = model.lowerPositionLimit, model.upperPositionLimit
        for c in self.coordinates:
            short = model.joints[c.joint_id].shortname()
            i = c.idx_q
            if c.nq == 1:
                lo, hi = float(lo_all[i]), float(hi_all[i])  # Python floats: no overflow warning at +-1.8e308
                length = bool(self._translational[c.idx_v])
                wide = 100 * L if length else 2 * np.pi
                if np.isfinite(lo) and np.isfinite(hi) and 0 < hi - lo <= wide:
                    q[i] = rng.uniform(lo, hi)
                elif length:
                    q[i] = rng.uniform(max(lo, -L), min(hi, L)) if max(lo, -L) < min(hi, L) else rng.uniform(-L, L)
                else:
                    q[i] = rng.uniform(-np.pi, np.pi)
            elif c.nq == 2 and c.nv == 1:  # continuous: (cos, sin)
                a = rng.uniform(-np.pi, np.pi)
                q[i:i + 2] = (np.cos(a), np.sin(a))
            elif short == "JointModelSpherical":
                v = rng.normal(size=4)
                q[i:i + 4] = v / np.linalg.norm(v)
            elif short == "JointModelFreeFlyer":
                q[i:i + 3] = rng.uniform(-L, L, 3)
                v = rng.normal(size=4)
                q[i + 3:i + 7] = v / np.linalg.norm(v)
            elif short == "JointModelPlanar":
                a = rng.uniform(-np.pi, np.pi)
                q[i:i + 4] = (*rng.uniform(-L, L, 2), np.cos(a), np.sin(a))
            elif short == "JointModelTranslation":
                q[i:i + 3] = rng.uniform(-L, L, 3)
            else:  # universal, spherical ZYX, ...: angles over a full turn
                dq = np.zeros(model.nv)
                dq[c.idx_v:c.idx_v + c.nv] = rng.uniform(-np.pi, np.pi, c.nv)
                q[i:i + c.nq] = pin.integrate(model, pin.neutral(model), dq)[i:i + c.nq]
        return q

    def _keep(self, q, hint, frozen):
        """q with the coordinates of the joints whose velocity indices are frozen taken from hint."""
        if not len(frozen):
            return q
        frozen = set(int(f) for f in frozen)
        q = np.array(q, float)
        for c in self.coordinates:
            if any(c.idx_v + k in frozen for k in range(c.nv)):
                q[c.idx_q:c.idx_q + c.nq] = hint[c.idx_q:c.idx_q + c.nq]
        return q

    # ------------------------------------------------------------------ analyses
    def assemble(self, q0=None, frozen=(), seed: int = 0) -> Assembly:
        """Close the loops: a seeded search, not a single descent.

        The hint ``q0`` (default: the file's configuration, every joint at zero) is tried
        first; when damped Newton does not close the loops from it (a file drawn with every
        link along one line has a residual whose gradient vanishes there), perturbations of
        it and then random configurations within the joint limits are tried, in a fixed
        order (``seed``), and the first that closes is returned: ``Assembly.start`` says
        which.  ``frozen`` velocity indices (inputs) keep the hint's values in every start.
        Raises AssemblyError with the smallest residual reached and the number of starts."""
        cache = q0 is None and not len(frozen)
        if cache and self._assembly is not None:
            return self._assembly
        tol = self.tolerances
        hint = self.neutral() if q0 is None else np.array(q0, float)
        given = "the file's configuration" if q0 is None else "the given configuration"
        rng = np.random.default_rng(seed)
        total = max(int(tol.assembly_starts), 1) if self.closure.nrows else 1
        best, best_it = np.inf, 0
        for k in range(total):
            if k == 0:
                q, what = hint, given
            elif k <= tol.perturbations:
                q = self.random_configuration(rng, around=hint, spread=0.1 * k)
                what = f"a perturbation of {given} (start {k + 1} of {total})"
            else:
                q = self.random_configuration(rng)
                what = f"a random configuration within the joint limits (start {k + 1} of {total})"
            q = self._keep(q, hint, frozen) if k else q
            try:
                a = self.closure.solve(q, frozen=frozen)
            except AssemblyError as exc:
                if exc.residual < best:
                    best, best_it = exc.residual, exc.iterations
                continue
            result = Assembly(a.q, a.residual, a.iterations, what, k + 1)
            if cache:
                self._assembly = result
            return result
        starts = (f"{given}, {min(tol.perturbations, total - 1)} perturbations of it and "
                  f"{max(total - 1 - tol.perturbations, 0)} random configurations within the joint limits"
                  if total > 1 else given)
        raise AssemblyError(self.path, best, best_it, detail=starts, starts=total)

    def generic_configurations(self, hint=None, seed: int = 0) -> tuple:
        """(assembly, configurations): assembled configurations where generic ranks are taken.

        The first configuration the assembly search closes (:meth:`assemble`, from ``hint``
        when given) may be singular -- a file drawn straight, at a limit position, or on a
        degenerate branch where links fold onto each other.  So the rank of the constraint
        Jacobian is taken at it, at ``tolerances.samples`` nearby ones (a random step of
        ``sample_step`` along the motion the loops allow, closed again) and at the
        configurations that ``tolerances.generic_starts`` further random starts close; the
        configurations of the largest rank are returned, the one nearest the first assembly
        first (``assembly`` is that first one, with where it came from).  Cached."""
        if self._generic is None:
            a = self.assemble() if hint is None else self.assemble(hint)
            tol, closure = self.tolerances, self.closure
            rng = np.random.default_rng(seed)
            configs = [a.q]
            if self.nv:  # a serial chain too: its file configuration may be singular for an output
                for _ in range(tol.samples):
                    V = null_space(closure.jacobian(a.q), tol, self.nv)
                    if V.shape[1] == 0:
                        break
                    step = V @ rng.normal(size=V.shape[1])
                    step *= tol.sample_step / max(np.linalg.norm(step), 1e-300)
                    try:
                        configs.append(closure.solve(pin.integrate(self.model, a.q, step)).q)
                    except AssemblyError:
                        continue
                for _ in range(tol.generic_starts if closure.nrows else 0):  # (for the branches of loops)
                    try:
                        configs.append(closure.solve(self.random_configuration(rng)).q)
                    except AssemblyError:
                        continue
            ranks = [rank(closure.jacobian(q), tol) if closure.nrows else 0 for q in configs]
            top = max(ranks)
            self._generic = (a, tuple(q for q, r in zip(configs, ranks) if r == top), ranks[0] < top, ranks[0], top)
        return self._generic[:2]

    @property
    def first_assembly_singular(self):
        """(True, its rank, the generic rank) when the first configuration the assembly search
        closed is less constrained than the generic ones (singular or on a degenerate branch);
        (False, r, r) otherwise.  Needs generic_configurations() first."""
        if self._generic is None:
            self.generic_configurations()
        return self._generic[2:]

    def topology(self, q=None):
        """The :class:`~screwkin.topology.Topology` (links, joints, compound joints, loops)."""
        from .topology import build_topology

        return build_topology(self, self.assemble().q if q is None else q)

    def mobility(self, actuated=None, output=None, seed: int = 0, point: bool = False):
        """Mobility analysis; returns a :class:`~screwkin.mobility.MobilityResult`.
        point: analyse the output link's origin as a point (its 3 translations)."""
        from .mobility import analyze_mobility

        if actuated is not None:
            self.set_actuated(actuated)
        return analyze_mobility(self, output=output, seed=seed, point=point)

    def __repr__(self):
        return (f"Mechanism({Path(self.path).name!r}: {len(self.spec.links)} links, "
                f"{len(self.coordinates)} moving tree joints, {len(self.cuts)} cut joints)")


@contextmanager
def _native_stderr(box: list):
    """Collect into ``box`` what native code writes to file descriptor 2 while inside."""
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError):  # no usable stderr: nothing to keep quiet
        yield
        return
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            box.append(tmp.read(1 << 20).decode("utf-8", "replace"))  # the first MB says what went wrong


def _urdfdom_messages(box: list) -> list:
    """(level, message) of console_bridge lines such as 'Error:   Joint [j] is ...' (the
    'at line N in file.cpp' lines that follow them are dropped)."""
    out = []
    for line in "".join(box).splitlines():
        level, sep, message = line.partition(":")
        if sep and level.strip() in ("Error", "Warning", "Info", "Debug") and message.strip():
            out.append((level.strip(), message.strip()))
    return out


def load(path, yaml=None, actuated=None, tolerances: Tolerances = DEFAULT, warn=None, package_dirs=None) -> Mechanism:
    """Read a mechanism file (URDF with ``<loop_joint>`` or a YAML sidecar, or SDF).

    yaml:      path of an Extended-URDF sidecar; default: ``<file>.yaml`` when it exists.
    actuated:  actuated joint names, overriding the file's declaration.
    warn:      callable receiving each warning (default: print to stderr).
    package_dirs: folders searched first for ``package://`` meshes (as ``ROS_PACKAGE_PATH``).

    The file is untrusted: see :mod:`screwkin.xmlsafe` and
    :class:`~screwkin.description.Limits` for what is refused before Pinocchio reads it.
    """
    path = Path(path)
    text = _read_text(path)
    root = parse_xml_text(text, path)  # the root element decides the format, not the suffix
    package_dirs = [str(d) for d in package_dirs or ()]
    for d in package_dirs:
        if not os.path.isdir(d):
            raise UsageError(f"package folder {quote(d)} (--package-dir) is not a folder")
    if root.tag == "sdf":
        from .sdf import read_sdf

        spec = read_sdf(path, text, root=root, package_dirs=package_dirs)
    elif root.tag == "robot" or path.suffix.lower() != ".sdf":
        spec = read_urdf(path, text, root=root, package_dirs=package_dirs)
    else:
        raise MechanismFileError(path, f"not an SDF file: the root element is <{shorten(root.tag, 40)}>, "
                                       "expected <sdf>")
    spec.package_dirs = package_dirs
    native = []  # what urdfdom (inside Pinocchio) prints on the process's stderr: kept out of the output
    try:
        with _native_stderr(native):
            model = pin.buildModelFromXML(spec.urdf_text)
    except (ValueError, RuntimeError) as exc:
        first = str(exc).strip().splitlines()[-1].strip() if str(exc).strip() else type(exc).__name__
        reasons = [m for level, m in _urdfdom_messages(native) if level == "Error"]
        if reasons:  # urdfdom's first complaint says more than Pinocchio's summary
            first = reasons[0]
        raise MechanismFileError(path, f"Pinocchio's URDF parser refused the file: {shorten(first, 120)}") from None
    spec.warnings.extend(f"URDF parser: {shorten(m, 120)}" for level, m in _urdfdom_messages(native)
                         if level != "Error")
    if yaml is None and spec.format == "urdf":
        yaml = _find_sidecar(path)
    if yaml is not None:
        read_yaml_sidecar(spec, Path(yaml), [f.name for f in model.frames], _frame_bodies(model))
    model = _rebuild(model, spec.replacements, first={c.mimics for c in spec.couplings})
    model = _couple(model, spec.couplings, path)
    check_sizes(spec.yaml_path or path, len(spec.links), len(spec.joints), len(spec.cut_joints), model.nv)
    _check_cut_bodies(model, spec)
    shown = spec.warnings
    if warn is None:  # on the terminal: a bounded number of bounded lines
        def warn(m):
            print(f"warning: {shorten(str(path), 200)}: {shorten(m, 400)}", file=sys.stderr)

        if len(shown) > MAX_WARNINGS:
            shown = shown[:MAX_WARNINGS] + [f"and {len(spec.warnings) - MAX_WARNINGS} more warnings"]
    for w in shown:
        warn(w)
    return Mechanism(spec, model, actuated=actuated, tolerances=tolerances)
