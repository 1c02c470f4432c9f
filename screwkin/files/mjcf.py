"""Reading MuJoCo MJCF models (``<mujoco>`` files): a body tree plus equality constraints.

MJCF writes a closed loop as an open tree of bodies plus an ``<equality>``: ``<connect>``
(a 3-D point joint, here a ``spherical`` cut joint) or ``<weld>`` (6-D, a ``fixed`` one).
The tree is written out as URDF text for Pinocchio's URDF parser, the path every file
takes, with each body's frame exactly where MuJoCo puts it.

Why not Pinocchio's own MJCF reader (``buildModelsAndConstraintsFromMJCF``): it refuses an
equality that names the world explicitly (``body2="world"``: "Model does not have any body
named world"), which MuJoCo accepts and real files use, and it does not give the plain
description (cut joints, couplings, inputs) the rest of screwkin reads.

What is read (docs/format.md, section 4b): ``<compiler angle eulerseq>``, ``<default>``
classes (joint and site attributes; ``childclass``/``class``), every ``<worldbody>``'s bodies
with ``pos`` and one orientation (``quat``, ``axisangle``, ``euler``, ``xyaxes``, ``zaxis``),
their joints (``hinge``, ``slide``, ``ball``, ``free``; ``pos``, ``axis``, ``range``),
``<inertial>``, sites; ``<equality>`` ``connect``, ``weld`` and ``joint`` (linear polycoef);
actuators on joints.  Anything else that shapes the kinematics is refused in one line.
Inertias MuJoCo derives from geoms are not computed: a body without ``<inertial>`` has no mass here.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from ..errors import MechanismFileError, quote, shorten
from ..tolerances import DEFAULT
from .description import LIMITS, Coupling, CutJointSpec, JointSpec, LinkSpec, MechanismSpec
from .urdf import Problems, check_sizes, numbers, unit_axis
from .writer import quoteattr, vector_text
from .xmlsafe import parse_xml_text

__all__ = ["read_mjcf", "quat_matrix", "matrix_quat"]

#: Joint types read, with their URDF stand-in (a ball is a revolute replaced by a spherical joint).
_JOINTS = {"hinge": "revolute", "slide": "prismatic", "ball": "continuous", "free": "floating"}
#: Actuator elements whose ``joint`` is an input.
_ACTUATORS = ("motor", "position", "velocity", "general", "intvelocity", "damper", "cylinder", "muscle")
#: Elements of a body that do not change its kinematics (geoms are noted as geometry).
_BODY_PASSIVE = ("geom", "camera", "light")
#: Top-level sections that do not change the kinematics.
_PASSIVE = ("option", "size", "visual", "statistic", "asset", "contact", "sensor", "keyframe", "custom")


def quat_matrix(q) -> np.ndarray:
    """The rotation matrix of MuJoCo's quaternion (w, x, y, z), normalised (Pinocchio's)."""
    w, x, y, z = (float(v) for v in q)
    return pin.Quaternion(w, x, y, z).normalized().matrix()


def matrix_quat(R) -> tuple:
    """MuJoCo's quaternion (w, x, y, z) of a rotation matrix."""
    q = pin.Quaternion(np.asarray(R, float))
    return (q.w, q.x, q.y, q.z)


def _fmt(v):
    return vector_text(*v)


def _origin(M):
    return f'<origin xyz="{_fmt(M.translation)}" rpy="{_fmt(pin.rpy.matrixToRpy(M.rotation))}"/>'


