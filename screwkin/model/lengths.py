"""A mechanism's characteristic length: the length of each link as written in the file (the largest
distance between two joint centres on it) and their mean, by which every measure that mixes
translations and rotations is made dimensionless.
"""

from __future__ import annotations

import numpy as np

from ..tolerances import DEFAULT
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pinocchio as pin

__all__ = ["link_lengths", "characteristic_length"]


def link_lengths(model: pin.Model, cuts: list) -> list:
    """The length of each rigid body of the model that has one: the largest distance between
    two joint centres on it (the origin of the joint that carries it, the origins of the
    joints it carries, and the frames of the cut joints on it), as written in the file --
    the same whatever the configuration.  Bodies whose joints all sit at one point (the
    massless links inside compound joints) have none."""
    points = {j: [] for j in range(model.njoints)}
    for j in range(1, model.njoints):
        points[j].append(np.zeros(3))
        points[model.parents[j]].append(np.array(model.jointPlacements[j].translation))
    for c in cuts:
        for f in (c.frame1, c.frame2):
            fr = model.frames[f]
            points[fr.parentJoint].append(np.array(fr.placement.translation))
    lengths = []
    for pts in points.values():
        if len(pts) < 2:
            continue
        P = np.array(pts[:200])  # a body carrying more joints than that: its first 200 decide
        d = float(np.sqrt(np.max(np.sum((P[:, None, :] - P[None, :, :]) ** 2, axis=2))))
        if d > DEFAULT.equal:  # a body whose joints are not all at one point
            lengths.append(d)
    return lengths


def characteristic_length(model: pin.Model, cuts: list) -> float:
    """The characteristic length L of a mechanism [m]: the mean length of its links
    (:func:`link_lengths`), 1 m when no link has a length.  Every measure that mixes
    translations and rotations divides translations by L (and multiplies the rates of
    sliding joints by it), so it is dimensionless and the same in every command."""
    lengths = link_lengths(model, cuts)
    return float(np.mean(lengths)) if lengths else 1.0
