"""meshcat views of mechanisms: configurations, motions, screws and singular directions.

The scene is a Pinocchio GeometryModel: the links' URDF visuals (meshes when
found, primitives otherwise), plus what screwkin adds as geometry objects
attached to the moving joints -- joint axes as thin cylinders with a ball at the
joint's centre (actuated joints orange, passive grey, cut joints magenta), stand-ins for links without geometry
(a ball at the link frame and bars to its joints), the output link's frame,
and, at singular configurations, the singular screw axis with an arrow.
Pinocchio's MeshcatVisualizer draws it into any meshcat viewer: the loopback
server of :class:`ViewerServer`, or a recording stand-in in tests.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from html import escape
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from ..errors import MechanismFileError, UsageError, quote, shorten
from ..files.meshes import find_mesh
from ..files.xmlsafe import parse_xml_text
from ..model.geometry import perpendicular_basis
from ..model._pin import frame_id
from ..model.state import KinematicState
from .viewplanar import colour_links, link_colours, planar_basis, top_view
from .viewserver import ViewerServer
from .camera import BACKGROUND, PICTURE, fit_camera, view_direction
from .outfile import write_output

if TYPE_CHECKING:
    from ..model.mechanism import Mechanism
    from screwkin.files.description import CutJointSpec
    from collections.abc import Sequence

__all__ = ["COLORS", "build_scene", "show", "page", "legend_entries", "view", "RecordingViewer", "screenshot"]

COLORS = {
    "actuated": np.array([1.0, 0.55, 0.0, 1.0]),
    "passive": np.array([0.55, 0.55, 0.55, 1.0]),
    "cut": np.array([0.9, 0.0, 0.9, 1.0]),
    "standin": np.array([0.35, 0.6, 0.9, 1.0]),
    "screw": np.array([1.0, 0.1, 0.1, 1.0]),
    "marker": np.array([1.0, 0.9, 0.0, 1.0]),
    "pair": np.array([0.1, 0.6, 0.6, 1.0]),
    "x": np.array([1.0, 0.0, 0.0, 1.0]),
    "y": np.array([0.0, 0.8, 0.0, 1.0]),
    "z": np.array([0.0, 0.0, 1.0, 1.0]),
}


def _coal():
    import coal

    return coal


def _visual_urdf(mech: Mechanism, unreadable: set | tuple = ()) -> str:
    """The URDF text with every mesh resolved to an absolute path, and visuals
    whose mesh cannot be found (or is in ``unreadable``) dropped (their links get stand-ins)."""
    root = parse_xml_text(mech.spec.urdf_text, mech.path)
    base = Path(mech.path).resolve().parent
    package_dirs = getattr(mech.spec, "package_dirs", ()) or ()
    for link in root.findall("link"):
        for tag in ("visual", "collision"):
            for vis in link.findall(tag):
                mesh = vis.find("geometry/mesh")
                if mesh is None:
                    continue
                found = find_mesh(mesh.get("filename", ""), base, package_dirs)
                if found is not None and str(found.resolve()) not in unreadable:
                    mesh.set("filename", str(found.resolve()))
                else:
                    link.remove(vis)
    return ET.tostring(root, encoding="unicode")


_JOINT_FIRST = (pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT, pin.FrameType.BODY, pin.FrameType.OP_FRAME)


def _body_frame(model: pin.Model, name: str):
    """The BODY frame of link ``name`` (a joint may have the same name), or None."""
    fid = frame_id(model, name)
    return fid if fid is not None and model.frames[fid].type == pin.FrameType.BODY else None


def _owner_link(mech: Mechanism, frame_name: str):
    """The link a cut joint's side is on: the link itself, or the child link of a joint named so (sidecars)."""
    if frame_name in mech.spec.links:
        return frame_name
    return next((j.child for j in mech.spec.joints if j.name == frame_name), None)


