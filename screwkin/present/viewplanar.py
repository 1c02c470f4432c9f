"""Planar mechanisms seen as planar in meshcat (``view``'s pictures): an orthographic camera on
the plane's normal, the drawing plane's axes as the picture's (the skeleton diagram's e1 to the
right, e2 up: :func:`screwkin.analysis.motion.planar.plane_basis`), and one colour per link, the
colours and numbers of ``screwkin draw`` (ground dark grey)."""

from __future__ import annotations

import numpy as np

from ..model.geometry import plane_basis
from ..analysis.course.skeleton import numbering
from .draw import number_colours
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["GROUND", "planar_basis", "link_colours", "colour_links", "top_view"]

GROUND = np.array([0.3, 0.3, 0.3, 1.0])  # the ground's links: darker than the passive joints' grey


def planar_basis(mech: Mechanism, q: np.ndarray) -> tuple | None:
    """(e1, e2, n) of the plane of motion of a planar mechanism at q; None for a spatial or spherical one."""
    topo = mech.topology(q)
    if topo.motion_space != "planar" or topo.normal is None:
        return None
    return plane_basis(topo.normal)


def _rgba(hex_colour) -> np.ndarray:
    h = hex_colour.lstrip("#")
    return np.array([int(h[k:k + 2], 16) / 255 for k in (0, 2, 4)] + [1.0])


def link_colours(mech: Mechanism, q: np.ndarray) -> dict:
    """Pinocchio joint id of each rigid body -> RGBA: the colour ``screwkin draw`` gives its link
    (links numbered from the ground along the chain, the actuated joints first); the ground (joint 0) grey."""
    topo = mech.topology(q)
    number = numbering(topo, mech.actuated)[0]
    palette = number_colours(len(number))
    out = {0: GROUND}
    for name, k in sorted(number.items(), key=lambda item: item[1]):
        if k == 1:
            continue
        jid = mech.model.frames[mech.link_frame(name)].parentJoint
        out.setdefault(jid, _rgba(palette[k]))
    return out


def colour_links(scene, colours: dict) -> None:
    """Give every link visual and stand-in of the scene its link's colour (``colours``: link_colours)."""
    for obj in scene.geometry.geometryObjects:
        if scene.roles.get(obj.name) in ("link", "standin") and obj.parentJoint in colours:
            obj.meshColor = np.array(colours[obj.parentJoint], float)


def top_view(viewer, points, basis, aspect: float, fill: float = 0.8) -> np.ndarray:
    """Look at ``points`` (world, (n, 3)) along the plane's normal with an orthographic camera whose
    frame they fill to ``fill``: the scene node /screwkin is turned so that e1 is the world's x, e2
    its z (meshcat's up) and n its -y, and moved so that the points' centre is at the origin (meshcat's
    orbit controls look at it); the camera sits on -y (on the normal's side).  Returns the 4x4
    transform given to /screwkin."""
    import meshcat.geometry as g

    e1, e2, n = (np.asarray(v, float) for v in basis)
    R = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]]).T @ np.array([e1, e2, n])  # e1->x, e2->z, n->-y
    P = np.atleast_2d(np.asarray(points, float))
    x, y, z = P @ e1, P @ e2, P @ n
    centre = 0.5 * (x.max() + x.min()) * e1 + 0.5 * (y.max() + y.min()) * e2 + 0.5 * (z.max() + z.min()) * n
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = -R @ centre
    viewer["screwkin"].set_transform(T)
    half_h = max(0.5 * np.ptp(y), 0.5 * np.ptp(x) / aspect, 1e-6) / fill
    depth = max(np.ptp(z), np.ptp(x), np.ptp(y), 1e-3)
    dist = 10 * depth
    camera = g.OrthographicCamera(-half_h * aspect, half_h * aspect, half_h, -half_h, dist / 100, dist * 100)
    viewer["/Cameras/default/rotated"].set_object(camera)
    viewer["/Cameras/default/rotated/<object>"].set_property("position", [0.0, 0.0, float(dist)])  # world -y
    return T