class _Reader:
    def __init__(self, path, root):
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
        self.defaults = {}
        for d in root.findall("default"):
            self._default(d, "main", {})

    # ---- defaults -------------------------------------------------------------------------
    def _default(self, elem, name, inherited):
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

    def attrs(self, elem, cls):
        """The element's attributes over those of its default class."""
        cls = elem.get("class", cls)
        if cls not in self.defaults and cls != "main":
            self.problems.append(f"<{elem.tag}> names default class {quote(cls)}, which is not defined")
        out = dict(self.defaults.get(cls, {}).get(elem.tag, {}))
        out.update(elem.attrib)
        return out

    # ---- numbers and frames ---------------------------------------------------------------
    def vec(self, text, n, what, default, bound=LIMITS.length, unit="m"):
        return np.array(numbers(text, n, what, self.problems, default, bound, unit), float)

    def angle(self, value):
        return math.radians(value) if self.degree else value

    def rotation(self, a, what) -> np.ndarray:
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
        z = np.asarray(unit_axis(self.vec(a[k], 3, f"{what} zaxis", (0, 0, 1), 1e6, ""), f"{what} zaxis",
                                 self.problems, (0.0, 0.0, 1.0)))
        c = np.cross([0, 0, 1.0], z)
        s = np.linalg.norm(c)
        if s < DEFAULT.zero:
            return np.eye(3) if z[2] > 0 else pin.exp3(np.array([math.pi, 0, 0]))
        return pin.exp3(c / s * math.atan2(s, z[2]))

    def frame(self, a, what) -> pin.SE3:
        return pin.SE3(self.rotation(a, what), self.vec(a.get("pos"), 3, f"{what} pos", (0, 0, 0)))


