"""Reading MuJoCo MJCF models (``<mujoco>`` files): a body tree plus equality constraints.

MJCF writes a closed loop as an open tree of bodies plus an ``<equality>``: ``<connect>``
(a 3-D point joint, here a ``spherical`` cut joint) or ``<weld>`` (6-D, a ``fixed`` one).
The tree is written out as URDF text for Pinocchio's URDF parser, the path every file
takes, with each body's frame exactly where MuJoCo puts it.

Why not Pinocchio's own MJCF reader (``buildModelsAndConstraintsFromMJCF``): it refuses an
equality that names the world explicitly (``body2="world"``: "Model does not have any body
named world"), which MuJoCo accepts and real files use, and it does not give the plain
description (cut joints, couplings, inputs) the rest of screwkin reads.

What is read (docs/format.md, section 4b): ``<include>`` (mjcf_include), ``<compiler angle eulerseq
autolimits inertiafromgeom inertiagrouprange>``, ``<default>`` classes (``childclass``/``class``), every
``<worldbody>``'s bodies and ``<frame>``s with ``pos`` and one orientation (``quat``, ``axisangle``,
``euler``, ``xyaxes``, ``zaxis``), their joints (``hinge``, ``slide``, ``ball``, ``free``; ``pos``,
``axis``, ``range``, ``limited``, ``ref``: the joint's value where the file draws the body, so a joint's
value is MuJoCo's qpos; ``armature``, ``damping``, ``frictionloss``, a hinge's or slide's
``stiffness`` and ``springref``: kept for dynamics and exports), ``<inertial>``
(checked as MuJoCo checks it) or, without one, the mass and inertia of the body's geoms as MuJoCo
computes them (mjcf_inertia; meshes are not computed, and said), sites; ``<equality>`` (mjcf_equality); actuators and fixed tendons (mjcf_transmission).  Anything else
that shapes the kinematics is refused in one line; what is read and not used (``springdamper``, a
ball's or free joint's spring) is said once.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ..errors import MechanismFileError, quote, shorten
from ..tolerances import DEFAULT
from .description import JOINT_DYNAMICS, LIMITS, JointSpec, LinkSpec, MechanismSpec, resolve_chains
from .mjcf_equality import quat_matrix, read_equalities
from .mjcf_include import expand_includes
from .inertia import inertia_problem
from .mjcf_inertia import DEFAULT_DENSITY, SOLIDS, body_inertia, geom_inertia, geom_volume
from .mjcf_transmission import ACTUATORS, read_actuators, read_tendons
from .urdf import Problems, check_sizes, numbers, unit_axis
from .writer import origin_text, quoteattr, vector_text
from .xmlsafe import parse_xml_text

__all__ = ["read_mjcf"]

if TYPE_CHECKING:
    from xml.etree.ElementTree import Element

    #: An element with its placement in its body and its class.
    _Placed = tuple[Element, pin.SE3, str]

#: Joint types read, with their URDF stand-in (a ball is a revolute replaced by a spherical joint).
_JOINTS = {"hinge": "revolute", "slide": "prismatic", "ball": "continuous", "free": "floating"}
#: Elements of a body that do not change its kinematics (geoms give its mass when it has no <inertial>).
_BODY_PASSIVE = ("geom", "camera", "light")
#: MuJoCo's ``limited`` keywords.
_LIMITED = ("true", "false", "auto")
#: Top-level sections that do not change the kinematics.
_PASSIVE = ("option", "size", "visual", "statistic", "asset", "contact", "sensor", "keyframe", "custom", "extension")


class _Reader:
    def __init__(self, path: Path, root: Element) -> None:
        self.path, self.root = path, root
        self.problems = Problems()
        self.warnings = []
        comp = {}
        for c in root.findall("compiler"):
            comp.update(c.attrib)
        angle = comp.get("angle", "degree")
        if angle not in ("degree", "radian"):
            self.problems.append(f"<compiler angle={quote(angle)}> must be degree or radian")
        self.degree = angle == "degree"
        self.eulerseq = comp.get("eulerseq", "xyz")
        if len(self.eulerseq) != 3 or any(ch not in "xyzXYZ" for ch in self.eulerseq):
            self.problems.append(f"<compiler eulerseq={quote(self.eulerseq)}> must be three of x, y, z, X, Y, Z")
            self.eulerseq = "xyz"
        if comp.get("coordinate", "local") != "local":
            self.problems.append("<compiler coordinate=\"global\"> is not supported (MuJoCo 3 removed it too)")
        self.autolimits = comp.get("autolimits", "true") == "true"
        self.fromgeom = comp.get("inertiafromgeom", "auto")
        if self.fromgeom not in ("auto", "true", "false"):
            self.problems.append(f"<compiler inertiafromgeom={quote(self.fromgeom)}> must be auto, true or false")
        self.groups = numbers(comp.get("inertiagrouprange"), 2, "<compiler inertiagrouprange>", self.problems,
                              (0, 5), 1e6, "")
        unused = [k for k in ("boundmass", "boundinertia", "settotalmass", "balanceinertia") if k in comp
                  and comp[k] not in ("0", "-1", "false")]
        if unused:
            self.warnings.append(f"<compiler {' '.join(unused)}> is not applied: the masses and inertias here are "
                                 "the file's, before MuJoCo's adjustment")
        self.defaults = {}
        for d in root.findall("default"):
            self._default(d, "main", {})

    # ---- defaults -------------------------------------------------------------------------
    def _default(self, elem: Element, name: str, inherited: dict) -> None:
        own = {tag: dict(attrs) for tag, attrs in inherited.items()}
        for child in elem:
            if child.tag == "default":
                continue
            own.setdefault(child.tag, {}).update(child.attrib)
        name = elem.get("class", name)
        self.defaults[name] = own
        for child in elem.findall("default"):
            if not child.get("class"):
                self.problems.append("a nested <default> has no class")
                continue
            self._default(child, child.get("class"), own)

    def attrs(self, elem: Element, cls) -> dict:
        """The element's attributes over those of its default class."""
        cls = elem.get("class", cls)
        if cls not in self.defaults and cls != "main":
            self.problems.append(f"<{elem.tag}> names default class {quote(cls)}, which is not defined")
        out = dict(self.defaults.get(cls, {}).get(elem.tag, {}))
        out.update(elem.attrib)
        return out

    def actuator_attrs(self, elem: Element) -> dict:
        """An actuator's attributes over its class's: MuJoCo's actuator shortcuts share one default."""
        cls = elem.get("class", "main")
        if cls not in self.defaults and cls != "main":
            self.problems.append(f"<{elem.tag}> names default class {quote(cls)}, which is not defined")
        out = {}
        for tag in ACTUATORS:
            out.update(self.defaults.get(cls, {}).get(tag, {}))
        out.update(elem.attrib)
        return out

    # ---- numbers and frames ---------------------------------------------------------------
    def vec(self, text: str, n: int, what: str, default: tuple, bound: float=LIMITS.length, unit: str="m") -> np.ndarray:
        return np.array(numbers(text, n, what, self.problems, default, bound, unit), float)

    def angle(self, value: float) -> float:
        return math.radians(value) if self.degree else value

    def rotation(self, a: dict, what: str) -> np.ndarray:
        given = [k for k in ("quat", "axisangle", "euler", "xyaxes", "zaxis") if a.get(k) is not None]
        if len(given) > 1:
            self.problems.append(f"{what} gives more than one orientation ({', '.join(given)})")
            return np.eye(3)
        if not given:
            return np.eye(3)
        k = given[0]
        n0 = len(self.problems)
        if k == "quat":
            q = self.vec(a[k], 4, f"{what} quat", (1, 0, 0, 0), 1e6, "")
            if len(self.problems) > n0 or not np.linalg.norm(q) > DEFAULT.zero:
                if len(self.problems) == n0:
                    self.problems.append(f"{what} quat is zero")
                return np.eye(3)
            return quat_matrix(q)
        if k == "axisangle":
            v = self.vec(a[k], 4, f"{what} axisangle", (1, 0, 0, 0), LIMITS.angle, "")
            axis = unit_axis(v[:3], f"{what} axisangle", self.problems)
            return pin.exp3(np.asarray(axis) * self.angle(v[3]))
        if k == "euler":
            e = self.vec(a[k], 3, f"{what} euler", (0, 0, 0), LIMITS.angle, "")
            R = np.eye(3)
            for ch, ang in zip(self.eulerseq, e):
                Ri = pin.exp3(np.eye(3)["xyz".index(ch.lower())] * self.angle(ang))
                R = R @ Ri if ch.islower() else Ri @ R  # lower case: about the moving axes
            return R
        if k == "xyaxes":
            v = self.vec(a[k], 6, f"{what} xyaxes", (1, 0, 0, 0, 1, 0), 1e6, "")
            x = np.asarray(unit_axis(v[:3], f"{what} xyaxes", self.problems))
            y = v[3:] - (v[3:] @ x) * x
            if not np.linalg.norm(y) > DEFAULT.equal:
                self.problems.append(f"{what} xyaxes: the two axes are parallel")
                return np.eye(3)
            y /= np.linalg.norm(y)
            return np.column_stack([x, y, np.cross(x, y)])
        return _z_to(unit_axis(self.vec(a[k], 3, f"{what} zaxis", (0, 0, 1), 1e6, ""), f"{what} zaxis",
                               self.problems, (0.0, 0.0, 1.0)))

    def content(self, elem: Element, cls) -> list:
        """(child, T, class) of every child of a body (or <worldbody>) with its <frame>s opened: T the
        frames' placement in the body, class the frames' childclass over ``cls``."""
        out = []

        def walk(e: Element, T: pin.SE3, c: str | None, depth: int) -> None:
            for child in e:
                if child.tag == "frame":
                    if depth > LIMITS.elements:  # pragma: no cover - the element count bounds it first
                        break
                    walk(child, T * self.frame(child.attrib, "<frame>"), child.get("childclass", c), depth + 1)
                else:
                    out.append((child, T, c))

        walk(elem, pin.SE3.Identity(), cls, 0)
        return out

    def frame(self, a: dict, what: str) -> pin.SE3:
        return pin.SE3(self.rotation(a, what), self.vec(a.get("pos"), 3, f"{what} pos", (0, 0, 0)))


