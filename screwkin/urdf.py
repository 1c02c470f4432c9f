"""Reading URDF files with loop joints, transmissions and YAML sidecars.

The tree part is left to Pinocchio's URDF parser (the file's own text is what it
reads); this module reads what that parser ignores -- ``<loop_joint>``,
``<transmission>``, link masses and geometry -- and validates the file first so
that every problem is reported with the file's name and all at once.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .description import (
    CUT_JOINT_DOF,
    TREE_JOINT_DOF,
    CutJointSpec,
    JointSpec,
    LinkSpec,
    MechanismSpec,
    finite,
)
from .errors import MechanismFileError
from .xmlsafe import parse_xml_text

__all__ = ["read_urdf", "read_yaml_sidecar", "numbers", "check_tree", "check_meshes"]


class _Problems(list):
    """Collects every problem of a file before failing."""

    def fail_if_any(self, path):
        if self:
            raise MechanismFileError(path, list(self))


def numbers(text, count, what, problems, default):
    """Parse ``count`` floats from an attribute; record a problem when invalid."""
    if text is None:
        return tuple(default)
    parts = text.split()
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        problems.append(f"{what}: '{text}' is not {count} numbers")
        return tuple(default)
    if len(values) != count:
        problems.append(f"{what}: '{text}' has {len(values)} numbers, expected {count}")
        return tuple(default)
    if not finite(values):
        problems.append(f"{what}: '{text}' contains NaN or infinite numbers")
        return tuple(default)
    return values


def _axis(elem, what, problems, default=(1.0, 0.0, 0.0)):
    if elem is None:
        return tuple(default)
    values = numbers(elem.get("xyz"), 3, f"{what} <{elem.tag} xyz>", problems, default)
    if np.linalg.norm(values) < 1e-12:
        problems.append(f"{what}: zero axis '{elem.get('xyz')}'")
        return tuple(default)
    return tuple(np.asarray(values) / np.linalg.norm(values))


def _link(elem, problems) -> LinkSpec:
    name = elem.get("name")
    mass = None
    mass_elem = elem.find("inertial/mass")
    if mass_elem is not None:
        value = numbers(mass_elem.get("value"), 1, f"link '{name}' <mass value>", problems, (0.0,))
        mass = value[0]
    for inertia in elem.findall("inertial/inertia"):
        for key, val in inertia.attrib.items():
            numbers(val, 1, f"link '{name}' <inertia {key}>", problems, (0.0,))
    for origin in elem.findall("*/origin"):
        numbers(origin.get("xyz"), 3, f"link '{name}' <origin xyz>", problems, (0, 0, 0))
        numbers(origin.get("rpy"), 3, f"link '{name}' <origin rpy>", problems, (0, 0, 0))
    has_geometry = elem.find("visual") is not None or elem.find("collision") is not None
    return LinkSpec(name=name, mass=mass, has_geometry=has_geometry)


def _joint(elem, links, problems) -> JointSpec | None:
    name = elem.get("name")
    if not name:
        problems.append("a <joint> has no name")
        return None
    jtype = elem.get("type")
    if jtype not in TREE_JOINT_DOF:
        problems.append(
            f"joint '{name}' has unknown type '{jtype}' (known: {', '.join(sorted(TREE_JOINT_DOF))})"
        )
        return None
    ends = {}
    for tag in ("parent", "child"):
        e = elem.find(tag)
        link = e.get("link") if e is not None else None
        if not link:
            problems.append(f"joint '{name}' has no <{tag} link>")
            return None
        if link not in links:
            problems.append(f"joint '{name}' names {tag} link '{link}', which does not exist")
            return None
        ends[tag] = link
    origin = elem.find("origin")
    xyz = numbers(origin.get("xyz") if origin is not None else None, 3, f"joint '{name}' <origin xyz>", problems, (0, 0, 0))
    rpy = numbers(origin.get("rpy") if origin is not None else None, 3, f"joint '{name}' <origin rpy>", problems, (0, 0, 0))
    axis = (1.0, 0.0, 0.0)
    if jtype in ("revolute", "continuous", "prismatic", "planar"):
        axis = _axis(elem.find("axis"), f"joint '{name}'", problems)
    limit = elem.find("limit")
    if limit is not None:
        for key in ("lower", "upper", "effort", "velocity"):
            if limit.get(key) is not None:
                numbers(limit.get(key), 1, f"joint '{name}' <limit {key}>", problems, (0.0,))
    return JointSpec(name, jtype, ends["parent"], ends["child"], xyz, rpy, axis)


def _loop_joint(elem, links, problems, warnings) -> CutJointSpec | None:
    name = elem.get("name")
    if not name:
        problems.append("a <loop_joint> has no name")
        return None
    jtype = elem.get("type")
    if jtype not in CUT_JOINT_DOF:
        problems.append(
            f"loop joint '{name}' has unknown type '{jtype}' (known: {', '.join(sorted(CUT_JOINT_DOF))})"
        )
        return None
    firsts = elem.findall("link1")
    seconds = elem.findall("link2")
    if len(firsts) == 2 and not seconds:
        warnings.append(f"loop joint '{name}' has two <link1> children; the second is read as <link2>")
        seconds = [firsts[1]]
    if len(firsts) < 1 or len(seconds) < 1:
        problems.append(f"loop joint '{name}' needs a <link1> and a <link2>")
        return None
    sides = []
    for tag, e in (("link1", firsts[0]), ("link2", seconds[0])):
        link = e.get("link")
        if not link:
            problems.append(f"loop joint '{name}' <{tag}> has no link attribute")
            return None
        if link not in links:
            problems.append(f"loop joint '{name}' names {tag} '{link}', which is not a link of the file")
            return None
        xyz = numbers(e.get("xyz"), 3, f"loop joint '{name}' <{tag} xyz>", problems, (0, 0, 0))
        rpy = numbers(e.get("rpy"), 3, f"loop joint '{name}' <{tag} rpy>", problems, (0, 0, 0))
        sides.append((link, xyz, rpy))
    axis = _axis(elem.find("axis"), f"loop joint '{name}'", problems)
    axis2 = None
    if jtype == "universal":
        a2 = elem.find("axis2")
        if a2 is None:
            problems.append(f"universal loop joint '{name}' needs an <axis2 xyz> (its second axis, in F2)")
            return None
        axis2 = _axis(a2, f"loop joint '{name}'", problems)
    (l1, xyz1, rpy1), (l2, xyz2, rpy2) = sides
    if l1 == l2:
        problems.append(f"loop joint '{name}' connects link '{l1}' to itself")
        return None
    return CutJointSpec(name, jtype, l1, l2, xyz1, rpy1, xyz2, rpy2, axis, axis2, source="loop_joint")


def check_tree(path, links, joints, problems):
    """Record problems that keep the joints from forming one tree over the links."""
    parent_of = {}
    for j in joints:
        if j.child in parent_of:
            problems.append(
                f"link '{j.child}' has two parents ('{parent_of[j.child][0]}' through joint "
                f"'{parent_of[j.child][1]}' and '{j.parent}' through joint '{j.name}'); "
                "a closed loop must be written as a <loop_joint>"
            )
        else:
            parent_of[j.child] = (j.parent, j.name)
    roots = [name for name in links if name not in parent_of]
    if len(links) == 0:
        problems.append("the file has no links")
    elif not roots:
        problems.append("the joints form a cycle: no link is the root")
    elif len(roots) > 1:
        problems.append(
            f"the links do not form one tree: {len(roots)} links have no parent joint ({', '.join(roots[:5])})"
        )
    else:
        # every link must reach the root without cycling
        for start in links:
            seen = set()
            link = start
            while link in parent_of:
                if link in seen:
                    problems.append(f"the joints form a cycle through link '{start}'")
                    return
                seen.add(link)
                link = parent_of[link][0]


def read_urdf(path: Path, text: str) -> MechanismSpec:
    """Read a URDF file (already loaded as ``text``) into a :class:`MechanismSpec`."""
    root = parse_xml_text(text, path)
    if root.tag != "robot":
        raise MechanismFileError(path, f"not a URDF file: the root element is <{root.tag}>, expected <robot>")
    problems = _Problems()
    warnings = []
    links = {}
    for elem in root.findall("link"):
        name = elem.get("name")
        if not name:
            problems.append("a <link> has no name")
            continue
        if name in links:
            problems.append(f"link '{name}' is defined twice")
            continue
        links[name] = _link(elem, problems)
    joints = []
    seen = set()
    for elem in root.findall("joint"):
        j = _joint(elem, links, problems)
        if j is None:
            continue
        if j.name in seen:
            problems.append(f"joint '{j.name}' is defined twice")
        seen.add(j.name)
        joints.append(j)
    problems.fail_if_any(path)
    check_tree(path, links, joints, problems)
    cuts = []
    for elem in root.findall("loop_joint"):
        c = _loop_joint(elem, links, problems, warnings)
        if c is not None:
            if c.name in seen:
                problems.append(f"loop joint '{c.name}' has the name of another joint")
            seen.add(c.name)
            cuts.append(c)
    transmissions = []
    for t in root.findall("transmission"):
        for j in t.findall("joint"):
            jn = j.get("name")
            if jn not in {x.name for x in joints}:
                problems.append(f"transmission '{t.get('name')}' names joint '{jn}', which is not a tree joint")
            elif jn not in transmissions:
                transmissions.append(jn)
    problems.fail_if_any(path)
    warnings += check_meshes(path, root)
    return MechanismSpec(
        path=str(path),
        name=root.get("name") or Path(path).stem,
        format="urdf",
        urdf_text=text,
        links=links,
        joints=joints,
        cut_joints=cuts,
        transmissions=transmissions,
        warnings=warnings,
    )


def resolve_uri(uri: str, base: Path):
    """Candidate paths of a mesh URI: ``package://`` against the file's folder
    and ``ROS_PACKAGE_PATH``, ``file://`` as is, relative paths against the file."""
    if uri.startswith("package://"):
        rest = uri[len("package://"):]
        package, _, inside = rest.partition("/")
        inside = inside.lstrip("/")
        roots = [base, *base.parents[:2]]
        roots += [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
        cands = []
        for r in roots:
            if package:
                cands += [r / package / inside, r / inside]
                if r.name == package:
                    cands.append(r / inside)
            else:
                cands.append(r / inside)
        return cands
    if uri.startswith("file://"):
        return [Path(uri[len("file://"):])]
    p = Path(uri)
    return [p if p.is_absolute() else base / p]


def check_meshes(path, root) -> list:
    """Warnings for mesh files that cannot be found (missing meshes do not fail a load)."""
    base = Path(path).resolve().parent
    missing = []
    for mesh in root.iter("mesh"):
        uri = mesh.get("filename") or (mesh.findtext("uri") or "").strip()
        if not uri or uri.startswith("model://"):
            continue
        if not any(c.is_file() for c in resolve_uri(uri, base)):
            if uri not in missing:
                missing.append(uri)
    if not missing:
        return []
    shown = ", ".join(missing[:3]) + (f" and {len(missing) - 3} more" if len(missing) > 3 else "")
    return [f"{len(missing)} mesh file(s) not found (views will use stand-ins): {shown}"]


_YAML_TYPES = {"6d": "fixed", "3d": "spherical"}


def read_yaml_sidecar(spec: MechanismSpec, yaml_path: Path, frame_names) -> None:
    """Add the loops, actuation and joint replacements of an Extended-URDF sidecar.

    ``frame_names`` are the frames of the Pinocchio model of the tree: the YAML
    names frames, not links.
    """
    import yaml

    try:
        content = yaml.safe_load(Path(yaml_path).read_text())
    except yaml.YAMLError as exc:
        first = str(exc).splitlines()[0]
        raise MechanismFileError(yaml_path, f"malformed YAML: {first}") from None
    except OSError as exc:
        raise MechanismFileError(yaml_path, f"cannot read: {exc.strerror}") from None
    if content is None:
        content = {}
    if not isinstance(content, dict):
        raise MechanismFileError(yaml_path, "expected a mapping with closed_loop, type, name_mot")
    problems = _Problems()
    pairs = content.get("closed_loop") or []
    types = content.get("type") or ["6d"] * len(pairs)
    if not isinstance(pairs, list) or not isinstance(types, list):
        raise MechanismFileError(yaml_path, "closed_loop and type must be lists")
    if len(types) != len(pairs):
        problems.append(f"closed_loop has {len(pairs)} pairs but type has {len(types)} entries")
    frames = set(frame_names)
    for k, pair in enumerate(pairs):
        if not (isinstance(pair, (list, tuple)) and len(pair) == 2):
            problems.append(f"closed_loop entry {k + 1} is not a pair of frame names: {pair!r}")
            continue
        a, b = (str(x) for x in pair)
        for f in (a, b):
            if f not in frames:
                problems.append(f"closed_loop names frame '{f}', which is not in the URDF")
        ctype = str(types[k]).lower() if k < len(types) else "6d"
        if ctype not in _YAML_TYPES:
            problems.append(f"closed_loop type '{types[k]}' is unknown (known: 3d, 6d)")
            continue
        spec.cut_joints.append(
            CutJointSpec(name=f"{a}~{b}", type=_YAML_TYPES[ctype], frame1=a, frame2=b, source="yaml")
        )
    names = content.get("name_mot")
    joint_names = {j.name for j in spec.joints}
    if names is not None:
        if not isinstance(names, list):
            problems.append("name_mot must be a list of joint names")
        else:
            for n in names:
                if n not in joint_names:
                    problems.append(f"name_mot names joint '{n}', which is not in the URDF")
            spec.yaml_actuated = [str(n) for n in names]
    jn = content.get("joint_name") or []
    jt = content.get("joint_type") or []
    if len(jn) != len(jt):
        problems.append(f"joint_name has {len(jn)} entries but joint_type has {len(jt)}")
    for n, t in zip(jn, jt):
        if n not in joint_names:
            problems.append(f"joint_name names joint '{n}', which is not in the URDF")
        t = str(t).upper()
        if t not in ("SPHERICAL", "FIXED") and not t.startswith(("UJOINT", "CARDAN")):
            problems.append(f"joint_type '{t}' is unknown (known: SPHERICAL, FIXED, CARDAN, UJOINT_XY, ...)")
        spec.replacements.append((str(n), t))
    problems.fail_if_any(yaml_path)
    spec.yaml_path = str(yaml_path)
