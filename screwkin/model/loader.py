"""Loading a mechanism file into a :class:`~screwkin.model.mechanism.Mechanism`.

The file becomes a description (screwkin.files); Pinocchio's URDF parser builds the
model of the spanning tree from its URDF text; the model is rebuilt once where
screwkin needs it otherwise (continuous joints as revolute joints without limits,
the sidecar's joint replacements, mimicked joints before their mimics) and the
<mimic> couplings are made Pinocchio mimic joints; the cut joints are bound to it.
"""

from __future__ import annotations

import os
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import MechanismFileError, UsageError, quote, shorten
from ..files.description import LIMITS, placement
from ..files.mjcf import read_mjcf
from ..files.sdf import read_sdf
from ..files.sidecar import axis_letters, read_yaml_sidecar
from ..files.urdf import check_sizes, read_urdf
from ..files.xacro import expand as expand_xacro
from ..files.xacro import is_xacro
from ..files.xmlsafe import parse_xml_text, read_regular_file
from ..tolerances import DEFAULT, Tolerances
from ._pin import FRAME_PREFERENCE, frame_id
from .cuts import in_plane
from .cuts import virtual_joint_name, virtual_roles
from .mechanism import Mechanism
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.files.description import MechanismSpec
    from collections.abc import Callable
    from collections.abc import Iterator

__all__ = ["load", "rebuild"]


def _read_text(path: Path) -> str:
    """The text of a mechanism file: a regular file of at most ``LIMITS.file_bytes``, in UTF-8."""
    raw = read_regular_file(path, LIMITS.file_bytes, "mechanism file")
    if not raw.strip():
        raise MechanismFileError(path, "the file is empty")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise MechanismFileError(path, "not a text file (not UTF-8)") from None


def _find_sidecar(path: Path) -> Path | None:
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


def _frame_bodies(model: pin.Model) -> dict:
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


def _check_cut_bodies(model: pin.Model, spec: MechanismSpec) -> None:
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


_UNBOUNDED = {"JointModelRUBX": pin.JointModelRX, "JointModelRUBY": pin.JointModelRY,
              "JointModelRUBZ": pin.JointModelRZ}


def _revolute_for(jm: pin.JointModel) -> pin.JointModelRY | pin.JointModelRZ | None:
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


def _order(model: pin.Model, first: set | tuple = ()) -> list:
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


def _rebuild(model: pin.Model, replacements: list=(), first: set | tuple = ()) -> pin.Model:
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
            a1, a2 = axis_letters(t)
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


def _couple(model: pin.Model, couplings: list, path: str) -> pin.Model:
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