def _standin_points(mech: Mechanism) -> dict:
    """link -> (its BODY frame id, [(target, point)]): the centres of its child joints and its loop-joint
    frames, expressed like the frame's placement (in the frame of the Pinocchio joint carrying the link)."""
    model = mech.model
    out = {}
    for name in mech.spec.links:
        fid = _body_frame(model, name)
        if fid is not None:
            out[name] = (fid, [])
    for j in mech.spec.joints:  # a child joint's origin is given in the parent link's frame
        if j.parent in out:
            fid, points = out[j.parent]
            points.append((j.name, model.frames[fid].placement.act(np.asarray(j.xyz, float))))
    for cut in mech.cuts:
        for link, side in ((cut.link1, cut.frame1), (cut.link2, cut.frame2)):
            owner = _owner_link(mech, link)
            if owner in out and model.frames[side].parentJoint == model.frames[out[owner][0]].parentJoint:
                out[owner][1].append((cut.name, model.frames[side].placement.translation.copy()))
    return out


def _segment(name: str, joint: int, frame: int, a: np.ndarray, b: np.ndarray, radius: float, color: Sequence[float]):
    """A cylinder between points a and b (in the frame of joint ``joint``)."""
    coal = _coal()
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    L = float(np.linalg.norm(d))
    if L < 1e-9:
        return None
    z = d / L
    R = np.column_stack([*perpendicular_basis(z), z])  # (b1, b2, z) right-handed; the cylinder is round
    obj = pin.GeometryObject(name, joint, frame, pin.SE3(R, (a + b) / 2), coal.Cylinder(radius, L))
    obj.meshColor = np.asarray(color, float)
    return obj


def _ball(name: str, joint: int, frame: int, p: np.ndarray, radius: float, color: Sequence[float]):
    obj = pin.GeometryObject(name, joint, frame, pin.SE3(np.eye(3), np.asarray(p, float)), _coal().Sphere(radius))
    obj.meshColor = np.asarray(color, float)
    return obj


def _disc(name: str, joint: int, frame: int, M: pin.SE3, radius: float, color: Sequence[float], alpha: float=0.35):
    """A thin disc of ``radius`` whose normal is the z axis of the placement M (a pitch circle or
    a circular profile), see-through so the links stay visible."""
    obj = pin.GeometryObject(name, joint, frame, M, _coal().Cylinder(radius, 0.05 * radius))
    obj.meshColor = np.array([*color[:3], alpha])
    return obj


def _pair_geometry(mech: Mechanism, cut, spec: CutJointSpec, r_axis: float, L_axis: float) -> list:
    """What a higher pair looks like: pitch circles (rolling, gears; a pitch line for a rack),
    profiles (circles as discs, lines as slots, points as pins) and a screw's helix of its lead."""
    model = mech.model
    out = []
    color = COLORS["pair"]
    frames = [model.getFrameId(f"{cut.name}@F{k}") for k in (1, 2)]
    a = np.asarray(cut.axis, float) / np.linalg.norm(cut.axis)
    turn = _segment("t", 0, 0, np.zeros(3), a, 1.0, color).placement.rotation  # z along the axis

    def side(k: int) -> tuple:
        f = model.frames[frames[k]]
        return f.parentJoint, frames[k], f.placement

    if spec.type in ("rolling", "gear"):
        for k, r in ((0, spec.radius1), (1, spec.radius2)):
            joint, frame, P = side(k)
            if np.isinf(r):  # the pitch line: F1's x axis
                out.append(_segment(f"screwkin/pair/{cut.name}/line", joint, frame, P.act(np.array([-6 * L_axis, 0, 0])),
                                    P.act(np.array([6 * L_axis, 0, 0])), r_axis, color))
                continue
            out.append(_disc(f"screwkin/pair/{cut.name}/circle{k + 1}", joint, frame, P * pin.SE3(turn, np.zeros(3)), r,
                             color))
    elif spec.type == "contact":
        for k, (shape, r) in enumerate((spec.profile1, spec.profile2)):
            joint, frame, P = side(k)
            name = f"screwkin/pair/{cut.name}/{shape}{k + 1}"
            if shape == "circle":
                out.append(_disc(name, joint, frame, P * pin.SE3(turn, np.zeros(3)), r, color))
            elif shape == "line":  # a slot or a flat face: the frame's x axis
                out.append(_segment(name, joint, frame, P.act(np.array([-4 * L_axis, 0, 0])),
                                    P.act(np.array([4 * L_axis, 0, 0])), 1.5 * r_axis, color))
            else:
                out.append(_ball(name, joint, frame, P.translation, 2.5 * r_axis, color))
    elif spec.type == "helical":  # two turns of a helix of the screw's lead, around its axis
        joint, frame, P = side(0)
        b1, b2 = perpendicular_basis(a)
        radius = 2 * L_axis / 3
        ts = np.linspace(0.0, 4 * np.pi, 49)
        pts = [P.act(radius * (np.cos(s) * b1 + np.sin(s) * b2) + spec.lead * s / (2 * np.pi) * a) for s in ts]
        for k in range(len(pts) - 1):
            obj = _segment(f"screwkin/pair/{cut.name}/helix{k}", joint, frame, pts[k], pts[k + 1], 0.6 * r_axis, color)
            if obj is not None:
                out.append(obj)
        out.append(_segment(f"screwkin/pair/{cut.name}/axis", joint, frame, P.act(-L_axis * a),
                            P.act((2 * spec.lead + L_axis) * a), r_axis, color))
    return [o for o in out if o is not None]


