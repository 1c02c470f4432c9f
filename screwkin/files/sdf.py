"""Reading SDF models, whose joints may form loops.

The PyPI Pinocchio wheel has no SDF parser, so the joint graph is read here,
cut into a spanning tree (breadth first from the ground) plus cut joints, and
the tree is written out as URDF text for Pinocchio's URDF parser -- the same
path every URDF takes.  Each tree link's frame is put at its joint's frame (as
URDF requires); SDF ``ball`` and ``universal``/``revolute2`` joints in the tree
become three or two revolutes through massless links, i.e. compound joints.

Supported: poses of links relative to the model, joint poses relative to the
child link (SDF defaults), joint axes in the joint frame (or the model frame
with ``use_parent_model_frame`` / ``expressed_in="__model__"``).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ..errors import MechanismFileError, quote, shorten
from .description import LIMITS, CutJointSpec, JointSpec, LinkSpec, MechanismSpec
from .meshes import check_meshes
from .urdf import check_sizes, numbers, unit_axis
from .writer import origin_text, quoteattr, vector_text
from .xmlsafe import parse_xml_text

__all__ = ["read_sdf"]

if TYPE_CHECKING:
    from xml.etree.ElementTree import Element

_TYPES = {"revolute", "continuous", "prismatic", "fixed", "ball", "universal", "revolute2"}
_CUT = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic", "fixed": "fixed",
        "ball": "spherical", "universal": "universal", "revolute2": "universal"}


def _pose(elem, what: str, problems: list) -> pin.SE3:
    if elem is None or not (elem.text or "").strip():
        return pin.SE3.Identity()
    rel = elem.get("relative_to")
    before = len(problems)
    parts = elem.text.split()
    if len(parts) != 6:
        problems.append(f"{what} <pose> {quote(elem.text.strip())} must be 6 finite numbers")
        return pin.SE3.Identity()
    xyz = numbers(" ".join(parts[:3]), 3, f"{what} <pose> x y z", problems, (0, 0, 0), LIMITS.length, "m")
    rpy = numbers(" ".join(parts[3:]), 3, f"{what} <pose> roll pitch yaw", problems, (0, 0, 0), LIMITS.angle, "rad")
    if len(problems) > before:
        return pin.SE3.Identity()
    if rel not in (None, "", "__model__"):
        problems.append(f"{what} <pose relative_to={quote(rel)}> is not supported (only poses relative to the model)")
    return pin.SE3(pin.rpy.rpyToMatrix(np.array(rpy)), np.array(xyz))


def _vec(text: str, what: str, problems: list) -> np.ndarray:
    before = len(problems)
    v = numbers((text or "").strip() or "?", 3, what, problems, (1.0, 0, 0))
    if len(problems) > before:
        return np.array([1.0, 0, 0])
    return np.array(unit_axis(v, what, problems))


def _axis_element(joint, tag: str, name: str, X_joint: pin.SE3, problems: list) -> np.ndarray:
    a = joint.find(tag)
    if a is None:
        return np.array([1.0, 0, 0]) if tag == "axis" else np.array([0, 1.0, 0])
    xyz = a.find("xyz")
    v = _vec(xyz.text if xyz is not None else None, f"joint {quote(name)} <{tag}><xyz>", problems)
    model_frame = (a.findtext("use_parent_model_frame") or "").strip() == "true" or (
        xyz is not None and xyz.get("expressed_in") == "__model__")
    return X_joint.rotation.T @ v if model_frame else v


def _spanning_tree(links: dict, edges: list, ground: str) -> dict:
    """The breadth-first spanning tree from ``ground`` of the graph of ``links`` joined by
    ``edges`` (parent, child) (a multigraph: two joints may join the same links): joint
    index -> (link towards the ground, link away from it), in the order reached; of parallel
    joints the first in the file.  The other joints are the cut joints."""
    import networkx as nx

    graph = nx.MultiGraph()
    graph.add_nodes_from(links)
    for k, (p, c) in enumerate(edges):
        graph.add_edge(p, c, key=k)
    return {min(graph[link][other]): (link, other) for link, other in nx.bfs_edges(graph, ground)}


def _read_links(link_elems: list[Element], problems: list[str]) -> tuple[dict[str, LinkSpec], dict[str, pin.SE3]]:
    """(link name -> its LinkSpec, link name -> its pose in the model) of the <link>s."""
    links, poses = {}, {}
    for e in link_elems:
        name = e.get("name")
        if not name or name in links or name == "world":
            problems.append(f"a <link> has no name, a duplicate name or the reserved name ({quote(name)})")
            continue
        mass = e.findtext("inertial/mass")
        if mass is not None:
            mass = numbers(mass.strip() or "?", 1, f"link {quote(name)} <mass>", problems, (0.0,), LIMITS.mass,
                           "kg", low=0.0)[0]
        links[name] = LinkSpec(name, mass, e.find("visual") is not None or e.find("collision") is not None)
        poses[name] = _pose(e.find("pose"), f"link {quote(name)}", problems)
    return links, poses


def _read_joints(joint_elems: list[Element], links: dict[str, LinkSpec],
                 problems: list[str]) -> list[tuple[str, str, str, str, Element]]:
    """(name, type, parent, child, element) of every well-formed <joint>; what is wrong with the others in
    ``problems``."""
    raw = []
    seen = set()
    for e in joint_elems:
        name, jtype = e.get("name"), e.get("type")
        if not name:
            problems.append("a <joint> has no name")
            continue
        if name in seen:
            problems.append(f"joint {quote(name)} is defined twice")
            continue
        seen.add(name)
        if jtype not in _TYPES:
            problems.append(f"joint {quote(name)} has unknown or unsupported type {quote(jtype)} "
                            f"(supported: {', '.join(sorted(_TYPES))})")
            continue
        parent, child = (e.findtext("parent") or "").strip(), (e.findtext("child") or "").strip()
        bad = False
        for tag, link in (("parent", parent), ("child", child)):
            if link != "world" and link not in links:
                problems.append(f"joint {quote(name)} names {tag} link {quote(link)}, which does not exist")
                bad = True
        if child == "world":
            problems.append(f"joint {quote(name)} has the world as its child")
            bad = True
        if parent == child and not bad:
            problems.append(f"joint {quote(name)} connects link {quote(parent)} to itself")
            bad = True
        if not bad:
            raw.append((name, jtype, parent, child, e))
    return raw


def _tree_joint(n: str, jt: str, parent: str, child: str, origin: pin.SE3, a1: np.ndarray, a2: np.ndarray,
                spec_links: dict[str, LinkSpec], out: list[str], joints: list[JointSpec]) -> None:
    """A joint of the spanning tree (oriented from ``parent`` to ``child``, at ``origin`` in the parent) as URDF
    text and JointSpecs: a ball, universal or revolute2 joint as a chain of revolutes through dummy links."""
    if jt in ("ball", "universal", "revolute2"):
        chain = [np.eye(3)[0], np.eye(3)[1], np.eye(3)[2]] if jt == "ball" else [a1, a2]
        prev = parent
        for i, ax in enumerate(chain):
            nxt = child if i == len(chain) - 1 else f"{n}__dummy{i}"
            if nxt != child:
                spec_links[nxt] = LinkSpec(nxt, None, False)
                out.append(f"<link name={quoteattr(nxt)}/>")
            o = origin_text(origin) if i == 0 else '<origin xyz="0 0 0" rpy="0 0 0"/>'
            jn = f"{n}__{i}"
            out.append(f'<joint name={quoteattr(jn)} type="revolute"><parent link={quoteattr(prev)}/>'
                       f'<child link={quoteattr(nxt)}/>{o}<axis xyz="{vector_text(*ax)}"/>'
                       f'<limit lower="-1e9" upper="1e9" effort="0" velocity="0"/></joint>')
            joints.append(JointSpec(jn, "revolute", prev, nxt, tuple(origin.translation) if i == 0 else (0, 0, 0),
                                    tuple(pin.rpy.matrixToRpy(origin.rotation)) if i == 0 else (0, 0, 0), tuple(ax)))
            prev = nxt
        return
    urdf_type = "revolute" if jt == "continuous" else jt
    limit = '<limit lower="-1e9" upper="1e9" effort="0" velocity="0"/>' if jt != "fixed" else ""
    out.append(f'<joint name={quoteattr(n)} type="{urdf_type}"><parent link={quoteattr(parent)}/>'
               f'<child link={quoteattr(child)}/>{origin_text(origin)}<axis xyz="{vector_text(*a1)}"/>{limit}</joint>')
    joints.append(JointSpec(n, urdf_type, parent, child, tuple(origin.translation),
                            tuple(pin.rpy.matrixToRpy(origin.rotation)), tuple(a1)))


def _link_xml(link: LinkSpec) -> str:
    """A link's URDF text, with its mass (a tiny inertia: the SDF's is not read)."""
    mass = link.mass
    inertial = (f'<inertial><mass value="{mass:.17g}"/><inertia ixx="1e-9" iyy="1e-9" izz="1e-9" '
                f'ixy="0" ixz="0" iyz="0"/></inertial>') if mass else ""
    return f"<link name={quoteattr(link.name)}>{inertial}</link>"


def read_sdf(path: str | Path, text: str, root: Element | None = None,
             package_dirs: Iterable[str | Path] = ()) -> MechanismSpec:
    """Read an SDF file (already loaded as ``text``, parsed as ``root`` when given)."""
    if root is None:
        root = parse_xml_text(text, path)
    if root.tag != "sdf":
        raise MechanismFileError(path, f"not an SDF file: the root element is <{shorten(root.tag, 40)}>")
    model = root.find("model")
    if model is None:
        model = root.find("world/model")
    if model is None:
        raise MechanismFileError(path, "the SDF file has no <model>")
    link_elems, joint_elems = model.findall("link"), model.findall("joint")
    check_sizes(path, len(link_elems), len(joint_elems), 0)
    problems: list[str] = []
    links, poses = _read_links(link_elems, problems)
    raw = _read_joints(joint_elems, links, problems)
    if problems:
        raise MechanismFileError(path, problems)
    if any(p == "world" for _, _, p, _, _ in raw):
        links = {"world": LinkSpec("world", None, False), **links}
        poses["world"] = pin.SE3.Identity()
    ground = "world" if "world" in links else next(iter(links), None)
    if ground is None:
        raise MechanismFileError(path, "the model has no links")
    # world pose of every joint frame (SDF: joint pose relative to the child link)
    joint_pose = {n: poses[c] * _pose(e.find("pose"), f"joint {quote(n)}", problems) for n, _, _, c, e in raw}
    axes = {n: (_axis_element(e, "axis", n, joint_pose[n], problems), _axis_element(e, "axis2", n, joint_pose[n], problems))
            for n, _, _, _, e in raw}
    if problems:
        raise MechanismFileError(path, problems)
    tree = _spanning_tree(links, [(p, c) for _, _, p, c, _ in raw], ground)
    frame = {ground: poses[ground]}
    for k, (_, child) in tree.items():
        frame[child] = joint_pose[raw[k][0]]
    unreached = [n for n in links if n not in frame]
    if unreached:
        raise MechanismFileError(path, f"links not connected to {quote(ground)} by any joint: "
                                       f"{', '.join(quote(n, 40) for n in unreached[:5])}")
    dof = {"revolute": 1, "continuous": 1, "prismatic": 1, "fixed": 0, "ball": 3, "universal": 2, "revolute2": 2}
    check_sizes(path, len(links), len(raw), len(raw) - len(tree), sum(dof[raw[k][1]] for k in tree))
    out = [f'<robot name={quoteattr(model.get("name") or "sdf_model")}>']
    spec_links = dict(links)
    joints: list[JointSpec] = []
    cuts = []
    out.extend(_link_xml(link) for link in links.values())
    for k in sorted(tree):
        n, jt = raw[k][:2]
        parent, child = tree[k]  # oriented away from the ground
        _tree_joint(n, jt, parent, child, frame[parent].inverse() * joint_pose[n], *axes[n], spec_links, out, joints)
    for k, (n, jt, p, c, _) in enumerate(raw):
        if k in tree:
            continue
        P1 = frame[p].inverse() * joint_pose[n]
        P2 = frame[c].inverse() * joint_pose[n]
        a1, a2 = axes[n]
        cuts.append(CutJointSpec(n, _CUT[jt], p, c, tuple(P1.translation), tuple(pin.rpy.matrixToRpy(P1.rotation)),
                                 tuple(P2.translation), tuple(pin.rpy.matrixToRpy(P2.rotation)), tuple(a1),
                                 tuple(a2) if _CUT[jt] == "universal" else None, source="sdf"))
    out.append("</robot>")
    meshes: list[str] = []
    warnings = check_meshes(path, model, package_dirs, meshes)
    return MechanismSpec(path=str(path), name=model.get("name") or "sdf_model", format="sdf", files_read=meshes,
                         urdf_text="\n".join(out), links=spec_links, joints=joints, cut_joints=cuts,
                         warnings=warnings,
                         package_dirs=[str(d) for d in package_dirs or ()])