def _check_sections(root: Element, path: str | Path, r: _Reader) -> None:
    """Refuse the top-level sections that are not read and a file too large to read."""
    p = r.problems
    for child in root:
        if child.tag == "deformable":
            p.append(f"<{child.tag}> is not supported (flexes and skins are not rigid bodies)")
        elif child.tag not in _PASSIVE + ("compiler", "default", "worldbody", "equality", "actuator", "tendon"):
            p.append(f"<{shorten(str(child.tag), 30)}> (under <mujoco>) is not supported")
    bodies = root.findall(".//worldbody//body")
    joints_xml = root.findall(".//worldbody//joint") + root.findall(".//worldbody//freejoint")
    check_sizes(path, len(bodies) + 1, len(joints_xml) + len(bodies), len(root.findall("equality/*")))
    p.fail_if_any(path)


class _Tree:
    """The body tree of an MJCF file, written out as URDF links and joints as it is read."""

    def __init__(self, r: _Reader) -> None:
        self.r, self.p = r, r.problems
        self.links = {"world": LinkSpec("world", None, False)}
        self.world = {"world": pin.SE3.Identity()}  # body -> world pose at qpos0
        self.joints: list[JointSpec] = []
        self.out: list[str] = []  # the URDF <joint>s
        self.out_links: list[str] = []  # the URDF <link>s
        self.mjoints: dict[str, tuple[str, str]] = {}  # MJCF joint name -> (type, body)
        self.sites: dict[str, tuple[str, pin.SE3]] = {}  # site name -> (body, placement in the body)
        self.replacements: list[tuple[str, str]] = []
        self.reference: dict[str, float] = {}  # joint -> ref (its value at qpos0), when not 0
        self.unnamed = 0
        self.unread: dict[str, list[str]] = {"springref": [], "mesh": [], "extra numbers": []}

    def read(self, root: Element) -> None:
        """Read every <worldbody>: its own elements first, then its bodies, depth first."""
        for ws in root.findall("worldbody"):
            for e, T, cls in self.r.content(ws, "main"):
                if e.tag == "site":
                    self.site(e, "world", cls, T)
                elif e.tag == "geom":
                    self.links["world"].has_geometry = True
                elif e.tag in ("joint", "freejoint"):
                    self.p.append("a joint directly in <worldbody> (MuJoCo refuses it too)")
                elif e.tag == "body":
                    pass
                elif e.tag not in _BODY_PASSIVE:
                    self.p.append(f"<worldbody> has a <{shorten(str(e.tag), 30)}> element: not supported")
        for ws in root.findall("worldbody"):
            for e, T, cls in self.r.content(ws, "main"):
                if e.tag == "body":
                    self.body(e, "world", cls, T)

    def site(self, elem: Element, body: str, cls: str, T: pin.SE3) -> None:
        a = self.r.attrs(elem, cls)
        name = a.get("name")
        if name:
            if name in self.sites:
                self.p.append(f"site {quote(name)} is defined twice")
            self.sites[name] = (body, T * self.r.frame(a, f"site {quote(name)}"))

    def _name(self, elem: Element) -> str:
        """The body's name, or a new one for an unnamed body."""
        name = elem.get("name")
        if not name:
            self.unnamed += 1
            name = f"body{self.unnamed}"
            while name in self.links:
                name += "_"
        return name

    def body(self, elem: Element, parent: str, cls: str, T: pin.SE3) -> None:
        """Read a body, its joints to ``parent`` and (depth first) its child bodies."""
        cls = elem.get("childclass", cls)
        name = self._name(elem)
        what = f"body {quote(name)}"
        if name in self.links:
            self.p.append(f"{what} is defined twice (or is the world)")
            return
        if (elem.get("mocap") or "false") == "true":
            if parent != "world" or elem.find("joint") is not None or elem.find("freejoint") is not None:
                self.p.append(f"{what} is a mocap body that is not a jointless child of the world (MuJoCo refuses "
                              "it too)")
            self.r.warnings.append(f"{what} is a mocap body (moved by the simulation's data, not by joints): "
                                   "fixed to the world here, where the file draws it")
        X = T * self.r.frame(elem.attrib, what)
        self.world[name] = self.world[parent] * X
        inertial, jlist, geoms, kids = self._content(elem, cls, name, what)
        self._link(name, what, inertial, geoms)
        prev, prev_pos = parent, None
        for k, (e, Te, ecls) in enumerate(jlist):
            done = self.joint(k, e, Te, ecls, name, parent, X, len(jlist), prev, prev_pos)
            if done is not None:
                prev, prev_pos = done
        if prev != name:  # no joint (welded to the parent), or the body's frame is off the last joint's anchor
            jn = f"{name}__fixed"
            origin = X if prev_pos is None else pin.SE3(np.eye(3), -prev_pos)
            self.out.append(f'<joint name={quoteattr(jn)} type="fixed"><parent link={quoteattr(prev)}/>'
                            f'<child link={quoteattr(name)}/>{origin_text(origin)}</joint>')
            self.joints.append(JointSpec(jn, "fixed", prev, name, tuple(origin.translation),
                                         tuple(pin.rpy.matrixToRpy(origin.rotation))))
        for e, Te, ecls in kids:
            self.body(e, name, ecls, Te)

    def _content(self, elem: Element, cls: str, name: str, what: str) -> tuple[
            Element | None, list[_Placed], list[_Placed], list[_Placed]]:
        """(<inertial>, joints, geoms, child bodies) of a body, its sites read on the way."""
        inertial, jlist, geoms, kids = None, [], [], []
        for e, Te, ecls in self.r.content(elem, cls):
            if e.tag == "inertial":
                inertial = e
            elif e.tag in ("joint", "freejoint"):
                jlist.append((e, Te, ecls))
            elif e.tag == "site":
                self.site(e, name, ecls, Te)
            elif e.tag == "geom":
                geoms.append((e, Te, ecls))
            elif e.tag == "body":
                kids.append((e, Te, ecls))
            elif e.tag not in _BODY_PASSIVE:
                self.p.append(f"{what} has a <{shorten(str(e.tag), 30)}> element: not supported")
        return inertial, jlist, geoms, kids

    def _link(self, name: str, what: str, inertial: Element | None, geoms: list[_Placed]) -> None:
        """The body's link, with its mass from its <inertial> or its geoms."""
        r = self.r
        mass, inertia_xml = None, ""
        if inertial is not None and r.fromgeom != "true":
            mass, inertia_xml = _inertial(r, inertial, what)
        elif r.fromgeom != "false" and geoms:
            mass, inertia_xml, meshes = _geom_inertial(r, geoms, what)
            if meshes:
                self.unread["mesh"].append(name)
        self.links[name] = LinkSpec(name, mass, bool(geoms))
        self.out_links.append(f"<link name={quoteattr(name)}>{inertia_xml}</link>")

    def joint(self, k: int, e: Element, Te: pin.SE3, ecls: str, name: str, parent: str, X: pin.SE3, n: int,
              prev: str, prev_pos: np.ndarray | None) -> tuple[str, np.ndarray] | None:
        """Read the ``k``-th of the ``n`` joints of body ``name`` (placed at ``X`` in ``parent``), after the link
        ``prev`` at ``prev_pos``: (its child link, its position), or None when it is refused."""
        r, p = self.r, self.p
        a = {"type": "free"} if e.tag == "freejoint" else r.attrs(e, ecls)
        if e.tag == "freejoint" and e.get("name"):
            a["name"] = e.get("name")
        jt = a.get("type", "hinge")
        jn = a.get("name") or f"{name}_joint{k}"
        jw = f"joint {quote(jn)}"
        if jt not in _JOINTS:
            p.append(f"{jw} has unknown type {quote(jt)} (known: {', '.join(_JOINTS)})")
            return None
        if jn in self.mjoints:
            p.append(f"{jw} is defined twice")
            return None
        if jt == "free" and (parent != "world" or n > 1):
            p.append(f"{jw} is free but not the only joint of a top-level body (MuJoCo refuses it too)")
        pos = np.zeros(3) if jt == "free" else Te.act(r.vec(a.get("pos"), 3, f"{jw} pos", (0, 0, 0)))
        axis = (1.0, 0.0, 0.0) if jt in ("free", "ball") else tuple(unit_axis(
            Te.rotation @ r.vec(a.get("axis"), 3, f"{jw} axis", (0, 0, 1), 1e6, ""), jw, p, (0.0, 0.0, 1.0)))
        ref = 0.0
        if jt in ("hinge", "slide"):
            ref = float(numbers(a.get("ref"), 1, f"{jw} ref", p, (0.0,), LIMITS.length if jt == "slide"
                                else LIMITS.angle, "m" if jt == "slide" else "")[0])
            ref = r.angle(ref) if jt == "hinge" else ref
            if ref:
                self.reference[jn] = ref
        dyn = self._dynamics(a, jt, jn, jw)
        self.mjoints[jn] = (jt, name)
        origin = X * pin.SE3(np.eye(3), pos) if prev_pos is None else pin.SE3(np.eye(3), pos - prev_pos)
        if ref:  # the body as written is the joint at ref: its zero is -ref from there
            shift = pin.exp3(np.asarray(axis) * -ref) if jt == "hinge" else np.eye(3)
            origin = origin * pin.SE3(shift, np.zeros(3) if jt == "hinge" else -ref * np.asarray(axis))
        last = k == n - 1
        child = name if last and not np.any(pos) else f"{name}__{jn}"
        if child != name:
            self.links[child] = LinkSpec(child, None, False)
            self.out_links.append(f"<link name={quoteattr(child)}/>")
        utype, limit = self._limit(a, jt, jn, jw)
        self.out.append(f'<joint name={quoteattr(jn)} type="{utype}"><parent link={quoteattr(prev)}/>'
                        f'<child link={quoteattr(child)}/>{origin_text(origin)}<axis xyz="{vector_text(*axis)}"/>'
                        f'{limit}</joint>')
        self.joints.append(JointSpec(jn, utype, prev, child, tuple(origin.translation),
                                     tuple(pin.rpy.matrixToRpy(origin.rotation)), axis, **dyn))
        return child, pos

    def _dynamics(self, a: dict[str, str], jt: str, jn: str, jw: str) -> dict[str, float]:
        """A joint's armature, damping, friction loss and (hinge or slide) spring."""
        r, p = self.r, self.p
        dyn = {}
        for key in JOINT_DYNAMICS:  # MuJoCo takes the first number (it may be written as several)
            raw = (a.get(key) or "0").split()
            dyn[key] = float(numbers(raw[0] if raw else "0", 1, f"{jw} {key}", p, (0.0,), 1e9, "")[0])
            if len(raw) > 1:
                self.unread["extra numbers"].append(f"{jn} {key}")
        if jt in ("hinge", "slide"):  # a spring towards springref (qpos; a hinge's in the compiler's angle unit)
            raw = (a.get("stiffness") or "0").split()
            dyn["stiffness"] = float(numbers(raw[0] if raw else "0", 1, f"{jw} stiffness", p, (0.0,), 1e9, "")[0])
            ref_at = float(numbers(a.get("springref"), 1, f"{jw} springref", p, (0.0,), LIMITS.length
                                   if jt == "slide" else LIMITS.angle, "m" if jt == "slide" else "")[0])
            dyn["springref"] = r.angle(ref_at) if jt == "hinge" else ref_at
            if a.get("springdamper") not in (None, "0", "0 0"):
                self.unread["springref"].append(jn)
        elif any(a.get(k) not in (None, "0", "0 0") for k in ("stiffness", "springref", "springdamper")):
            self.unread["springref"].append(jn)
        return dyn

    def _limit(self, a: dict[str, str], jt: str, jn: str, jw: str) -> tuple[str, str]:
        """(URDF type, URDF <limit>) of a joint from its range and limited."""
        r, p = self.r, self.p
        utype = _JOINTS[jt]
        limit = ""
        limited = a.get("limited", "auto")
        if limited not in _LIMITED:
            p.append(f"{jw} limited={quote(limited)}: MuJoCo's keywords are true, false and auto")
        if jt in ("hinge", "slide"):
            rng = a.get("range")
            on = limited == "true" or (limited == "auto" and r.autolimits and rng is not None)
            lo, hi = (-1e9, 1e9)
            if on and rng is not None:
                lo, hi = numbers(rng, 2, f"{jw} range", p, (-1e9, 1e9), LIMITS.length if jt == "slide"
                                 else LIMITS.angle, "m" if jt == "slide" else "")
                if jt == "hinge":
                    lo, hi = r.angle(lo), r.angle(hi)
                if lo > hi:
                    p.append(f"{jw} range: lower {lo:g} is above upper {hi:g}")
            elif jt == "hinge":
                utype = "continuous"
            limit = f'<limit lower="{lo:.17g}" upper="{hi:.17g}" effort="0" velocity="0"/>'
        elif jt == "ball":
            self.replacements.append((jn, "SPHERICAL"))
            if a.get("range") is not None and limited != "false":
                r.warnings.append(f"{jw} (ball) has a range: its cone of rotation is not read (unlimited here)")
        return utype, limit

    def unread_warnings(self) -> None:
        """Say once what was read and not used."""
        w, unread = self.r.warnings, self.unread
        if unread["mesh"]:
            n = unread["mesh"]
            w.append(f"{len(n)} bodies ({', '.join(quote(x, 30) for x in n[:3])}{', ...' if len(n) > 3 else ''}) "
                     "have mesh geoms and no <inertial>: MuJoCo computes a mesh's mass and inertia, screwkin "
                     "does not (their mass here is their other geoms')")
        if unread["springref"]:
            n = unread["springref"]
            w.append(f"the springs of {len(n)} joint{'s' if len(n) > 1 else ''} "
                     f"({', '.join(quote(x, 30) for x in n[:3])}{', ...' if len(n) > 3 else ''}) are not read: "
                     "screwkin reads a hinge's or slide's stiffness and springref, not a ball's or free joint's "
                     "spring nor springdamper")
        if unread["extra numbers"]:
            n = unread["extra numbers"]
            w.append(f"{len(n)} joint attributes ({', '.join(quote(x, 40) for x in n[:3])}"
                     f"{', ...' if len(n) > 3 else ''}) give several numbers: the first is read, as MuJoCo reads it")