def read_mjcf(path, text, root=None, package_dirs=()) -> MechanismSpec:
    """Read an MJCF file (already loaded as ``text``, parsed as ``root`` when given)."""
    if root is None:
        root = parse_xml_text(text, path)
    if root.tag != "mujoco":
        raise MechanismFileError(path, f"not an MJCF file: the root element is <{shorten(root.tag, 40)}>")
    r = _Reader(path, root)
    p = r.problems
    for child in root:
        if child.tag in ("include", "extension", "deformable"):
            p.append(f"<{child.tag}> is not supported (write the model in one file, without plugins or flexes)")
        elif child.tag == "tendon" and len(child):
            r.warnings.append("<tendon> elements are not read (a tendon in an <equality> or an actuator is an error)")
        elif child.tag not in _PASSIVE + ("compiler", "default", "worldbody", "equality", "actuator", "tendon"):
            p.append(f"<{shorten(child.tag, 30)}> (under <mujoco>) is not supported")
    bodies = root.findall(".//worldbody//body")
    joints_xml = root.findall(".//worldbody//joint") + root.findall(".//worldbody//freejoint")
    check_sizes(path, len(bodies) + 1, len(joints_xml) + len(bodies), len(root.findall("equality/*")))
    p.fail_if_any(path)

    links = {"world": LinkSpec("world", None, False)}
    world = {"world": pin.SE3.Identity()}  # body -> world pose at qpos0
    joints, out = [], []
    mjoints = {}  # MJCF joint name -> (type, body)
    sites = {}  # site name -> (body, placement in the body)
    replacements = []
    unnamed = [0]
    out_links = []

    def site(elem, body, cls):
        a = r.attrs(elem, cls)
        name = a.get("name")
        if name:
            if name in sites:
                p.append(f"site {quote(name)} is defined twice")
            sites[name] = (body, r.frame(a, f"site {quote(name)}"))

    for ws in root.findall("worldbody"):
        for e in ws:
            if e.tag == "site":
                site(e, "world", "main")
            elif e.tag in ("geom",):
                links["world"].has_geometry = True
            elif e.tag in ("joint", "freejoint"):
                p.append("a joint directly in <worldbody> (MuJoCo refuses it too)")

    def body(elem, parent, cls):
        cls = elem.get("childclass", cls)
        name = elem.get("name")
        if not name:
            unnamed[0] += 1
            name = f"body{unnamed[0]}"
            while name in links:
                name += "_"
        what = f"body {quote(name)}"
        if name in links:
            p.append(f"{what} is defined twice (or is the world)")
            return
        if (elem.get("mocap") or "false") == "true":
            p.append(f"{what} is a mocap body: not supported")
        X = r.frame(elem.attrib, what)
        world[name] = world[parent] * X
        mass, inertial = None, ""
        jlist = []
        for e in elem:
            if e.tag == "inertial":
                mass, inertial = _inertial(r, e, what)
            elif e.tag in ("joint", "freejoint"):
                jlist.append(e)
            elif e.tag == "site":
                site(e, name, cls)
            elif e.tag in _BODY_PASSIVE or e.tag == "body":
                pass
            else:
                p.append(f"{what} has a <{shorten(e.tag, 30)}> element: not supported")
        links[name] = LinkSpec(name, mass, elem.find("geom") is not None)
        out_links.append(f"<link name={quoteattr(name)}>{inertial}</link>")
        prev, prev_pos = parent, None
        for k, e in enumerate(jlist):
            a = {"type": "free"} if e.tag == "freejoint" else r.attrs(e, cls)
            if e.tag == "freejoint" and e.get("name"):
                a["name"] = e.get("name")
            jt = a.get("type", "hinge")
            jn = a.get("name") or f"{name}_joint{k}"
            jw = f"joint {quote(jn)}"
            if jt not in _JOINTS:
                p.append(f"{jw} has unknown type {quote(jt)} (known: {', '.join(_JOINTS)})")
                continue
            if jn in mjoints:
                p.append(f"{jw} is defined twice")
                continue
            if jt == "free" and (parent != "world" or len(jlist) > 1):
                p.append(f"{jw} is free but not the only joint of a top-level body (MuJoCo refuses it too)")
            ref = float(numbers(a.get("ref"), 1, f"{jw} ref", p, (0.0,))[0])
            if ref != 0:
                p.append(f"{jw} has ref={shorten(a['ref'], 20)}: a reference position other than 0 is not supported")
            pos = np.zeros(3) if jt == "free" else r.vec(a.get("pos"), 3, f"{jw} pos", (0, 0, 0))
            axis = (1.0, 0.0, 0.0) if jt in ("free", "ball") else tuple(unit_axis(
                r.vec(a.get("axis"), 3, f"{jw} axis", (0, 0, 1), 1e6, ""), jw, p, (0.0, 0.0, 1.0)))
            mjoints[jn] = (jt, name)
            origin = X * pin.SE3(np.eye(3), pos) if prev_pos is None else pin.SE3(np.eye(3), pos - prev_pos)
            last = k == len(jlist) - 1
            child = name if last and not np.any(pos) else f"{name}__{jn}"
            if child != name:
                links[child] = LinkSpec(child, None, False)
                out_links.append(f"<link name={quoteattr(child)}/>")
            utype = _JOINTS[jt]
            limit = ""
            if jt in ("hinge", "slide"):
                rng = a.get("range")
                limited = a.get("limited", "auto")
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
                replacements.append((jn, "SPHERICAL"))
                if a.get("range") is not None and a.get("limited", "auto") != "false":
                    r.warnings.append(f"{jw} (ball) has a range: its cone of rotation is not read (unlimited here)")
            out.append(f'<joint name={quoteattr(jn)} type="{utype}"><parent link={quoteattr(prev)}/>'
                       f'<child link={quoteattr(child)}/>{_origin(origin)}<axis xyz="{_fmt(axis)}"/>{limit}</joint>')
            joints.append(JointSpec(jn, utype, prev, child, tuple(origin.translation),
                                    tuple(pin.rpy.matrixToRpy(origin.rotation)), axis))
            prev, prev_pos = child, pos
        if prev != name:  # no joint (welded to the parent), or the body's frame is off the last joint's anchor
            jn = f"{name}__fixed"
            origin = X if prev_pos is None else pin.SE3(np.eye(3), -prev_pos)
            out.append(f'<joint name={quoteattr(jn)} type="fixed"><parent link={quoteattr(prev)}/>'
                       f'<child link={quoteattr(name)}/>{_origin(origin)}</joint>')
            joints.append(JointSpec(jn, "fixed", prev, name, tuple(origin.translation),
                                    tuple(pin.rpy.matrixToRpy(origin.rotation))))
        for e in elem.findall("body"):
            body(e, name, cls)

    for ws in root.findall("worldbody"):
        for e in ws.findall("body"):
            body(e, "world", "main")
    for ws in root.findall("worldbody"):
        for e in ws:
            if e.tag not in ("body", "site") + _BODY_PASSIVE:
                p.append(f"<worldbody> has a <{shorten(e.tag, 30)}> element: not supported")
    p.fail_if_any(path)
    cuts, couplings = _equalities(r, world, sites, mjoints)
    transmissions = _actuators(r, mjoints, {c.joint: c.mimics for c in couplings})
    p.fail_if_any(path)
    no_inertia = [n for n, lk in links.items() if n != "world" and lk.has_geometry and lk.mass is None]
    if no_inertia:
        r.warnings.append(f"{len(no_inertia)} bodies ({', '.join(quote(n, 30) for n in no_inertia[:3])}"
                          f"{', ...' if len(no_inertia) > 3 else ''}) have geoms but no <inertial>: MuJoCo derives "
                          "their inertia from the geoms, screwkin does not (no mass here)")
    name = root.get("model") or "mjcf_model"
    urdf = "\n".join([f"<robot name={quoteattr(name)}>", '<link name="world"/>', *out_links, *out, "</robot>"])
    return MechanismSpec(path=str(path), name=name, format="mjcf", urdf_text=urdf, links=links, joints=joints,
                         cut_joints=cuts, transmissions=transmissions, warnings=r.warnings,
                         replacements=replacements, couplings=couplings,
                         package_dirs=[str(d) for d in package_dirs or ()])