@dataclass
class Scene:
    """A mechanism's scene: the geometry model and what each added object shows."""

    geometry: pin.GeometryModel
    roles: dict  # geometry object name -> role ("link", "axis:actuated", "axis:passive", "axis:cut", "standin", ...)
    scale: float  # size of the mechanism [m]
    center: np.ndarray  # centre of its joints [m]
    points: np.ndarray | None = None  # (n, 3): the corners of every drawn object's box, world, at q [m]
    declared: bool = True  # the file (or --actuated) names the actuated joints; False: none declared

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3): the world bounding box (min, max corners) of everything drawn [m]."""
        pts = self.points if self.points is not None and len(self.points) else self.center[None]
        return np.array([pts.min(axis=0), pts.max(axis=0)])


def _corner_points(state: KinematicState, geom) -> np.ndarray:
    """Points that bound the drawn geometry at the configuration of ``state`` (a KinematicState): the
    joint centres and the corners of each object's own bounding box placed where its joint puts it
    (meshes as loaded, scale included)."""
    placed = [state.joint_placement(j) for j in range(state.mech.model.njoints)]
    pts = [M.translation for M in placed]
    signs = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float)
    for obj in geom.geometryObjects:
        g = obj.geometry
        try:
            g.computeLocalAABB()
            lo, hi = np.asarray(g.aabb_local.min_, float), np.asarray(g.aabb_local.max_, float)
        except (AttributeError, RuntimeError):  # pragma: no cover - a shape coal cannot bound: its origin
            lo = hi = np.zeros(3)
        if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
            lo = hi = np.zeros(3)
        M = placed[obj.parentJoint] * obj.placement
        corners = lo + signs * (hi - lo)
        pts.extend(corners @ M.rotation.T + M.translation)
    return np.asarray(pts)


def _visual_geometry(mech: Mechanism, warn: Callable[[str], object] | None=None):
    """Pinocchio's visual GeometryModel of the links; a mesh file that exists but cannot be
    read (not a mesh, truncated) is a warning and its link is drawn as a stand-in."""

    warn = warn or (lambda m: print(f"warning: {shorten(str(mech.path), 200)}: {m}", file=sys.stderr))
    unreadable = set()
    while True:
        try:
            return pin.buildGeomFromUrdfString(mech.model, _visual_urdf(mech, unreadable), pin.GeometryType.VISUAL)
        except (ValueError, RuntimeError) as exc:
            found = re.search(r"Could not load resource (.+)", str(exc))
            bad = found.group(1).strip() if found else None
            if not bad or bad in unreadable:
                lines = [line for line in str(exc).splitlines() if line.strip()]
                raise MechanismFileError(mech.path, f"the visuals cannot be loaded: "
                                                    f"{shorten(lines[-1] if lines else type(exc).__name__, 160)}") \
                    from None
            unreadable.add(bad)
            warn(f"mesh {quote(bad, 120)} cannot be read as a mesh: its link is drawn as a stand-in")


#: How build_scene's parts add a geometry object (None: nothing) with its role.
_Add = Callable[[Any, str], None]


def _joint_marks(mech: Mechanism, add: _Add, r_axis: float, L_axis: float) -> None:
    """Each moving joint's axis (drawn on its child side) and centre; a prismatic joint's with an arrow head; each
    cut joint's axis on its F1 side, a higher pair's profiles."""
    model = mech.model
    actuated = set(mech.actuated)
    axis_of = {j.name: np.asarray(j.axis) for j in mech.spec.joints}
    virtual = {n for names in mech.virtual_joints.values() for n in names}
    for c in mech.coordinates:
        if c.joint in virtual:
            continue  # the equivalent linkage of a higher pair: drawn as the pair below
        jid = c.joint_id
        frame = frame_id(model, c.joint, prefer=_JOINT_FIRST)
        frame = 0 if frame is None else frame
        role = "axis:actuated" if c.joint in actuated else "axis:passive"
        a = axis_of.get(c.joint)
        if a is None or c.nv != 1:
            add(_ball(f"screwkin/axis/{c.joint}", jid, frame, np.zeros(3), 2 * r_axis, COLORS[role[5:]]), role)
            continue
        add(_segment(f"screwkin/axis/{c.joint}", jid, frame, -L_axis * a, L_axis * a, r_axis, COLORS[role[5:]]), role)
        add(_ball(f"screwkin/joint/{c.joint}", jid, frame, np.zeros(3), 6 * r_axis, COLORS[role[5:]]),
            "joint:" + role[5:])  # the joint's centre, seen from any side
        short = model.joints[jid].shortname()
        if "JointModelP" in short:  # pitch infinite: a translation, drawn with an arrow head
            seg = _segment("tmp", jid, frame, np.zeros(3), a, 1.0, COLORS[role[5:]])
            cone = pin.GeometryObject(f"screwkin/axis/{c.joint}/arrow", jid, frame,
                                      pin.SE3(seg.placement.rotation, L_axis * a), _coal().Cone(3 * r_axis, 6 * r_axis))
            cone.meshColor = COLORS[role[5:]]
            add(cone, role)
    specs = {s.name: s for s in mech.spec.cut_joints}
    for cut in mech.cuts:  # cut joints: their axis on the F1 side
        f = model.frames[cut.frame1]
        a = f.placement.rotation @ np.asarray(cut.axis)
        p = f.placement.translation
        if cut.pair is not None:
            for obj in _pair_geometry(mech, cut, specs[cut.name], r_axis, L_axis):
                add(obj, "pair")
            continue
        if cut.type in ("spherical", "fixed", "universal"):
            add(_ball(f"screwkin/cut/{cut.name}", f.parentJoint, cut.frame1, p, 2.5 * r_axis, COLORS["cut"]), "axis:cut")
        else:
            add(_segment(f"screwkin/cut/{cut.name}", f.parentJoint, cut.frame1, p - L_axis * a, p + L_axis * a,
                         1.5 * r_axis, COLORS["cut"]), "axis:cut")


def _singular_marks(mech: Mechanism, output: str | None, singular: Iterable, add: _Add, r_axis: float,
                    L_axis: float) -> None:
    """At each singular configuration: a ball at the output link's origin, and the singular screw axis as a
    line with an arrow."""
    for k, (qs, twist) in enumerate(singular):
        if output is not None:
            at = KinematicState(mech, qs).frame_placement(mech.link_frame(output)).translation
            add(_ball(f"screwkin/singular/{k}/marker", 0, 0, at, 4 * r_axis,
                      COLORS["marker"]), "singular:marker")
        if twist is not None and twist.screw is not None and twist.screw.point is not None:
            s = twist.screw
            p, u = np.asarray(s.point), np.asarray(s.direction)
            add(_segment(f"screwkin/singular/{k}/axis", 0, 0, p - 3 * L_axis * u, p + 3 * L_axis * u, r_axis,
                         COLORS["screw"]), "singular:axis")
            cone = pin.GeometryObject(f"screwkin/singular/{k}/arrow", 0, 0, pin.SE3(
                _segment("t", 0, 0, p, p + u, 1, COLORS["screw"]).placement.rotation, p + 3 * L_axis * u),
                _coal().Cone(3 * r_axis, 6 * r_axis))
            cone.meshColor = COLORS["screw"]
            add(cone, "singular:arrow")


def build_scene(mech: Mechanism, q: np.ndarray, output: str | None = None, singular: Iterable = (),
                warn: Callable[[str], object] | None = None) -> Scene:
    """The scene at configuration q (used for the characteristic size of the marks).

    singular: (q_singular, SingularTwist or None) pairs to mark: a ball at the
    output link's origin, and the singular screw axis as a line with an arrow.
    warn: callable receiving each warning (a mesh that cannot be read); default: stderr."""
    model = mech.model
    geom = _visual_geometry(mech, warn)
    roles = {o.name: "link" for o in geom.geometryObjects}
    state = KinematicState(mech, q)
    pts = np.array([state.centre(("joint", j)) for j in range(model.njoints)])
    scale = float(max(np.ptp(pts, axis=0).max(), 0.05))
    center = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    r_axis, L_axis = 0.004 * scale, 0.08 * scale

    def add(obj: Any, role: str) -> None:
        if obj is not None:
            geom.addGeometryObject(obj)
            roles[obj.name] = role

    _joint_marks(mech, add, r_axis, L_axis)
    # stand-ins for links without any visual: a ball at the link frame (its parent joint's centre) and bars
    # to the centres of its child joints and to its loop-joint frames
    with_visual = {model.frames[o.parentFrame].name for o in geom.geometryObjects if roles[o.name] == "link"}
    for name, (fid, points) in _standin_points(mech).items():
        if name in with_visual:
            continue
        fr = model.frames[fid]
        origin = fr.placement.translation
        if not any(np.linalg.norm(p - origin) > 1e-9 for _, p in points) and \
                mech.spec.links[name].is_massless(mech.tolerances.dummy_mass):
            continue  # no length, no mass, no geometry: the inside of a compound joint
        if not (fr.parentJoint == 0 and name == mech.spec.root):  # the ground keeps its bars, not a ball
            add(_ball(f"screwkin/standin/{name}", fr.parentJoint, fid, origin, 3 * r_axis, COLORS["standin"]),
                "standin")
        for target, p in points:
            add(_segment(f"screwkin/standin_bar/{name}/{target}", fr.parentJoint, fid, origin, p, 1.5 * r_axis,
                         COLORS["standin"]), "standin")
    if output is not None:
        fid = mech.link_frame(output)
        fr = model.frames[fid]
        for k, axis in enumerate("xyz"):
            end = fr.placement.translation + 2 * L_axis * fr.placement.rotation[:, k]
            add(_segment(f"screwkin/output/{axis}", fr.parentJoint, fid, fr.placement.translation, end, r_axis,
                         COLORS[axis]), f"output:{axis}")
    _singular_marks(mech, output, singular, add, r_axis, L_axis)
    return Scene(geom, roles, scale, center, _corner_points(state, geom),
                 declared=mech.actuation_source is not None)


class RecordingViewer:
    """A stand-in for meshcat.Visualizer that records what is sent to it."""

    def __init__(self, root=None, path: str="") -> None:
        import meshcat.path

        self._root = root or self
        self._path = path
        self.path = meshcat.path.Path(tuple(p for p in path.split("/") if p))
        if root is None:
            self.objects, self.transforms, self.properties, self.animation = {}, {}, {}, None

    def __getitem__(self, path: str) -> RecordingViewer:
        path = path if path.startswith("/") else f"{self._path}/{path}"
        return RecordingViewer(self._root, path)

    def set_object(self, geometry: object, material: object | None=None) -> None:
        self._root.objects[self._path] = (geometry, material)

    def set_transform(self, matrix: np.ndarray | None = None) -> None:
        self._root.transforms[self._path] = np.eye(4) if matrix is None else np.asarray(matrix)

    def set_property(self, key: str, value: object) -> None:
        self._root.properties[(self._path, key)] = value

    def delete(self) -> None:
        self._root.objects.pop(self._path, None)

    def set_animation(self, animation: object, play: bool=True, repetitions: int=1) -> None:
        self._root.animation = animation

    def get_image(self, *args: Any):  # pragma: no cover - present so Pinocchio does not warn
        raise NotImplementedError


def _translation(p: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T


def show(mech: Mechanism, scene: Scene, viewer, q: np.ndarray, motion: Sequence[np.ndarray] | None=None, fps: int=30):
    """Draw the scene at q into a meshcat viewer with Pinocchio's MeshcatVisualizer;
    with ``motion`` (a sequence of configurations) also set a meshcat animation.  A planar
    mechanism is seen along its plane's normal, orthographic, a colour per link (viewplanar)."""
    from pinocchio.visualize import MeshcatVisualizer

    basis = planar_basis(mech, q)
    if basis is not None:
        colour_links(scene, link_colours(mech, q))
    viz = MeshcatVisualizer(mech.model, pin.GeometryModel(), scene.geometry)
    viz.initViewer(viewer=viewer)
    viz.loadViewerModel(rootNodeName="screwkin")
    viz.display(q)
    # a neutral background, no grid nor world axes, and the camera fitted to what is drawn.  meshcat's orbit
    # controls look at the world origin (its camera sits in the frame /Cameras/default/rotated, y up: world
    # (x, y, z) is (x, z, -y) there), so the scene is moved instead: /screwkin carries the target to the origin
    viewer["/Axes"].set_property("visible", False)
    viewer["/Grid"].set_property("visible", False)
    for key, value in BACKGROUND.items():
        viewer["/Background"].set_property(key, value)
    pts = scene.points if scene.points is not None else scene.center[None]
    if basis is not None:
        top_view(viewer, pts, basis, PICTURE[0] / PICTURE[1])
    else:
        target, eye = fit_camera(pts, view_direction(scene.bounds))
        w = eye - target
        dist = float(np.linalg.norm(w))
        viewer["screwkin"].set_transform(_translation(-target))  # beside the visuals: /meshcat/screwkin
        camera = viewer["/Cameras/default/rotated/<object>"]
        camera.set_property("position", [float(w[0]), float(w[2]), float(-w[1])])
        camera.set_property("near", dist / 100)
        camera.set_property("far", dist * 100)
    if motion is not None and len(motion):
        import meshcat.animation

        anim = meshcat.animation.Animation(default_framerate=fps)
        for k, qk in enumerate(motion):
            with anim.at_frame(viewer, k) as frame:
                viz.viewer = frame
                viz.display(qk)
        viz.viewer = viewer
        viewer.set_animation(anim, play=True, repetitions=0)
    return viz


