"""Plain data describing a mechanism file, before any model is built.

A file (URDF with loop joints, URDF with an Extended-URDF YAML sidecar, or SDF)
becomes a :class:`MechanismSpec`: the spanning tree of ordinary joints, the cut
joints that close the loops, the declared actuation, and the URDF text of the
tree handed to Pinocchio's parser.  Nothing here solves or computes kinematics.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "TREE_JOINT_DOF",
    "CUT_JOINT_DOF",
    "LinkSpec",
    "JointSpec",
    "CutJointSpec",
    "MechanismSpec",
    "placement",
    "resolve_actuation",
]

#: Degrees of freedom of the URDF joint types Pinocchio's parser knows.
TREE_JOINT_DOF = {
    "revolute": 1,
    "continuous": 1,
    "prismatic": 1,
    "fixed": 0,
    "floating": 6,
    "planar": 3,
}

#: Degrees of freedom of the cut (loop) joint types of mechanism-format.md.
CUT_JOINT_DOF = {
    "fixed": 0,
    "revolute": 1,
    "continuous": 1,
    "prismatic": 1,
    "cylindrical": 2,
    "universal": 2,
    "planar": 3,
    "spherical": 3,
}


def placement(xyz, rpy):
    """The pinocchio.SE3 of a URDF ``<origin xyz rpy>``."""
    import pinocchio as pin

    return pin.SE3(pin.rpy.rpyToMatrix(np.asarray(rpy, float)), np.asarray(xyz, float))


@dataclass
class LinkSpec:
    """A link as written in the file.

    mass: [kg], None when the file gives no ``<inertial>``.
    has_geometry: the link has a visual or collision element.
    """

    name: str
    mass: float | None = None
    has_geometry: bool = False

    def is_massless(self, dummy_mass: float) -> bool:
        """No geometry and (almost) no mass: it can be the inside of a compound joint."""
        return not self.has_geometry and (self.mass is None or self.mass < dummy_mass)


@dataclass
class JointSpec:
    """A joint of the spanning tree (an ordinary URDF joint)."""

    name: str
    type: str
    parent: str
    child: str
    xyz: tuple = (0.0, 0.0, 0.0)
    rpy: tuple = (0.0, 0.0, 0.0)
    axis: tuple = (1.0, 0.0, 0.0)

    @property
    def dof(self) -> int:
        return TREE_JOINT_DOF[self.type]


@dataclass
class CutJointSpec:
    """A cut joint closing a loop.

    ``frame1``/``frame2`` name Pinocchio frames (a link name for ``<loop_joint>``,
    any frame name for the YAML sidecar).  ``xyz1/rpy1`` place F1 on frame1,
    ``xyz2/rpy2`` place F2 on frame2.  ``axis`` is expressed in F1, ``axis2``
    (universal joints) in F2.
    """

    name: str
    type: str
    frame1: str
    frame2: str
    xyz1: tuple = (0.0, 0.0, 0.0)
    rpy1: tuple = (0.0, 0.0, 0.0)
    xyz2: tuple = (0.0, 0.0, 0.0)
    rpy2: tuple = (0.0, 0.0, 0.0)
    axis: tuple = (1.0, 0.0, 0.0)
    axis2: tuple | None = None
    source: str = "loop_joint"

    @property
    def dof(self) -> int:
        return CUT_JOINT_DOF[self.type]


@dataclass
class MechanismSpec:
    """Everything read from a mechanism file."""

    path: str
    name: str
    format: str
    urdf_text: str
    links: dict = field(default_factory=dict)  # name -> LinkSpec
    joints: list = field(default_factory=list)  # JointSpec, tree joints
    cut_joints: list = field(default_factory=list)  # CutJointSpec
    transmissions: list = field(default_factory=list)  # joint names from <transmission>
    yaml_actuated: list | None = None  # joint names from the sidecar's name_mot
    yaml_path: str | None = None
    replacements: list = field(default_factory=list)  # (joint name, type) from the sidecar
    warnings: list = field(default_factory=list)

    @property
    def root(self) -> str:
        children = {j.child for j in self.joints}
        roots = [name for name in self.links if name not in children]
        return roots[0]


def resolve_actuation(spec: MechanismSpec, actuated=None):
    """The actuated joint names and where they were declared.

    Precedence: the caller's list (the command line), the YAML ``name_mot``,
    then ROS ``<transmission>`` elements.  Returns ``(names, source)``;
    ``([], None)`` when nothing declares inputs.
    """
    if actuated:
        return list(actuated), "command line"
    if spec.yaml_actuated:
        return list(spec.yaml_actuated), "yaml name_mot"
    if spec.transmissions:
        return list(spec.transmissions), "transmission"
    return [], None


def finite(values) -> bool:
    return all(math.isfinite(v) for v in values)