def _inertial(r, e, what):
    """(mass, URDF <inertial>) of an MJCF ``<inertial pos quat mass diaginertia|fullinertia>``."""
    p = r.problems
    a = e.attrib
    mass = numbers(a.get("mass"), 1, f"{what} <inertial mass>", p, (0.0,), LIMITS.mass, "kg", low=0.0)[0]
    M = r.frame(a, f"{what} <inertial>")
    if a.get("fullinertia") is not None:
        if a.get("quat") is not None:
            p.append(f"{what} <inertial> gives both fullinertia and an orientation")
        xx, yy, zz, xy, xz, yz = numbers(a["fullinertia"], 6, f"{what} <inertial fullinertia>", p, (0,) * 6,
                                         LIMITS.inertia, "kg m^2")
    else:
        xx, yy, zz = numbers(a.get("diaginertia") or "?", 3, f"{what} <inertial diaginertia>", p, (0,) * 3,
                             LIMITS.inertia, "kg m^2", low=0.0)
        xy = xz = yz = 0.0
    return mass, (f"<inertial>{_origin(M)}<mass value=\"{mass:.17g}\"/><inertia ixx=\"{xx:.17g}\" "
                  f"iyy=\"{yy:.17g}\" izz=\"{zz:.17g}\" ixy=\"{xy:.17g}\" ixz=\"{xz:.17g}\" iyz=\"{yz:.17g}\"/>"
                  "</inertial>")


def _equalities(r, world, sites, mjoints):
    """Cut joints (connect: spherical, weld: fixed) and couplings (joint) of every <equality>."""
    p = r.problems
    cuts, couplings, names = [], [], set()
    count = {"connect": 0, "weld": 0, "joint": 0}
    for eq in r.root.findall("equality"):
        for e in eq:
            tag = e.tag
            a = r.attrs(e, "main")
            if tag not in count:
                p.append(f"<equality><{shorten(tag, 30)}> is not supported (connect, weld and joint are)")
                continue
            count[tag] += 1
            name = a.get("name") or f"{tag}{count[tag]}"
            what = f"<equality><{tag}> {quote(name)}"
            if name in names or name in mjoints:
                p.append(f"{what}: the name is used twice")
                continue
            names.add(name)
            if a.get("active", "true") == "false":
                r.warnings.append(f"{what} is inactive (active=\"false\"): not read")
                continue
            if tag == "joint":
                c = _joint_equality(r, a, what, mjoints)
                if c is not None:
                    couplings.append(c)
                continue
            ends = _ends(r, a, what, world, sites)
            if ends is None:
                continue
            (b1, S1), (b2, S2), by_site = ends
            if tag == "connect":
                if by_site:  # the two sites' origins coincide
                    F1, F2 = pin.SE3(np.eye(3), S1.translation), pin.SE3(np.eye(3), S2.translation)
                else:  # anchor on body1; the point of body2 there at qpos0
                    anchor = r.vec(a.get("anchor") or "?", 3, f"{what} anchor", (0, 0, 0))
                    F1 = pin.SE3(np.eye(3), anchor)
                    F2 = pin.SE3(np.eye(3), (world[b2].inverse() * world[b1]).act(anchor))
                ctype = "spherical"
            else:
                if by_site:  # the two sites' frames coincide
                    F1, F2 = S1, S2
                else:
                    anchor = r.vec(a.get("anchor"), 3, f"{what} anchor", (0, 0, 0))
                    F2 = pin.SE3(np.eye(3), anchor)
                    rel = r.vec(a.get("relpose"), 7, f"{what} relpose", (0, 1, 0, 0, 0, 0, 0))
                    if np.any(rel[3:]):  # body2's pose in body1
                        X12 = pin.SE3(quat_matrix(rel[3:]), rel[:3])
                    else:  # as at qpos0
                        X12 = world[b1].inverse() * world[b2]
                    F1 = X12 * F2
                ctype = "fixed"
            cuts.append(CutJointSpec(name, ctype, b1, b2, tuple(F1.translation),
                                     tuple(pin.rpy.matrixToRpy(F1.rotation)), tuple(F2.translation),
                                     tuple(pin.rpy.matrixToRpy(F2.rotation)), source="mjcf"))
    return cuts, couplings


