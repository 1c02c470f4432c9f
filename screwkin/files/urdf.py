"""Reading URDF files with loop joints, transmissions and YAML sidecars.

The tree part is left to Pinocchio's URDF parser (the file's own text is what it
reads); this module reads what that parser ignores -- ``<loop_joint>``,
``<transmission>``, ``<screwkin:targets>`` (a synthesized design's precision positions), link
masses and geometry -- and validates the file first so
that every problem is reported with the file's name and all at once.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from ..errors import MechanismFileError, quote, shorten
from ..tolerances import DEFAULT
from .description import (
    CUT_JOINT_DOF,
    HIGHER_PAIRS,
    LIMITS,
    PROFILE_SHAPES,
    TREE_JOINT_DOF,
    CutJointSpec,
    JointSpec,
    LinkSpec,
    MechanismSpec,
    resolve_chains,
    TARGET_KINDS,
    TARGETS_NS,
    TargetSpec,
    data_bytes,
)
from .inertia import inertia_problem, inertia_warnings
from .meshes import check_meshes
from .urdf_transmission import read_transmissions
from .xmlsafe import parse_xml_text
from typing import TYPE_CHECKING
if TYPE_CHECKING:
    from xml.etree.ElementTree import Element

__all__ = ["read_urdf", "numbers", "unit_axis", "check_tree", "check_sizes", "Problems"]


class Problems(list):
    """Collects every problem of a file before failing."""

    def fail_if_any(self, path: Path | str) -> None:
        if self:
            raise MechanismFileError(path, list(self))


# a plain decimal number as urdfdom and SDFormat read it (no "1_000", no non-ASCII digits, no hex)
_NUMBER = re.compile(r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?\Z")
_NONFINITE = re.compile(r"[-+]?(?:nan|inf|infinity)\Z", re.IGNORECASE)


def numbers(text: str, count: int, what: str, problems: list | Problems, default: tuple, bound: float | None=None, unit: str = "m", low: float | None=None) -> tuple:
    """Parse ``count`` floats from an attribute; record a problem when invalid.

    bound: largest magnitude accepted (see :class:`~screwkin.files.description.Limits`);
    low: smallest value accepted (e.g. 0 for a mass).
    """
    if text is None:
        return tuple(default)
    parts = text.split()
    if len(parts) != count:
        problems.append(f"{what}: {quote(text)} has {len(parts)} number{'' if len(parts) == 1 else 's'}, "
                        f"expected {count}")
        return tuple(default)
    if any(_NONFINITE.match(p) for p in parts):
        problems.append(f"{what}: {quote(text)} contains NaN or infinite numbers")
        return tuple(default)
    if not all(_NUMBER.match(p) for p in parts):
        problems.append(f"{what}: {quote(text)} is not {count} number{'s' if count > 1 else ''}")
        return tuple(default)
    values = tuple(float(p) for p in parts)
    if not all(math.isfinite(v) for v in values):  # digits beyond the range of a double: 1e999
        problems.append(f"{what}: {quote(text)} contains NaN or infinite numbers")
        return tuple(default)
    if bound is not None and any(abs(v) > bound for v in values):
        problems.append(f"{what}: {quote(text)} is not a plausible value (beyond {bound:g}{' ' + unit if unit else ''})")
        return tuple(default)
    if low is not None and any(v < low for v in values):
        problems.append(f"{what}: {quote(text)} is not a plausible value (below {low:g}{' ' + unit if unit else ''})")
        return tuple(default)
    return values


def unit_axis(values: tuple | np.ndarray, what: str, problems: Problems | list, default: tuple=(1.0, 0.0, 0.0)) -> tuple:
    """``values`` scaled to length 1 (safely: divided by the largest magnitude first);
    records a problem for a zero axis or one whose length Pinocchio cannot normalize."""
    v = np.asarray(values, float)
    big = float(np.max(np.abs(v))) if v.size else 0.0
    if not big:
        problems.append(f"{what}: zero axis {quote(' '.join(f'{x:g}' for x in v))}")
        return tuple(default)
    length = big * float(np.linalg.norm(v / big))
    if not LIMITS.axis_min <= length <= LIMITS.axis_max:
        problems.append(f"{what}: axis {quote(' '.join(f'{x:g}' for x in v))} is not a plausible value "
                        f"(its length must lie between {LIMITS.axis_min:g} and {LIMITS.axis_max:g})")
        return tuple(default)
    u = v / big
    return tuple(u / np.linalg.norm(u))


def _axis(elem: Element | None, what: str, problems: Problems, default: tuple=(1.0, 0.0, 0.0)) -> tuple:
    if elem is None or elem.get("xyz") is None:  # urdfdom's default: the x axis
        return tuple(default)
    before = len(problems)
    values = numbers(elem.get("xyz"), 3, f"{what} <{elem.tag} xyz>", problems, default)
    if len(problems) > before:
        return tuple(default)
    return unit_axis(values, what, problems, default)


def _origin(elem: Element | None, what: str, problems: Problems) -> tuple:
    """xyz and rpy of an ``<origin>`` (or of any element carrying them), checked."""
    get = (lambda k: elem.get(k)) if elem is not None else (lambda k: None)
    xyz = numbers(get("xyz"), 3, f"{what} xyz>", problems, (0.0, 0.0, 0.0), LIMITS.length, "m")
    rpy = numbers(get("rpy"), 3, f"{what} rpy>", problems, (0.0, 0.0, 0.0), LIMITS.angle, "rad")
    return xyz, rpy


_GEOMETRY = {"box": (("size", 3),), "cylinder": (("radius", 1), ("length", 1)), "sphere": (("radius", 1),),
             "capsule": (("radius", 1), ("length", 1)), "mesh": (("scale", 3),)}


def _link(elem: Element, problems: Problems) -> LinkSpec:
    name = elem.get("name")
    what = f"link {quote(name)}"
    mass = None
    mass_elem = elem.find("inertial/mass")
    if mass_elem is not None:
        value = numbers(mass_elem.get("value"), 1, f"{what} <mass value>", problems, (0.0,), LIMITS.mass, "kg",
                        low=0.0)
        mass = value[0]
    impossible = None
    for inertia in elem.findall("inertial/inertia"):
        before = len(problems)
        got = {key: numbers(val, 1, f"{what} <inertia {quote(key, 20)}>", problems, (0.0,), LIMITS.inertia,
                            "kg m^2")[0] for key, val in inertia.attrib.items()}
        if len(problems) == before:  # (a missing component is urdfdom's to refuse)
            impossible = inertia_problem(mass, *(got.get(k, 0.0) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")))
    for origin in elem.findall("*/origin"):
        _origin(origin, f"{what} <origin", problems)
    for shape in elem.findall("*/geometry/*"):
        for key, count in _GEOMETRY.get(shape.tag, ()):  # sizes are not negative; a mesh scale may be (mirroring)
            numbers(shape.get(key), count, f"{what} <{shape.tag} {key}>", problems, (0.0,) * count, LIMITS.length,
                    "m", low=None if key == "scale" else 0.0)
    has_geometry = elem.find("visual") is not None or elem.find("collision") is not None
    return LinkSpec(name=name, mass=mass, has_geometry=has_geometry, inertia_problem=impossible)


def _name_and_type(elem: Element, tag: str, kind: str, types: dict, problems: Problems) -> tuple | None:
    """(name, type, 'kind NAME') of a <joint> or <loop_joint>, or None after recording why."""
    name = elem.get("name")
    if not name:
        problems.append(f"a <{tag}> has no name")
        return None
    what = f"{kind} {quote(name)}"
    jtype = elem.get("type")
    if jtype not in types:
        problems.append(f"{what} has unknown type {quote(jtype)} (known: {', '.join(sorted(types))})")
        return None
    return name, jtype, what


def _joint(elem: Element, links: dict, problems: Problems) -> JointSpec | None:
    head = _name_and_type(elem, "joint", "joint", TREE_JOINT_DOF, problems)
    if head is None:
        return None
    name, jtype, what = head
    ends = {}
    for tag in ("parent", "child"):
        e = elem.find(tag)
        link = e.get("link") if e is not None else None
        if not link:
            problems.append(f"{what} has no <{tag} link>")
            return None
        if link not in links:
            problems.append(f"{what} names {tag} link {quote(link)}, which does not exist")
            return None
        ends[tag] = link
    xyz, rpy = _origin(elem.find("origin"), f"{what} <origin", problems)
    axis = (1.0, 0.0, 0.0)
    if jtype in ("revolute", "continuous", "prismatic", "planar"):
        axis = _axis(elem.find("axis"), what, problems)
    limit = elem.find("limit")
    if limit is not None:
        values = {}
        for key in ("lower", "upper", "effort", "velocity"):
            if limit.get(key) is not None:
                values[key] = numbers(limit.get(key), 1, f"{what} <limit {key}>", problems, (None,))[0]
        lo, hi = values.get("lower"), values.get("upper")
        if jtype in ("revolute", "prismatic") and lo is not None and hi is not None and lo > hi:
            problems.append(f"{what} <limit>: lower {lo:g} > upper {hi:g}")
    mimic = None
    m = elem.find("mimic")
    if m is not None:
        target = m.get("joint")
        if not target:
            problems.append(f"{what} <mimic> has no joint attribute")
        else:
            mult = numbers(m.get("multiplier"), 1, f"{what} <mimic multiplier>", problems, (1.0,))[0]
            off = numbers(m.get("offset"), 1, f"{what} <mimic offset>", problems, (0.0,))[0]
            mimic = (target, mult, off)
    dyn = elem.find("dynamics")  # MuJoCo's URDF reader: damping -> damping, friction -> frictionloss
    dyn = {} if dyn is None else {key: numbers(dyn.get(attr), 1, f"{what} <dynamics {attr}>", problems, (0.0,), 1e9, "")[0]
                                  for key, attr in (("damping", "damping"), ("frictionloss", "friction"))}
    return JointSpec(name, jtype, ends["parent"], ends["child"], xyz, rpy, axis, mimic, **dyn)


def _loop_joint(elem: Element, links: dict, problems: Problems, warnings: list) -> CutJointSpec | None:
    head = _name_and_type(elem, "loop_joint", "loop joint", CUT_JOINT_DOF, problems)
    if head is None:
        return None
    name, jtype, what = head
    firsts = elem.findall("link1")
    seconds = elem.findall("link2")
    if len(firsts) == 2 and not seconds:
        warnings.append(f"{what} has two <link1> children; the second is read as <link2>")
        seconds = [firsts[1]]
        firsts = firsts[:1]
    if len(firsts) > 1 or len(seconds) > 1:
        problems.append(f"{what} has {len(firsts)} <link1> and {len(seconds)} <link2> children: "
                        "it needs exactly one of each")
        return None
    parent, child = elem.findall("parent"), elem.findall("child")
    if not firsts and not seconds and len(parent) == 1 and len(child) == 1:
        # written like a <joint>: <parent link>, <child link>, <origin> in the parent; the joint
        # frame meets the child's own frame when the loop is closed, as a tree joint places it
        origin = elem.find("origin")
        firsts = [{"link": parent[0].get("link"), "xyz": None if origin is None else origin.get("xyz"),
                   "rpy": None if origin is None else origin.get("rpy")}]
        seconds = [{"link": child[0].get("link")}]  # (read with .get, as the elements are)
    if len(firsts) < 1 or len(seconds) < 1:
        problems.append(f"{what} needs a <link1> and a <link2> (or a <parent> and a <child> as a <joint> has)")
        return None
    sides = []
    for tag, e in (("link1", firsts[0]), ("link2", seconds[0])):
        link = e.get("link")
        if not link:
            problems.append(f"{what} <{tag}> has no link attribute")
            return None
        if link not in links:
            problems.append(f"{what} names {tag} {quote(link)}, which is not a link of the file")
            return None
        xyz, rpy = _origin(e, f"{what} <{tag}", problems)
        sides.append((link, xyz, rpy))
    axis = _axis(elem.find("axis"), what, problems)
    axis2 = None
    if jtype == "universal":
        a2 = elem.find("axis2")
        if a2 is None:
            problems.append(f"universal {what} needs an <axis2 xyz> (its second axis, in F2)")
            return None
        axis2 = _axis(a2, what, problems)
    (l1, xyz1, rpy1), (l2, xyz2, rpy2) = sides
    if l1 == l2:
        problems.append(f"{what} connects link {quote(l1)} to itself")
        return None
    extra = _pair_parameters(elem, jtype, what, axis, problems) if jtype in HIGHER_PAIRS else {}
    if extra is None:
        return None
    return CutJointSpec(name, jtype, l1, l2, xyz1, rpy1, xyz2, rpy2, axis, axis2, source="loop_joint", **extra)


def _radius(text: str, what: str, problems: Problems, allow_inf: bool=False):
    """A radius [m]: a positive number, or (a straight line) 'inf' where allowed."""
    if text is None:
        problems.append(f"{what} is missing")
        return None
    if allow_inf and text.strip().lower() in ("inf", "+inf", "infinity"):
        return float("inf")
    value = numbers(text, 1, what, problems, (None,))[0]
    if value is not None and not value > 0:
        problems.append(f"{what} must be positive, got {shorten(text, 40)}")
        return None
    return value


def _pair_parameters(elem: Element, jtype: str, what: str, axis: tuple, problems: Problems) -> dict | None:
    """The parameters of a rolling, gear, contact or helical loop joint, checked."""
    n0 = len(problems)
    out = {}
    ex = np.array([1.0, 0.0, 0.0])
    if jtype in ("rolling", "gear"):
        r = elem.find("rolling")
        if r is None:
            r = elem.find("gear")
        if r is None:
            problems.append(f"{jtype} {what} needs a <{'gear' if jtype == 'gear' else 'rolling'} radius1=... "
                            "radius2=.../> (the two circles; radius1=\"inf\" for a straight line)")
            return None
        r1 = _radius(r.get("radius1"), f"{what} radius1", problems, allow_inf=True)
        r2 = _radius(r.get("radius2"), f"{what} radius2", problems)
        contact = (r.get("contact") or "external").strip().lower()
        if contact not in ("external", "internal"):
            problems.append(f"{what} contact {quote(contact)} is unknown (external or internal)")
        elif contact == "internal" and r1 is not None and r2 is not None and not r2 < r1:
            problems.append(f"{what}: internal contact needs radius2 < radius1 (circle 2 runs inside circle 1), "
                            f"got {r2:g} and {r1:g}")
        elif contact == "internal" and r1 == float("inf"):
            problems.append(f"{what}: a circle cannot run inside a straight line (radius1 inf, contact internal)")
        if r1 is not None and np.isinf(r1) and abs(float(np.dot(axis, ex))) > DEFAULT.geometry:
            problems.append(f"{what}: the line is F1's x axis, so the <axis> (the plane's normal) must be "
                            "perpendicular to it")
        out = {"radius1": r1, "radius2": r2, "contact": contact}
    elif jtype == "contact":
        profiles = []
        for k in (1, 2):
            e = elem.find(f"profile{k}")
            if e is None:
                problems.append(f"contact {what} needs a <profile{k} shape=.../> (circle, line or point)")
                return None
            shape = (e.get("shape") or "").strip().lower()
            if shape not in PROFILE_SHAPES:
                problems.append(f"{what} <profile{k}> has unknown shape {quote(e.get('shape'))} "
                                f"(known: {', '.join(PROFILE_SHAPES)})")
                return None
            radius = _radius(e.get("radius"), f"{what} <profile{k} radius>", problems) if shape == "circle" else None
            if shape == "line" and abs(float(np.dot(axis, ex))) > DEFAULT.geometry:
                problems.append(f"{what}: a line profile is its frame's x axis, so the <axis> (the plane's normal) "
                                "must be perpendicular to it")
            profiles.append((shape, radius))
        shapes = (profiles[0][0], profiles[1][0])
        if shapes in (("line", "line"), ("point", "point")):
            problems.append(f"{what}: profiles {shapes[0]} and {shapes[1]} make no sliding contact "
                            "(two points are a revolute joint, two lines a prismatic one)")
            return None
        contact = (elem.find("profile2").get("contact") or elem.get("contact") or "external").strip().lower()
        if contact not in ("external", "internal"):
            problems.append(f"{what} contact {quote(contact)} is unknown (external or internal)")
        out = {"profile1": profiles[0], "profile2": profiles[1], "contact": contact}
    elif jtype == "helical":
        e = elem.find("pitch")
        if e is None or e.get("lead") is None:
            problems.append(f"helical {what} needs a <pitch lead=\"...\"/> (translation per turn, m)")
            return None
        lead = numbers(e.get("lead"), 1, f"{what} <pitch lead>", problems, (None,))[0]
        if lead is not None and lead == 0:
            problems.append(f"{what} <pitch lead> is 0: a screw with no lead is a revolute joint")
        out = {"lead": lead}
    return None if len(problems) > n0 else out


def check_sizes(path: str | Path, links: int, joints: int, loop_joints: int, coordinates: int | None = None) -> None:
    """Refuse a file beyond :data:`~screwkin.files.description.LIMITS` (before Pinocchio builds anything)."""
    for count, limit, what in ((links, LIMITS.links, "links"), (joints, LIMITS.joints, "joints"),
                               (loop_joints, LIMITS.loop_joints, "loop joints")):
        if count > limit:
            raise MechanismFileError(path, f"the file has {count} {what}; screwkin reads at most {limit} "
                                           "(a limit against runaway files: no real robot comes near it)")
    if coordinates is not None and coordinates > LIMITS.coordinates:
        raise MechanismFileError(
            path, f"the mechanism has {coordinates} moving joint coordinates; screwkin analyses at most "
                  f"{LIMITS.coordinates} (Pinocchio's data for {coordinates} joint coordinates needs about "
                  f"{data_bytes(coordinates) / 1e9:.3g} GB)")


def check_tree(path: str | Path, links: dict, joints: list, problems: Problems) -> None:
    """Record problems that keep the joints from forming one tree over the links."""
    parent_of = {}
    for j in joints:
        if j.child in parent_of:
            problems.append(
                f"link {quote(j.child)} has two parents ({quote(parent_of[j.child][0])} through joint "
                f"{quote(parent_of[j.child][1])} and {quote(j.parent)} through joint {quote(j.name)}); "
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
            f"the links do not form one tree: {len(roots)} links have no parent joint "
            f"({', '.join(quote(r, 40) for r in roots[:5])}{', ...' if len(roots) > 5 else ''})"
        )
    else:
        # every link must reach the root without cycling (links already known to reach it are not walked again)
        # (linear in the number of links: every link is walked once)
        reaches = set(roots)
        for start in links:
            on_path = set()
            link = start
            while link not in reaches:
                if link in on_path:
                    problems.append(f"the joints form a cycle through link {quote(start)}")
                    return
                on_path.add(link)
                link = parent_of[link][0]
            reaches |= on_path


def _coordinates(joints: list) -> int:
    return sum(TREE_JOINT_DOF[j.type] for j in joints)


def read_urdf(path: Path | str, text: str, root: Element | None=None, package_dirs: list | tuple = ()) -> MechanismSpec:
    """Read a URDF file (already loaded as ``text``, and parsed as ``root`` when given)
    into a :class:`MechanismSpec`.  package_dirs: folders searched for ``package://`` meshes."""
    if root is None:
        root = parse_xml_text(text, path)
    if root.tag != "robot":
        raise MechanismFileError(path, f"not a URDF file: the root element is <{shorten(root.tag, 40)}>, "
                                       "expected <robot> (MJCF: <mujoco>, SDF: <sdf>)")
    link_elems, joint_elems, loop_elems = root.findall("link"), root.findall("joint"), root.findall("loop_joint")
    check_sizes(path, len(link_elems), len(joint_elems), len(loop_elems))
    problems = Problems()
    warnings = []
    links = {}
    for elem in link_elems:
        name = elem.get("name")
        if not name:
            problems.append("a <link> has no name")
            continue
        if name in links:
            problems.append(f"link {quote(name)} is defined twice")
            continue
        links[name] = _link(elem, problems)
    joints = []
    seen = set()
    for elem in joint_elems:
        j = _joint(elem, links, problems)
        if j is None:
            continue
        if j.name in seen:
            problems.append(f"joint {quote(j.name)} is defined twice")
        seen.add(j.name)
        joints.append(j)
    problems.fail_if_any(path)
    check_tree(path, links, joints, problems)
    problems.fail_if_any(path)
    check_sizes(path, len(links), len(joints), len(loop_elems), _coordinates(joints))
    cuts = []
    for elem in loop_elems:
        c = _loop_joint(elem, links, problems, warnings)
        if c is not None:
            if c.name in seen:
                problems.append(f"loop joint {quote(c.name)} has the name of another joint")
            seen.add(c.name)
            cuts.append(c)
    couplings = _couplings(joints, problems, warnings)
    transmissions, inputs = read_transmissions(root, joints, {c.name for c in cuts}, warnings,
                                               {c.joint: c.mimics for c in couplings}, numbers)
    targets = _read_targets(root, links, {j.name for j in joints}, problems)
    problems.fail_if_any(path)
    warnings += inertia_warnings(links)
    meshes = []
    warnings += check_meshes(path, root, package_dirs, meshes)
    return MechanismSpec(
        files_read=meshes,
        path=str(path),
        name=root.get("name") or Path(path).stem,
        format="urdf",
        urdf_text=text,
        links=links,
        joints=joints,
        cut_joints=cuts,
        transmissions=transmissions,
        warnings=warnings,
        package_dirs=[str(d) for d in package_dirs or ()],
        couplings=couplings,
        targets=targets,
        inputs=inputs,
    )


