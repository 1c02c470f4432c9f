"""The grasp map of contacts on one object and the friction cones' generators (Murray, Li and
Sastry, 1994, ch. 5; see analysis.forces.grasp): contact frames R_i = [t1 t2 n], each contact model's
wrench basis carried to the object, G = [G_1 ... G_k], the characteristic length that makes
wrenches dimensionless, and the inscribed or circumscribed pyramids that stand for circular
cones.  Wrenches are (force, moment) about the object frame's origin; planar grasps (fx, fy, mz).
"""

from __future__ import annotations

import math

import numpy as np

from ...files.grasp import GraspSpec
from ...tolerances import DEFAULT
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.files.grasp import Contact

__all__ = ["contact_frame", "contact_columns", "grasp_map", "grasp_characteristic_length", "scaled_points",
           "cone_error", "exact_cones", "generators", "generator_matrix"]


# ------------------------------------------------------------------ the grasp map
def contact_frame(normal: np.ndarray) -> np.ndarray:
    """R = [t1 t2 n] (columns), right-handed, n the unit normal; t1 is the unit vector
    orthogonal to n nearest the coordinate axis least aligned with n."""
    n = np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    e = np.zeros(3)
    e[int(np.argmin(np.abs(n)))] = 1.0
    t1 = e - (e @ n) * n
    t1 /= np.linalg.norm(t1)
    return np.column_stack([t1, np.cross(n, t1), n])


def _hat(p: np.ndarray) -> np.ndarray:
    x, y, z = p
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


_SPATIAL_BASIS = {"frictionless": ([2], ["n"]), "point_friction": ([0, 1, 2], ["t1", "t2", "n"]),
                  "soft_finger": ([0, 1, 2, 5], ["t1", "t2", "n", "torsion"])}


def contact_columns(c: Contact, planar: bool) -> tuple:
    """(G_i, labels) of one contact."""
    p = np.asarray(c.point, float)
    n = np.asarray(c.normal, float)
    if planar:
        t = np.array([-n[1], n[0]])

        def col(d) -> np.ndarray:
            return np.array([d[0], d[1], p[0] * d[1] - p[1] * d[0]])

        if c.model == "frictionless":
            return col(n[:2])[:, None], ["n"]
        return np.column_stack([col(t), col(n[:2])]), ["t", "n"]
    R = contact_frame(n)
    Ad = np.zeros((6, 6))
    Ad[:3, :3] = R
    Ad[3:, :3] = _hat(p) @ R
    Ad[3:, 3:] = R
    idx, labels = _SPATIAL_BASIS[c.model]
    return Ad[:, idx], labels


def grasp_map(spec: GraspSpec) -> tuple[np.ndarray, tuple, tuple]:
    """(G, labels, blocks): the grasp map (wrenches (f, m) about the object frame's origin;
    planar: (fx, fy, mz)), its column labels "contact:coordinate" and each contact's column
    slice."""
    cols, labels, blocks, start = [], [], [], 0
    for k, c in enumerate(spec.contacts, 1):
        Gi, lab = contact_columns(c, spec.planar)
        cols.append(Gi)
        labels += [f"{k}:{x}" for x in lab]
        blocks.append(slice(start, start + Gi.shape[1]))
        start += Gi.shape[1]
    return np.hstack(cols), tuple(labels), tuple(blocks)


def grasp_characteristic_length(spec: GraspSpec) -> tuple:
    """(L, source): the mean distance of the contact points from their centroid [m], or 1 m
    when they all coincide."""
    P = np.array([c.point for c in spec.contacts], float)
    L = float(np.mean(np.linalg.norm(P - P.mean(axis=0), axis=1)))
    scale = max(1.0, float(np.abs(P).max()))
    if not L > DEFAULT.equal * scale:
        return 1.0, "1 m: the contacts are at one point"
    return L, "the mean distance of the contacts from their centroid"


def scaled_points(p: int, L: float) -> np.ndarray:
    """The weights of a wrench's p rows (3 planar, 6 spatial) that make it dimensionless: 1 on the
    forces, 1 / L on the moments (L the characteristic length [m])."""
    d = np.ones(p)
    d[3 if p == 6 else 2:] = 1.0 / L
    return d


# ------------------------------------------------------------------ cones
def cone_error(facets: int) -> float:
    """The inscribed N-facet pyramid holds the cone of friction mu cos(pi/N) and no more:
    its largest relative shortfall in mu is 1 - cos(pi/N)."""
    return 1.0 - math.cos(math.pi / facets)


def exact_cones(c: Contact, planar: bool) -> bool:
    """Whether the contact's cone is polyhedral (then its generators are exact)."""
    return planar or c.model == "frictionless" or c.mu == 0.0


def generators(c: Contact, planar: bool, facets: int = 8, circumscribed: bool = False) -> np.ndarray:
    """The generators of the contact's cone (or of the N-facet pyramid inscribed in it, or
    circumscribed about it) in the contact's coordinates (columns of G_i), each with unit
    normal force: frictionless (1); planar (t, n): (+-mu, 1); point contact (t1, t2, n):
    (mu cos th_j, mu sin th_j, 1); soft finger also +-mu_torsion as a fourth row."""
    if c.model == "frictionless":
        return np.ones((1, 1))
    mu = c.mu
    if planar:
        return np.array([[mu, -mu], [1.0, 1.0]]) if mu > 0 else np.array([[0.0], [1.0]])
    if mu > 0:
        r = mu / math.cos(math.pi / facets) if circumscribed else mu
        th = 2.0 * math.pi * np.arange(facets) / facets
        C = np.vstack([r * np.cos(th), r * np.sin(th), np.ones(facets)])
    else:
        C = np.array([[0.0], [0.0], [1.0]])
    if c.model == "soft_finger":
        g = c.mu_torsion
        if g > 0:
            k = C.shape[1]
            C = np.hstack([np.vstack([C, np.full(k, g)]), np.vstack([C, np.full(k, -g)])])
        else:
            C = np.vstack([C, np.zeros(C.shape[1])])
    return C


def generator_matrix(spec: GraspSpec, Gs: np.ndarray, blocks: tuple, facets: int, circumscribed: bool=False, frictionless: bool=False) -> tuple:
    """W = G_s C (scaled primitive wrenches, columns) and, per contact, its columns' slice and C_i."""
    cols, parts, start = [], [], 0
    for c, b in zip(spec.contacts, blocks):
        if frictionless:  # the normal alone
            normal_row = b.stop - b.start - (2 if c.model == "soft_finger" else 1)
            Wi = Gs[:, b.start + normal_row][:, None]
            C = None
        else:
            C = generators(c, spec.planar, facets, circumscribed)
            Wi = Gs[:, b] @ C
        cols.append(Wi)
        parts.append((slice(start, start + Wi.shape[1]), C))
        start += Wi.shape[1]
    return np.hstack(cols), parts


# ------------------------------------------------------------------ linear programs
