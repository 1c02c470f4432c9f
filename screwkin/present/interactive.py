"""``view --interactive``: the mechanism in the browser with a control per input, through viser
(an optional package: ``pip install viser``, the ``view`` extra), which serves its own client
page (no CDN: it works offline) and calls Python back as a control moves.

Why viser rather than meshcat and a page of our own: viser has the GUI controls (sliders,
dropdowns, text) with Python callbacks, and Pinocchio 4.1 ships a ViserVisualizer that draws a
GeometryModel (screwkin's scene) into it; meshcat would need a hand-written page and a second
channel for the controls.

The logic (inputs -> configuration, modes, singularity, limit positions) is
:class:`screwkin.analysis.position.interactive.Interactive`; this module only wires it to the controls:
a slider per input labelled with the joint's name over its range (degrees or millimetres), a
dropdown of the assembly modes at the current inputs, a status line (a warning near a
singularity, the reason a move was refused: the slider goes back), a readout of the output
pose and of the named points, and each named point's traced path (Interactive.path: a polyline
per point, its colour in the readout, a dot where the point is now).
"""

from __future__ import annotations

import contextlib
import io
import math
import socket
import threading

import numpy as np
import pinocchio as pin

from ..errors import UsageError
from .camera import fit_camera, view_direction
from .viewplanar import planar_basis
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.position.interactive import Interactive
    from screwkin.present.view import Scene

__all__ = ["InteractiveView", "viser_module"]


def viser_module():
    """viser, or a usage error saying how to install it."""
    try:
        import viser
    except ImportError:
        raise UsageError("view --interactive needs viser: pip install viser (or pip install 'screwkin[view]')") from None
    return viser


def _visualizer_class():
    import coal
    import trimesh
    from pinocchio.visualize import ViserVisualizer

    class Visualizer(ViserVisualizer):
        """Pinocchio's ViserVisualizer, which also draws cones (screwkin's arrow heads)."""

        def loadViewerGeometryObject(self, geometry_object, prefix: str = "", color=None):
            geom = geometry_object.geometry
            if not isinstance(geom, coal.Cone):
                return super().loadViewerGeometryObject(geometry_object, prefix, color)
            name = f"{prefix}/{geometry_object.name}" if prefix else geometry_object.name
            h = 2.0 * geom.halfLength
            mesh = trimesh.creation.cone(radius=geom.radius, height=h)
            mesh.apply_translation([0.0, 0.0, -0.5 * h])  # coal's cone is centred on its origin
            c = color or geometry_object.meshColor
            self.frames[name] = self.viewer.scene.add_mesh_simple(name, mesh.vertices, mesh.faces, color=c[:3],
                                                                  opacity=c[3])

    return Visualizer


#: Colours of the traced paths, one per named point in turn (RGB 0-255; matplotlib's tab10)
PATH_COLORS = ((31, 119, 180), (255, 127, 14), (44, 160, 44), (214, 39, 40), (148, 103, 189), (140, 86, 75),
               (227, 119, 194), (127, 127, 127), (188, 189, 34), (23, 190, 207))


#: The 3-D view's width over its height before a browser says it: a window of 3:2 less the docked panel
CANVAS_ASPECT = 1.0
#: A camera within this fraction of its distance from where the view put it is still there (the browser sends
#: its pose back in single precision); farther, the person moved it and it is no longer framed again
CAMERA_MOVED = 1e-4


def _moved(position: np.ndarray, eye: np.ndarray, dist: float) -> bool:
    """Whether a camera reported at ``position`` is no longer where the view put it (``eye``, at ``dist`` from its
    target): farther than CAMERA_MOVED of that distance."""
    return float(np.linalg.norm(np.asarray(position, float) - eye)) > CAMERA_MOVED * dist


def _shown(value: float, unit: str) -> float:
    return value * 1000.0 if unit == "m" else math.degrees(value)


def _si(shown: float, unit: str) -> float:
    return shown / 1000.0 if unit == "m" else math.radians(shown)