_MOVING_1DOF = ("revolute", "continuous", "prismatic")


def _couplings(joints: list, problems: Problems, warnings: list) -> list:
    """The ``<mimic>`` couplings, each resolved to the first joint of its chain (a gear train
    written 'idler mimics input, output mimics idler' couples the output to the input):
    j = m * k + o with k = m' * p + o' gives j = (m m') p + (m o' + o).  A <mimic> that cannot
    couple anything -- on a fixed joint, naming a joint not in the file or a fixed one, naming
    itself, or going round in a circle -- is a warning, and the joint moves on its own (real
    files carry such leftovers: TALOS's reduced models, Alex's hands)."""
    by_name = {j.name: j for j in joints}
    raw = {}
    for j in joints:
        if j.mimic is None:
            continue
        target, mult, off = j.mimic
        why = None
        if j.type not in _MOVING_1DOF:
            why = f"joint {quote(j.name)} is {j.type}: its <mimic> is ignored"
        elif target == j.name:
            why = f"joint {quote(j.name)} mimics itself: the <mimic> is ignored"
        elif target not in by_name:
            why = (f"joint {quote(j.name)} mimics {quote(target)}, which is not a joint of the file: the <mimic> "
                   f"is ignored and {quote(j.name)} moves on its own")
        elif by_name[target].type not in _MOVING_1DOF:
            why = (f"joint {quote(j.name)} mimics {quote(target)}, which is {by_name[target].type}: the <mimic> is "
                   f"ignored and {quote(j.name)} moves on its own")
        if why:
            warnings.append(why)
        else:
            raw[j.name] = (target, mult, off)
    return resolve_chains(raw, lambda name: warnings.append(
        f"the <mimic> couplings of joint {quote(name)} go round in a circle: ignored"))


