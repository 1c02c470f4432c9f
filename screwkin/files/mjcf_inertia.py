"""Mass and inertia of MJCF bodies as MuJoCo's compiler computes them (the physical-inertia check of
any format's inertial is files/inertia.inertia_problem).

A body without ``<inertial>`` (or every body, with ``<compiler inertiafromgeom="true">``) gets
the mass and inertia of its geoms: each geom a solid of uniform ``density`` (the geom's, default
1000 kg/m^3, MuJoCo's) or of the given ``mass``; the body's centre of mass and its inertia about
it by the parallel-axis theorem (MuJoCo then turns them to principal axes: the same tensor).
The solids, as MuJoCo's ``mjCGeom`` computes them (half sizes a, b, c; r a radius, h the full
length of a capsule's or cylinder's straight part):

- sphere: V = 4/3 pi r^3, I = 2/5 m r^2;
- ellipsoid: V = 4/3 pi a b c, I_xx = m (b^2 + c^2) / 5, ...;
- box: V = 8 a b c, I_xx = m (b^2 + c^2) / 3, ...;
- cylinder: V = pi r^2 h, I_xx = m (3 r^2 + h^2) / 12, I_zz = m r^2 / 2;
- capsule: the cylinder and two hemispheres, V = pi r^2 h + 4/3 pi r^3; the hemispheres'
  inertia about the centre from their own (2/5 m_s r^2) moved by MuJoCo's term m_s h (3 r + 2 h) / 8.

A mesh geom (and ``shellinertia``) is not computed here: MuJoCo integrates the mesh; its mass is
left out and the reader says so, naming the bodies.  Planes and height fields have no mass in MuJoCo.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["SOLIDS", "DEFAULT_DENSITY", "geom_volume", "geom_inertia", "body_inertia"]

#: Geom types whose mass MuJoCo computes from their shape and that screwkin computes the same way.
SOLIDS = ("sphere", "capsule", "cylinder", "box", "ellipsoid")
#: MuJoCo's default geom density [kg/m^3] (water).
DEFAULT_DENSITY = 1000.0


def geom_volume(kind: str, size) -> float:
    """The volume [m^3] of a solid geom of MuJoCo's ``size`` (half sizes, radius, half length)."""
    s = [float(x) for x in size]
    if kind == "sphere":
        return 4.0 / 3.0 * math.pi * s[0] ** 3
    if kind == "ellipsoid":
        return 4.0 / 3.0 * math.pi * s[0] * s[1] * s[2]
    if kind == "box":
        return 8.0 * s[0] * s[1] * s[2]
    if kind == "cylinder":
        return math.pi * s[0] ** 2 * 2.0 * s[1]
    if kind == "capsule":
        return math.pi * s[0] ** 2 * 2.0 * s[1] + 4.0 / 3.0 * math.pi * s[0] ** 3
    raise ValueError(kind)


def geom_inertia(kind: str, size, mass: float) -> np.ndarray:
    """The principal moments (I_xx, I_yy, I_zz) [kg m^2] about the geom's centre, in its frame."""
    s = [float(x) for x in size]
    if kind == "sphere":
        return np.full(3, 0.4 * mass * s[0] ** 2)
    if kind == "ellipsoid":
        a, b, c = s[:3]
        return mass / 5.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    if kind == "box":
        a, b, c = s[:3]
        return mass / 3.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    r, h = s[0], 2.0 * s[1]
    if kind == "cylinder":
        side = mass * (3 * r * r + h * h) / 12.0
        return np.array([side, side, mass * r * r / 2.0])
    if kind == "capsule":
        sphere = mass * 4 * r / (4 * r + 3 * h)  # the hemispheres' share of the volume
        cyl = mass - sphere
        side = cyl * (3 * r * r + h * h) / 12.0 + 0.4 * sphere * r * r + sphere * h * (3 * r + 2 * h) / 8.0
        return np.array([side, side, cyl * r * r / 2.0 + 0.4 * sphere * r * r])
    raise ValueError(kind)


def body_inertia(parts) -> tuple:
    """(mass, centre of mass, inertia tensor about it) [kg, m, kg m^2] in the body's frame of
    solids ``parts``: (mass, position, rotation matrix, principal moments) each."""
    mass = sum(m for m, _, _, _ in parts)
    if mass <= 0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    com = sum(m * np.asarray(p, float) for m, p, _, _ in parts) / mass
    inertia = np.zeros((3, 3))
    for m, p, R, moments in parts:
        d = np.asarray(p, float) - com
        inertia += R @ np.diag(moments) @ R.T + m * (d @ d * np.eye(3) - np.outer(d, d))
    return mass, com, inertia