def _ends(r, a, what, world, sites):
    """((body1, S1), (body2, S2), by_site) of a connect or weld; body2 omitted or "world" is the world."""
    p = r.problems
    if a.get("site1") or a.get("site2"):
        out = []
        for k in ("site1", "site2"):
            s = a.get(k)
            if s not in sites:
                p.append(f"{what} {k} {quote(s)} is not a site of the file")
                return None
            out.append(sites[s])
        b1, b2 = out[0][0], out[1][0]
        res = (out[0], out[1], True)
    else:
        b1, b2 = a.get("body1"), a.get("body2") or "world"
        for k, b in (("body1", b1), ("body2", b2)):
            if b not in world:  # a body of the file (not one of the links made for its joints)
                p.append(f"{what} {k} {quote(b)} is not a body of the file")
                return None
        res = ((b1, None), (b2, None), False)
    if b1 == b2:
        p.append(f"{what} connects body {quote(b1)} to itself")
        return None
    return res


def _joint_equality(r, a, what, mjoints):
    p = r.problems
    j1, j2 = a.get("joint1"), a.get("joint2")
    if not j2:
        p.append(f"{what} has no joint2: locking a joint at a value is not supported")
        return None
    for k, j in (("joint1", j1), ("joint2", j2)):
        if j not in mjoints:
            p.append(f"{what} {k} {quote(j)} is not a joint of the file")
            return None
        if mjoints[j][0] not in ("hinge", "slide"):
            p.append(f"{what} {k} {quote(j)} is a {mjoints[j][0]} joint: only hinge and slide joints can be coupled")
            return None
    c = numbers(a.get("polycoef"), 5, f"{what} polycoef", p, (0, 1, 0, 0, 0), 1e9, "")
    if any(c[2:]):
        p.append(f"{what} polycoef {quote(a.get('polycoef'))} is not linear: only joint1 = a0 + a1 joint2 "
                 "is supported")
        return None
    if j1 == j2:
        p.append(f"{what} couples joint {quote(j1)} to itself")
        return None
    return Coupling(j1, j2, float(c[1]), float(c[0]))


def _actuators(r, mjoints, mimics):
    """The joints driven by actuators, in file order."""
    p = r.problems
    names = []
    for section in r.root.findall("actuator"):
        for e in section:
            a = r.attrs(e, "main")
            what = f"actuator {quote(a.get('name') or e.tag)}"
            if e.tag not in _ACTUATORS:
                p.append(f"{what}: <actuator><{shorten(e.tag, 30)}> is not supported")
                continue
            j = a.get("joint") or a.get("jointinparent")
            if not j:
                other = next((k for k in ("tendon", "site", "body", "cranksite") if a.get(k)), "nothing")
                p.append(f"{what} acts on a {other}, not a joint: not supported (screwkin's inputs are joints)")
                continue
            if j not in mjoints:
                p.append(f"{what} names joint {quote(j)}, which is not in the file")
            elif j in mimics:
                r.warnings.append(f"{what} drives joint {quote(j)}, which is coupled to {quote(mimics[j])}: ignored")
            elif j not in names:
                names.append(j)
    return names