class InteractiveView:
    """The viser server of ``view --interactive`` (127.0.0.1 only) for an Interactive state and
    a scene (screwkin.present.view.build_scene); ``port``: default 8080.  The controls are
    ``sliders`` (input name -> slider), ``modes`` (the dropdown), ``status`` and ``readout``."""

    def __init__(self, mech: Mechanism, live: Interactive, scene: Scene, port: int | None = None, title: str = "screwkin") -> None:
        viser = viser_module()
        self.mech, self.live = mech, live
        if port is not None:  # viser takes the next free port when the one asked is in use: check it first
            with socket.socket() as probe:
                try:
                    probe.bind(("127.0.0.1", port))
                except OSError as exc:
                    raise UsageError(f"port {port} cannot be used on 127.0.0.1: {exc.strerror or exc}") from None
        with contextlib.redirect_stdout(io.StringIO()):  # viser's banner: the command says the URL itself
            self.server = viser.ViserServer(host="127.0.0.1", port=port or 8080, label=title, verbose=False)
        self.port = self.server.get_port()
        if port is not None and self.port != port:  # taken between the check and the server's start
            self.close()
            raise UsageError(f"port {port} cannot be used on 127.0.0.1: it was taken")
        self.url = f"http://127.0.0.1:{self.port}"
        self.server.scene.configure_environment_map(None)  # the presets are sent on demand: none is needed
        self.viz = _visualizer_class()(mech.model, pin.GeometryModel(), scene.geometry)
        self.viz.initViewer(viewer=self.server, open=False)
        self.viz.loadViewerModel(rootNodeName="screwkin")
        self._dock()
        self._camera(scene, planar_basis(mech, live.state.q))
        self.server.on_client_connect(self._frame_client)
        self._lock = threading.RLock()
        self._busy = False
        gui = self.server.gui
        self.sliders = {}
        for c in live.controls:
            unit = "mm" if c.unit == "m" else "deg"
            lo, hi = _shown(c.low, c.unit), _shown(c.high, c.unit)
            step = 0.1 if c.unit == "rad" else max((hi - lo) / 1000.0, 1e-3)
            slider = gui.add_slider(c.name, min=lo, max=hi, step=step,
                                    initial_value=float(np.clip(_shown(live.state.inputs[c.name], c.unit), lo, hi)),
                                    hint=f"{c.name} [{unit}]")
            slider.on_update(self._moved(c.name, c.unit))
            self.sliders[c.name] = slider
        self.modes = gui.add_dropdown("assembly mode", self._mode_names(), initial_value=self._mode_name())
        self.modes.on_update(self._switched)
        self.status = gui.add_markdown("")
        self.readout = gui.add_markdown("")
        self.paths = {}  # point name -> the viser handle of its traced path (two positions or more)
        self._dot = 0.025 * float(scene.scale)  # the dot where each point is now [m]
        self._show()

    def _dock(self) -> None:
        """The control panel docked to the window's right edge: the 3-D view is the rest of the window, so the
        controls never cover the mechanism (viser's floating panel sat over the view's top right corner)."""
        gui = self.server.gui
        panel = getattr(gui, "main_panel", None)
        if panel is not None and hasattr(panel, "dock_right"):
            panel.dock_right()
        else:  # viser before 1.1: a fixed sidebar
            gui.configure_theme(control_layout="fixed")

    def _camera(self, scene: Scene, basis: tuple) -> None:
        """The first view: the mechanism framed (fit_camera, as view's pictures), along the plane's
        normal for a planar mechanism (its drawing's y up), else from view's usual direction; for the
        view's shape before a browser says it (then _frame_client frames it for that browser's)."""
        self._points = scene.points if scene.points is not None else scene.center[None]
        self._direction = np.asarray(basis[2], float) if basis is not None else view_direction(scene.bounds)
        self._up = tuple(float(v) for v in (basis[1] if basis is not None else (0.0, 0.0, 1.0)))
        target, eye = fit_camera(self._points, self._direction, aspect=CANVAS_ASPECT)
        cam = self.server.initial_camera
        cam.look_at = tuple(float(v) for v in target)
        cam.position = tuple(float(v) for v in eye)
        cam.up = self._up
        dist = float(np.linalg.norm(eye - target))
        cam.near, cam.far = dist / 100, dist * 100
        self._first = (np.asarray(eye, float), dist)

    def _frame_client(self, client) -> None:
        """Frame the mechanism for a browser as it says its view's size and field of view (its camera messages):
        the view left of the docked panel is narrower than the window, differs by window, and is known only once
        the panel is laid out; framed again while the size changes, until the person moves the camera.  A camera
        reported where this view put it (the first view, or any framing: the browser may apply the first view
        after a framing, and its reports may lag one) was not moved by the person; elsewhere it was."""
        framed = {}  # the size last framed for and the camera position set for it
        placed = [self._first]  # every (eye, distance to its target) this view gave the camera

        def frame(cam) -> None:
            size = (int(cam.image_width), int(cam.image_height))
            if not size[0] or not size[1]:
                return
            if framed.get("size") == size and not _moved(cam.position, framed["eye"], framed["dist"]):
                return  # framed for this view, and there
            if framed and all(_moved(cam.position, eye, dist) for eye, dist in placed):
                return  # moved by the person: theirs to keep (the first report has nothing to compare with)
            target, eye = fit_camera(self._points, self._direction, fov_deg=math.degrees(cam.fov),
                                     aspect=size[0] / size[1])
            framed.update(size=size, eye=np.asarray(eye, float), dist=float(np.linalg.norm(eye - target)))
            placed.append((framed["eye"], framed["dist"]))
            with client.atomic():
                cam.up_direction = self._up
                cam.position = tuple(float(v) for v in eye)  # (moves look_at with it: set it after)
                cam.look_at = tuple(float(v) for v in target)

        client.camera.on_update(frame)

    # ------------------------------------------------------------------ callbacks
    def _mode_names(self) -> list:
        return [f"mode {k}" for k in range(1, self.live.state.modes + 1)] or ["mode 1"]

    def _mode_name(self) -> str:
        return f"mode {max(self.live.state.mode, 1)}"

    def _act(self, action) -> None:
        """Run ``action`` then redraw, unless a callback is already doing so: setting a control
        from Python (a slider sent back, the modes' dropdown updated) calls back, and is ignored."""
        with self._lock:
            if self._busy:
                return
            self._busy = True
            try:
                action()
                self._show()
            finally:
                self._busy = False

    def _moved(self, name: str, unit: str):
        def move() -> None:
            self.live.move(name, _si(float(self.sliders[name].value), unit))
            if not self.live.state.moved:  # refused: the slider goes back to where the mechanism is
                self.sliders[name].value = _shown(self.live.state.inputs[name], unit)

        return lambda event: self._act(move)

    def _switched(self, event) -> None:
        self._act(lambda: self.live.switch(int(str(self.modes.value).split()[-1])))

    # ------------------------------------------------------------------ display
    def _show(self) -> None:
        s = self.live.state
        self.viz.display(s.q)
        names = self._mode_names()
        if list(self.modes.options) != names:
            self.modes.options = names
        if self.modes.value != self._mode_name():
            self.modes.value = self._mode_name()
        lines = []
        if s.message:
            lines.append(f"**stopped:** {s.message}")
        if s.singular:
            lines.append(f"**warning: singular configuration** (relative sigma_min {s.sigma:.2g} below "
                         f"{self.mech.tolerances.singular:g})")
        lines.append(f"relative sigma_min {s.sigma:.3g}; assembly mode {s.mode or '?'} of {s.modes}")
        self.status.content = "  \n".join(lines)
        out = []
        if s.output_pose is not None:
            p = s.output_pose[:3, 3] * 1000.0
            rpy = np.degrees(pin.rpy.matrixToRpy(s.output_pose[:3, :3]))
            out.append(f"**{self.live.output}**: x {p[0]:.2f}, y {p[1]:.2f}, z {p[2]:.2f} mm; "
                       f"roll {rpy[0]:.2f}, pitch {rpy[1]:.2f}, yaw {rpy[2]:.2f} deg")
        for k, (name, p) in enumerate(s.points.items()):
            r, g, b = PATH_COLORS[k % len(PATH_COLORS)]
            out.append(f"**{name}** <span style='color:rgb({r},{g},{b})'>(path)</span>: "
                       f"x {p[0] * 1000:.2f}, y {p[1] * 1000:.2f}, z {p[2] * 1000:.2f} mm")
        self.readout.content = "  \n".join(out)
        self._trace(s)

    def _trace(self, s) -> None:
        """Each named point's traced path as line segments between its successive positions."""
        scene = self.server.scene
        for k, name in enumerate(s.points):
            color = PATH_COLORS[k % len(PATH_COLORS)]
            path = self.live.path(name)
            scene.add_icosphere(f"/screwkin_paths/{name}/now", radius=self._dot, color=color,
                                position=tuple(float(v) for v in s.points[name]))
            if len(path) >= 2:
                segments = np.stack([path[:-1], path[1:]], axis=1).astype(np.float32)
                self.paths[name] = scene.add_line_segments(f"/screwkin_paths/{name}/path", segments, colors=color,
                                                           thickness=2.0, thickness_units="screen")
            elif name in self.paths:  # a mode switch started the path again
                self.paths.pop(name).remove()

    def close(self) -> None:
        with contextlib.redirect_stdout(io.StringIO()):
            self.server.stop()
