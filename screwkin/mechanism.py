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
from .errors import MechanismFileError, UsageError, quote, shorten
from .tolerances import DEFAULT, Tolerances
from .urdf import check_sizes, read_urdf, read_yaml_sidecar
from .xmlsafe import parse_xml_text, read_regular_file

__all__ = ["load", "Mechanism", "Coordinate", "frame_id"]


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


def _unambiguous_cut_frames(model, spec) -> None:
    """Give every cut-joint frame name that several Pinocchio frames share (a joint
    named like a link) an alias frame of its own on the preferred frame, and name the
    alias in the spec, so that binding by name finds exactly one frame."""
    counts = {}
    for f in model.frames:
        counts[f.name] = counts.get(f.name, 0) + 1
    for c in spec.cut_joints:
        for attr in ("frame1", "frame2"):
            name = getattr(c, attr)
            if counts.get(name, 0) < 2:
                continue
            alias = f"screwkin@{name}"
            if not model.existFrame(alias):
                fid = frame_id(model, name)
                parent = model.frames[fid]
                model.addFrame(pin.Frame(alias, parent.parentJoint, fid, parent.placement, pin.FrameType.OP_FRAME),
                               False)
            setattr(c, attr, alias)


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


def _replace_joints(model, replacements):
    """Rebuild ``model`` with the sidecar's joint replacements (SPHERICAL,
    UJOINT_ab / CARDAN as a native universal joint, FIXED as locked)."""
    rep = dict(replacements)
    new = pin.Model()
    new.name = model.name
    locked = []
    for jid in range(1, model.njoints):
        name = model.names[jid]
        parent = new.getJointId(model.names[model.parents[jid]]) if model.parents[jid] else 0
        jm = model.joints[jid]
        t = rep.get(name)
        if t == "SPHERICAL":
            jm = pin.JointModelSpherical()
        elif t and (t.startswith("UJOINT") or t == "CARDAN"):
            a1, a2 = _axis_letters(t)
            jm = pin.JointModelUniversal(a1, a2)
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
        self.data = model.createData()
        self.coordinates = [
            Coordinate(model.names[j], j, model.idx_qs[j], model.nqs[j], model.idx_vs[j], model.nvs[j])
            for j in range(1, model.njoints)
            if model.nvs[j] > 0
        ]
        self._coord = {c.joint: c for c in self.coordinates}
        self.cuts = [self._bind_cut(c) for c in spec.cut_joints]
        # a ground frame for targets (inverse kinematics); every frame must exist
        # before any pinocchio.Data is made from the model
        self.target_frame = model.addFrame(
            pin.Frame("screwkin@target", 0, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME), False)
        self.data = model.createData()
        self.closure = ClosureSystem(model, self.cuts, tolerances, self.path)
        self.set_actuated(actuated)
        self._assembly = None
        self._limits = None

    # ------------------------------------------------------------------ binding
    def _frame_id(self, name: str, what: str) -> int:
        if not self.model.existFrame(name):
            raise MechanismFileError(self.path, f"{what} names frame '{name}', which is not in the model")
        return self.model.getFrameId(name)

    def _bind_cut(self, c) -> CutJoint:
        ids = []
        for k, (frame, xyz, rpy) in enumerate(((c.frame1, c.xyz1, c.rpy1), (c.frame2, c.xyz2, c.rpy2)), 1):
            fid = self._frame_id(frame, f"loop joint '{c.name}'")
            parent = self.model.frames[fid]
            frame_placement = parent.placement * placement(xyz, rpy)
            new = pin.Frame(f"{c.name}@F{k}", parent.parentJoint, fid, frame_placement, pin.FrameType.OP_FRAME)
            ids.append(self.model.addFrame(new, False))
        self.data = self.model.createData()
        return CutJoint(c.name, c.type, c.dof, ids[0], ids[1], c.frame1, c.frame2, tuple(c.axis),
                        tuple(c.axis2) if c.axis2 is not None else None)

    def set_actuated(self, actuated=None):
        """Choose the actuated joints (None: the file's declaration)."""
        names, source = resolve_actuation(self.spec, actuated)
        unknown = [n for n in names if n not in self._coord]
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
            known = ", ".join(c.joint for c in self.coordinates)
            raise UsageError(f"{self.path}: no moving joint named '{joint}' (joints: {known})") from None

    def velocity_indices(self, joints) -> np.ndarray:
        """Velocity (tangent) indices of the named joints, in order."""
        idx = []
        for j in joints:
            c = self.coordinate(j)
            idx.extend(range(c.idx_v, c.idx_v + c.nv))
        return np.asarray(idx, int)

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

    # ------------------------------------------------------------------ analyses
    def assemble(self, q0=None) -> Assembly:
        """Close the loops starting from q0 (default: the file's configuration)."""
        if q0 is None and self._assembly is not None:
            return self._assembly
        result = self.closure.solve(self.neutral() if q0 is None else q0)
        if q0 is None:
            self._assembly = result
        return result

    def topology(self, q=None):
        """The :class:`~screwkin.topology.Topology` (links, joints, compound joints, loops)."""
        from .topology import build_topology

        return build_topology(self, self.assemble().q if q is None else q)

    def mobility(self, actuated=None, output=None, seed: int = 0):
        """Mobility analysis; returns a :class:`~screwkin.mobility.MobilityResult`."""
        from .mobility import analyze_mobility

        if actuated is not None:
            self.set_actuated(actuated)
        return analyze_mobility(self, output=output, seed=seed)

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
    if spec.replacements:
        model = _replace_joints(model, spec.replacements)
    check_sizes(spec.yaml_path or path, len(spec.links), len(spec.joints), len(spec.cut_joints), model.nv)
    _check_cut_bodies(model, spec)
    _unambiguous_cut_frames(model, spec)
    shown = spec.warnings
    if warn is None:  # on the terminal: a bounded number of bounded lines
        def warn(m):
            print(f"warning: {shorten(str(path), 200)}: {shorten(m, 400)}", file=sys.stderr)

        if len(shown) > MAX_WARNINGS:
            shown = shown[:MAX_WARNINGS] + [f"and {len(spec.warnings) - MAX_WARNINGS} more warnings"]
    for w in shown:
        warn(w)
    return Mechanism(spec, model, actuated=actuated, tolerances=tolerances)