#: Legend entries: (label, colour key, the roles that show it), in the legend's order
LEGEND = (
    ("actuated joints", "actuated", ("axis:actuated", "joint:actuated")),
    ("passive joints", "passive", ("axis:passive", "joint:passive")),
    ("cut (loop) joints", "cut", ("axis:cut",)),
    ("higher pairs", "pair", ("pair",)),
    ("links without geometry", "standin", ("standin",)),
    ("output link: frame x", "x", ("output:x",)),
    ("y", "y", ("output:y",)),
    ("z", "z", ("output:z",)),
    ("singular configuration", "marker", ("singular:marker",)),
    ("singular screw axis", "screw", ("singular:axis",)),
)


def _css(color: Sequence[float]) -> str:
    r, g, b = (int(round(255 * float(c))) for c in color[:3])
    return f"rgb({r},{g},{b})"


def legend_entries(scene: Scene) -> list:
    """(label, CSS colour) for each kind of thing the scene shows; a file that declares no actuation
    (no transmissions, no name_mot) has "joints (no actuation declared)", not passive joints."""
    present = set(scene.roles.values())
    return [("joints (no actuation declared)" if key == "passive" and not scene.declared else label, _css(COLORS[key]))
            for label, key, roles in LEGEND if present & set(roles)]


def page(html: str, scene: Scene, title: str | None = None, controls: bool = True, size: tuple[int, int] | None=None) -> str:
    """meshcat's static page with screwkin's legend (a small box, bottom left: a coloured marker
    per kind of thing drawn, and ``title`` above them); ``controls=False`` hides meshcat's
    control panel and ``size`` (width, height) [px] fixes the drawing's size, for pictures
    (headless Chromium's viewport is not its window's size)."""

    rows = []
    entries = legend_entries(scene)
    k = 0
    while k < len(entries):
        label, color = entries[k]
        if label.startswith("output link"):  # x, y, z on one line
            marks = "".join(f'<span class="sk-mark" style="background:{c}"></span>{escape(lab[-1])} '
                            for lab, c in entries[k:k + 3])
            rows.append(f'<div class="sk-row">{marks}<span>output link frame</span></div>')
            k += 3
            continue
        rows.append(f'<div class="sk-row"><span class="sk-mark" style="background:{color}"></span>'
                    f'{escape(label)}</div>')
        k += 1
    head = f'<div class="sk-title">{escape(title)}</div>' if title else ""
    legend = f'<div id="screwkin-legend">{head}{"".join(rows)}</div>'
    style = """<style>
#screwkin-legend {position: absolute; left: 12px; bottom: 12px; padding: 6px 10px; z-index: 10;
  background: rgba(255,255,255,0.85); border: 1px solid #bbb; border-radius: 4px;
  font: 13px/1.5 'DejaVu Sans', Arial, sans-serif; color: #222;}
#screwkin-legend .sk-title {font-weight: bold; margin-bottom: 2px;}
#screwkin-legend .sk-mark {display: inline-block; width: 11px; height: 11px; border-radius: 50%;
  margin-right: 6px; vertical-align: -1px; border: 1px solid rgba(0,0,0,0.35);}
""" + ("" if controls else ".dg, .dg.main, .dg.ac {display: none !important;}\n") + "</style>"
    if size is not None:  # a picture: the pane and the camera's aspect fixed, whatever the browser's window does
        w, h = (int(v) for v in size)
        style += (f"<style>#meshcat-pane {{width: {w}px !important; height: {h}px !important;}}</style>"
                  f"<script>(function () {{ function fit() {{ viewer.set_3d_pane_size({w}, {h}); }} fit();"
                  f" requestAnimationFrame(fit); window.addEventListener('load', fit); window.addEventListener('resize', fit);"
                  f" setTimeout(fit, 50); }})();</script>")
    at = html.rfind("</body>")
    at = len(html) if at < 0 else at
    return html[:at] + style + legend + html[at:]


def chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        for d in os.environ.get("PATH", "").split(os.pathsep):
            p = Path(d) / name
            if p.is_file() and os.access(p, os.X_OK):
                return str(p)
    return None


def screenshot(html_path: str | Path, png_path: str | Path, size: tuple[int, int]=PICTURE, budget_ms: int=8000) -> None:
    """Render a static meshcat page with headless Chromium (software WebGL) into a PNG."""
    exe = chromium()
    if exe is None:
        raise UsageError("--png needs Chromium (Debian: apt-get install chromium)")

    with tempfile.TemporaryDirectory() as profile:
        shot = Path(profile) / "screenshot.png"  # Chromium writes here; the PNG is then written to png_path
        cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
               "--enable-unsafe-swiftshader", "--disable-quic", "--no-first-run", "--disable-background-networking",
               "--disable-component-update", "--disable-sync", f"--user-data-dir={profile}",
               f"--window-size={size[0]},{size[1]}", f"--virtual-time-budget={budget_ms}",
               f"--screenshot={shot}", Path(html_path).resolve().as_uri()]
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        if not shot.is_file():
            raise UsageError(f"Chromium did not write {png_path}: {p.stderr.strip()[-300:]}")
        write_output(png_path, shot.read_bytes())


_servers = []  # servers started by view(): they live as long as the Python session (a notebook)


def view(mech: Mechanism, q: np.ndarray | None=None, output=None, motion: Sequence[np.ndarray] | None=None, viewer=None):
    """Show a mechanism (at q, default its assembled configuration) and return the
    meshcat viewer; in a notebook, ``view(mech, s.q).jupyter_cell()`` embeds it.
    Without ``viewer`` a loopback-only server is started and kept for the session."""
    q = mech.assemble().q if q is None else q
    if viewer is None:
        server = ViewerServer()
        _servers.append(server)
        viewer = server.viewer
    show(mech, build_scene(mech, q, output=output), viewer, q, motion=motion)
    return viewer