def _joint_couplings(path: str | Path, r: _Reader, couplings: list) -> list:
    """The <equality><joint> couplings, each joint's chain resolved to a joint that moves on its own."""
    p = r.problems
    chains = {}
    for c in couplings:
        if c.joint in chains:
            p.append(f"joint {quote(c.joint)} is coupled by two <equality><joint> elements: screwkin holds one "
                     "coupling per joint")
        chains[c.joint] = (c.mimics, c.multiplier, c.offset)
    resolved = resolve_chains(chains, lambda name: p.append(
        f"the <equality><joint> couplings of joint {quote(name)} go round in a circle: screwkin holds a coupling "
        "only to a joint that moves on its own"))
    p.fail_if_any(path)
    return resolved


def read_mjcf(path: str | Path, text: str, root: Element | None = None,
              package_dirs: Iterable[str | Path] = ()) -> MechanismSpec:
    """Read an MJCF file (already loaded as ``text``, parsed as ``root`` when given)."""
    if root is None:
        root = parse_xml_text(text, path)
    if root.tag != "mujoco":
        raise MechanismFileError(path, f"not an MJCF file: the root element is <{shorten(root.tag, 40)}>")
    included: list[str] = []
    expand_includes(root, path, included)
    r = _Reader(path, root)
    p = r.problems
    _check_sections(root, path, r)
    tree = _Tree(r)
    tree.read(root)
    p.fail_if_any(path)
    cuts, couplings = read_equalities(r, tree.world, tree.sites, tree.mjoints, tree.reference,
                                      set(tree.mjoints) | set(tree.links))
    couplings = _joint_couplings(path, r, couplings)
    tendons = read_tendons(r, tree.mjoints)
    transmissions, inputs, unused = read_actuators(r, tree.mjoints, tendons, {c.joint: c for c in couplings})
    p.fail_if_any(path)
    if unused:
        r.warnings.append(unused)
    tree.unread_warnings()
    name = root.get("model") or "mjcf_model"
    urdf = "\n".join([f"<robot name={quoteattr(name)}>", '<link name="world"/>', *tree.out_links, *tree.out,
                      "</robot>"])
    return MechanismSpec(path=str(path), name=name, format="mjcf", files_read=included, urdf_text=urdf,
                         links=tree.links, joints=tree.joints, cut_joints=cuts, transmissions=transmissions,
                         warnings=r.warnings, replacements=tree.replacements, couplings=couplings,
                         package_dirs=[str(d) for d in package_dirs or ()], inputs=inputs,
                         reference=tree.reference)