def _virtual_pairs(model: pin.Model, spec: MechanismSpec) -> None:
    """Give every rolling, gear and helical loop joint the massless chain of its equivalent
    linkage, from F1 on its first link, whose coordinates are the pair's unwrapped angles (and
    advance); the loop closes with a weld from the chain's end frame ``NAME@end`` to F2, and a
    coupling row (model.cuts.CouplingRow) relates the coordinates:

    - two circles (radii r1, r2; R = r1 + r2 outside, r1 - r2 inside): a revolute at F1's
      origin (coordinate a1: the contact direction in F1, from its x axis), then, at distance R
      along it, a revolute (a2 = -its coordinate: the contact direction in F2) whose frame is
      turned by pi outside, so that a1 = a2 = 0 puts the points on both x axes in contact;
      no slip r1 a1 + r2 a2 = 0 outside, r1 a1 - r2 a2 = 0 inside;
    - a circle on a line (F1's x axis; radius1 inf): a slide along the line (x, the contact
      point) and, r2 beside it on the side of -y, a revolute (a2 = -its coordinate); x + r2 a2 = 0;
    - a screw: a revolute about the axis (turn) then a slide along it (advance);
      advance = lead turn / 2 pi.
    """
    for c in spec.cut_joints:
        if c.type not in ("rolling", "gear", "helical"):
            continue
        fid = frame_id(model, c.frame1)
        if fid is None:
            continue  # reported when the cut joint is bound
        parent = model.frames[fid]
        P = parent.placement * placement(c.xyz1, c.rpy1)
        a, u, n = in_plane(c.axis)
        inf, zero = np.array([-np.inf]), np.array([np.inf])

        roles = virtual_roles(c)

        def add(joint_parent, jm, M, role: str, c=c):  # called at once, in this iteration
            name = virtual_joint_name(c.name, role)
            if model.existJointName(name):
                raise MechanismFileError(spec.path, f"joint {quote(name)} is also the name of a coordinate of loop "
                                                    f"joint {quote(c.name)} ({c.type}): rename one of them")
            jid = model.addJoint(joint_parent, jm, M, name, np.zeros(1), np.zeros(1), inf, zero)  # noqa: B023 - add is called at once
            model.appendBodyToJoint(jid, pin.Inertia.Zero(), pin.SE3.Identity())
            return jid

        if c.type == "helical":
            v1 = add(parent.parentJoint, pin.JointModelRevoluteUnaligned(a), P, roles[0])
            v2 = add(v1, pin.JointModelPrismaticUnaligned(a), pin.SE3.Identity(), roles[1])
        elif np.isinf(c.radius1):
            v1 = add(parent.parentJoint, pin.JointModelPrismaticUnaligned(u), P, roles[0])
            M = pin.SE3(pin.exp3(a * np.pi / 2), -c.radius2 * n)
            v2 = add(v1, pin.JointModelRevoluteUnaligned(a), M, roles[1])
        else:
            outside = c.contact != "internal"
            R = c.radius1 + c.radius2 if outside else c.radius1 - c.radius2
            v1 = add(parent.parentJoint, pin.JointModelRevoluteUnaligned(a), P, roles[0])
            M = pin.SE3(pin.exp3(a * np.pi) if outside else np.eye(3), R * u)
            v2 = add(v1, pin.JointModelRevoluteUnaligned(a), M, roles[1])
        model.addFrame(pin.Frame(f"{c.name}@end", v2, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME), False)


def _finish_model(spec: MechanismSpec, model: pin.Model) -> pin.Model:
    """The tree model of a read file (its sidecar applied) made screwkin's: continuous joints, the joint
    replacements, mimic couplings, the virtual chains of higher pairs; sizes and cut joints checked."""
    path = spec.path
    model = _rebuild(model, spec.replacements, first={c.mimics for c in spec.couplings})
    model = _couple(model, spec.couplings, path)
    _virtual_pairs(model, spec)
    check_sizes(spec.yaml_path or path, len(spec.links), len(spec.joints), len(spec.cut_joints), model.nv)
    _check_cut_bodies(model, spec)
    return model


def rebuild(spec: MechanismSpec, actuated: list | None = None, tolerances: Tolerances = DEFAULT, cls=Mechanism) -> Mechanism:
    """A Mechanism from a description already read (and changed: other joint replacements, other cut
    joint types -- analysis.redundancy builds the exactly constrained model it suggests this way)."""
    with _native_stderr([]):
        model = pin.buildModelFromXML(spec.urdf_text)
    return cls(spec, _finish_model(spec, model), actuated=actuated, tolerances=tolerances)


#: The XML whitespace that attribute-value normalisation turns into a space (XML 1.0, section 3.3.3).
_NORMALISED = "\t\n\r"


def _check_names_read_alike(model: pin.Model, spec: MechanismSpec, path: Path) -> None:
    """Refuse a link or joint name that Pinocchio's parser and screwkin's read differently: a literal
    tab, newline or carriage return inside the quotes of its name.  urdfdom (TinyXML2: Pinocchio's
    parser, ROS's robot_state_publisher and check_urdf) keeps the character (a carriage return as a
    newline); the XML standard's attribute-value normalisation, which screwkin's reader, xacro and
    every conforming parser apply, reads a space.  The same file then names two different joints
    in two of ROS's own tools, and screwkin's two models would disagree: an error naming the name,
    exit 1.  Written as a character reference (``&#9;``) the character is kept by every reader
    (the standard does not normalise references), and the name is accepted."""
    ours = set(spec.links) | {j.name for j in spec.joints}
    for frame in list(model.frames)[1:]:
        name = frame.name
        if name in ours or not any(c in name for c in _NORMALISED):
            continue
        kind = "link" if frame.type == pin.FrameType.BODY else "joint"
        raise MechanismFileError(path, f"{kind} {quote(name)}: a literal tab or line break in a name is kept by "
                                       "urdfdom (Pinocchio, ROS) but read as a space by XML-standard readers "
                                       "(xacro, screwkin): write a space, or &#9; / &#10; to keep the character")