def _read_targets(root: Element, links: dict, joint_names: set, problems: Problems) -> tuple:
    """The TargetSpec of every <screwkin:target> under <screwkin:targets> of the URDF ``root``;
    a problem recorded (the file refused, as for any element) for an unknown kind, link or
    joint, a missing or implausible number."""
    elems = [t for group in root.findall(f"{{{TARGETS_NS}}}targets") for t in group.findall(f"{{{TARGETS_NS}}}target")]
    if len(elems) > LIMITS.targets:
        problems.append(f"<screwkin:targets> holds {len(elems)} targets; screwkin reads at most {LIMITS.targets}")
        return ()
    out = []
    for k, e in enumerate(elems, 1):
        what = f"<screwkin:target> {k}"
        kind, link, joint = e.get("kind"), e.get("link"), e.get("input")
        if kind not in TARGET_KINDS:
            problems.append(f"{what} has kind {quote(kind or '')}; expected {', '.join(TARGET_KINDS)}")
            continue
        if link not in links:
            problems.append(f"{what} names link {quote(link or '')}, which is not a link of the file")
            continue
        if joint not in joint_names:
            problems.append(f"{what} names input {quote(joint or '')}, which is not a joint of the file")
            continue
        (value,) = numbers(e.get("value"), 1, f"{what} value", problems, (None,), LIMITS.length)
        xyz = numbers(e.get("xyz"), 3, f"{what} xyz", problems, (None,) * 3, LIMITS.length)
        yaw = None
        if kind != "point":
            if e.get("yaw") is None:
                problems.append(f"{what}: a {kind} target needs yaw")
                continue
            (yaw,) = numbers(e.get("yaw"), 1, f"{what} yaw", problems, (None,), LIMITS.angle)
        if value is None or None in xyz or (kind != "point" and yaw is None):
            continue
        out.append(TargetSpec(kind, link, joint, value, xyz, yaw, (e.get("label") or "")[:200]))
    return tuple(out)