def _inertia_xml(com: np.ndarray, mass: float, I: np.ndarray) -> str:
    return (f"<inertial><origin xyz=\"{vector_text(*com)}\" rpy=\"0 0 0\"/><mass value=\"{mass:.17g}\"/><inertia "
            f"ixx=\"{I[0, 0]:.17g}\" iyy=\"{I[1, 1]:.17g}\" izz=\"{I[2, 2]:.17g}\" ixy=\"{I[0, 1]:.17g}\" "
            f"ixz=\"{I[0, 2]:.17g}\" iyz=\"{I[1, 2]:.17g}\"/></inertial>")


def _geom_inertial(r: _Reader, geoms: list, what: str) -> tuple:
    """(mass, URDF <inertial>, has meshes) of a body from its geoms, as MuJoCo computes them
    (screwkin.files.mjcf_inertia)."""
    p = r.problems
    parts, meshes = [], False
    for k, (e, T, cls) in enumerate(geoms):
        a = r.attrs(e, cls)
        gw = f"{what} geom {quote(a.get('name') or str(k + 1))}"
        kind = a.get("type", "sphere")
        group = numbers(a.get("group"), 1, f"{gw} group", p, (0,), 1e6, "")[0]
        if not _in_range(group, r.groups):
            continue
        if kind in ("plane", "hfield"):
            continue
        if kind not in SOLIDS or a.get("shellinertia", "false") == "true" or a.get("mesh"):
            # a mesh, an sdf, a shell, or a primitive MuJoCo fits to a mesh: MuJoCo integrates it
            meshes = True
            continue
        raw = (a.get("size") or "0").split()
        size = numbers(a.get("size") or "0", len(raw), f"{gw} size", p, (0.0,) * len(raw), LIMITS.length, low=0.0)
        size = list(size) + [0.0] * (3 - len(size))
        M = r.frame(a, gw)
        if a.get("fromto") is not None:
            f = r.vec(a["fromto"], 6, f"{gw} fromto", (0,) * 6)
            d = f[3:] - f[:3]
            half = float(np.linalg.norm(d)) / 2
            if kind in ("capsule", "cylinder"):
                size[1] = half
            elif kind in ("box", "ellipsoid"):
                size[1], size[2] = size[0], half
            M = pin.SE3(_z_to(d), (f[:3] + f[3:]) / 2)
        need = {"sphere": 1, "capsule": 2, "cylinder": 2, "box": 3, "ellipsoid": 3}[kind]
        if not all(x > 0 for x in size[:need]):
            p.append(f"{gw}: a {kind} needs {need} positive size{'s' if need > 1 else ''} (MuJoCo refuses it too)")
            continue
        volume = geom_volume(kind, size)
        if a.get("mass") is not None:
            m = numbers(a["mass"], 1, f"{gw} mass", p, (0.0,), LIMITS.mass, "kg", low=0.0)[0]
        else:
            density = numbers(a.get("density"), 1, f"{gw} density", p, (DEFAULT_DENSITY,), 1e6, "kg/m^3", low=0.0)[0]
            m = density * volume
        if m <= 0:
            continue
        Tm = T * M
        parts.append((m, Tm.translation, Tm.rotation, geom_inertia(kind, size, m)))
    mass, com, I = body_inertia(parts)
    if mass <= 0:
        return None, "", meshes
    return mass, _inertia_xml(com, mass, I), meshes