@contextmanager
def _native_stderr(box: list) -> Iterator:
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


def _print_warning(path: Path) -> Callable:
    def warn(m) -> None:
        print(f"warning: {shorten(str(path), 200)}: {shorten(m, 400)}", file=sys.stderr)

    return warn


def load(path: str | Path, yaml=None, actuated: list | None=None, tolerances: Tolerances = DEFAULT, warn: Callable | None=None, package_dirs=None,
         cls=Mechanism, args: dict | None=None, text: str | None = None) -> Mechanism:
    """Read a mechanism file (URDF with ``<loop_joint>`` or a YAML sidecar, SDF, MJCF, or a
    xacro file that expands to such a URDF).

    yaml:      path of an Extended-URDF sidecar; default: ``<file>.yaml`` when it exists.
    actuated:  actuated joint names, overriding the file's declaration.
    warn:      callable receiving each warning (default: print to stderr).
    package_dirs: folders searched first for ``package://`` meshes (as ``ROS_PACKAGE_PATH``).
    args:      xacro arguments {name: value} (numbers, or text such as ``"30mm"``: SI); only
               for xacro files (name ending in ``.xacro``, or declaring the xacro namespace).
    text:      the file's text, when already read (``path`` still names it in messages and
               locates its sidecar, meshes and includes).

    The file is untrusted: see :mod:`screwkin.files.xmlsafe`, :mod:`screwkin.files.xacro`
    and :class:`~screwkin.files.description.Limits` for what is refused before Pinocchio
    reads it.
    """
    path = Path(path)
    text = _read_text(path) if text is None else text
    root = parse_xml_text(text, path)  # the root element decides the format, not the suffix
    expansion_warnings, read = [], []
    if is_xacro(path, text):
        text = expand_xacro(path, text, args, root=root, warn=expansion_warnings.append, read=read)
        root = parse_xml_text(text, path)
    elif args:
        raise UsageError(f"{path}: xacro arguments (--arg) are given but the file is not a xacro file (its name "
                         "does not end in .xacro and it does not declare the xacro namespace)")
    package_dirs = [str(d) for d in package_dirs or ()]
    for d in package_dirs:
        if not os.path.isdir(d):
            raise UsageError(f"package folder {quote(d)} (--package-dir) is not a folder")
    if root.tag == "sdf":
        spec = read_sdf(path, text, root=root, package_dirs=package_dirs)
    elif root.tag == "mujoco":
        spec = read_mjcf(path, text, root=root, package_dirs=package_dirs)
    elif root.tag == "robot" or path.suffix.lower() != ".sdf":
        spec = read_urdf(path, text, root=root, package_dirs=package_dirs)
    else:
        raise MechanismFileError(path, f"not an SDF file: the root element is <{shorten(root.tag, 40)}>, "
                                       "expected <sdf>")
    spec.package_dirs = package_dirs
    spec.warnings[:0] = expansion_warnings
    spec.files_read[:0] = read or [str(path)]  # (the reader's own: includes, meshes)
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
    _check_names_read_alike(model, spec, path)
    if yaml is None and spec.format == "urdf":
        yaml = _find_sidecar(path)
    if yaml is not None:
        read_yaml_sidecar(spec, Path(yaml), [f.name for f in model.frames], _frame_bodies(model))
        spec.files_read.append(str(yaml))
    model = _finish_model(spec, model)
    shown = spec.warnings
    if warn is None:  # on the terminal: a bounded number of bounded lines
        warn = _print_warning(path)
        if len(shown) > MAX_WARNINGS:
            shown = shown[:MAX_WARNINGS] + [f"and {len(spec.warnings) - MAX_WARNINGS} more warnings"]
    for w in shown:
        warn(w)
    return cls(spec, model, actuated=actuated, tolerances=tolerances)