def _in_range(value: float, bounds: tuple[float, float]) -> bool:
    """Whether ``value`` lies in the closed range ``bounds`` (lo, hi)."""
    return bounds[0] <= value <= bounds[1]


def _z_to(d: np.ndarray) -> np.ndarray:
    """MuJoCo's rotation taking z onto the direction d (the smallest turn; a half turn about x for -z)."""
    d = np.asarray(d, float)
    n = float(np.linalg.norm(d))
    if not n > 0:
        return np.eye(3)
    z = d / n
    c = np.cross([0, 0, 1.0], z)
    s = np.linalg.norm(c)
    if s < DEFAULT.zero:
        return np.eye(3) if z[2] > 0 else pin.exp3(np.array([math.pi, 0, 0]))
    return pin.exp3(c / s * math.atan2(s, z[2]))


def _inertial(r: _Reader, e: Element, what: str) -> tuple:
    """(mass, URDF <inertial>) of an MJCF ``<inertial pos quat mass diaginertia|fullinertia>``, refused
    where MuJoCo refuses it (a negative mass, a tensor no body has)."""
    p = r.problems
    a = e.attrib
    mass = numbers(a.get("mass"), 1, f"{what} <inertial mass>", p, (0.0,), LIMITS.mass, "kg", low=0.0)[0]
    M = r.frame(a, f"{what} <inertial>")
    if a.get("fullinertia") is not None:
        if any(a.get(k) is not None for k in ("quat", "axisangle", "euler", "xyaxes", "zaxis")):
            p.append(f"{what} <inertial> gives both fullinertia and an orientation")
        xx, yy, zz, xy, xz, yz = numbers(a["fullinertia"], 6, f"{what} <inertial fullinertia>", p, (0,) * 6,
                                         LIMITS.inertia, "kg m^2")
    else:
        xx, yy, zz = numbers(a.get("diaginertia") or "?", 3, f"{what} <inertial diaginertia>", p, (0,) * 3,
                             LIMITS.inertia, "kg m^2", low=0.0)
        xy = xz = yz = 0.0
    I = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    why = inertia_problem(mass, I)
    if why:
        p.append(f"{what} <inertial> has {why}")
    I = M.rotation @ I @ M.rotation.T
    return mass, _inertia_xml(M.translation, mass, I)
