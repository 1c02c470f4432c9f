"""The kinematic pairs screwkin knows: a vocabulary table (``screwkin info --joint-types``).

Each entry gives the pair's degrees of freedom (relative motion between its two links; for
the planar higher pairs, the freedoms in their plane, as the Gruebler count takes them), the
motion it allows, whether it is a lower pair (elements touching over a surface) or a higher
pair (along a line or at a point), the contact, and how it is written in a file
(docs/format.md).  The DOF are those of the textbooks (Reuleaux's six lower pairs; a gear
or a rolling pair a full joint J1, a cam or a pin in a slot a half joint J2) and of
screwkin's own counts (``files.description.CUT_JOINT_DOF``).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["JointType", "JOINT_TYPES", "joint_type"]


@dataclass(frozen=True)
class JointType:
    name: str
    symbol: str
    dof: int
    motion: str
    pair: str  # "lower" | "higher" | "none" (a weld, a free body)
    contact: str  # "surface" | "line" | "point" | "none"
    written: str  # how a file declares it
    type: str  # screwkin's joint type (Joint.type, <loop_joint type=...>)


JOINT_TYPES = (
    JointType("revolute", "R", 1, "rotation about an axis", "lower", "surface",
              "URDF revolute; <loop_joint type=\"revolute\">", "revolute"),
    JointType("continuous", "R", 1, "rotation about an axis, unlimited", "lower", "surface",
              "URDF continuous; <loop_joint type=\"continuous\">", "continuous"),
    JointType("prismatic", "P", 1, "translation along an axis", "lower", "surface",
              "URDF prismatic; <loop_joint type=\"prismatic\">", "prismatic"),
    JointType("helical (screw pair)", "H", 1, "helical: rotation with translation along the axis, by the lead",
              "lower", "surface", "<loop_joint type=\"helical\"> with <pitch lead>; a P <mimic> of an R",
              "helical"),
    JointType("cylindrical", "C", 2, "rotation about and translation along one axis", "lower", "surface",
              "<loop_joint type=\"cylindrical\">; an R and a P on one axis through a massless link",
              "cylindrical"),
    JointType("universal (Hooke)", "U", 2, "two rotations about intersecting axes", "lower", "surface",
              "<loop_joint type=\"universal\"> with <axis2>; two intersecting Rs through a massless link",
              "universal"),
    JointType("spherical (ball)", "S", 3, "three rotations about a point", "lower", "surface",
              "<loop_joint type=\"spherical\">; three concurrent Rs through massless links", "spherical"),
    JointType("planar", "E", 3, "two translations in a plane and a rotation about its normal", "lower", "surface",
              "URDF planar; <loop_joint type=\"planar\">", "planar"),
    JointType("floating", "F", 6, "free: three translations and three rotations", "none", "none",
              "URDF floating", "floating"),
    JointType("fixed", "-", 0, "none (a weld: the two links are one)", "none", "none",
              "URDF fixed; <loop_joint type=\"fixed\">", "fixed"),
    JointType("rolling (friction wheels)", "Ro", 1, "rolling without slip, in a plane", "higher", "line",
              "<loop_joint type=\"rolling\"> with two circles or a circle on a line", "rolling"),
    JointType("gear pair", "G", 1, "pitch circles rolling without slip, in a plane", "higher", "line",
              "<loop_joint type=\"gear\"> with <gear radius1 radius2>; <mimic> couplings", "gear"),
    JointType("rack and pinion", "G", 1, "a pitch circle rolling on a pitch line, in a plane", "higher", "line",
              "<loop_joint type=\"gear\"> with radius1=\"inf\" (the rack's pitch line)", "gear"),
    JointType("cam (sliding contact)", "Ct", 2, "rolling and sliding of two profiles, in a plane", "higher", "line",
              "<loop_joint type=\"contact\"> with circle or line profiles", "contact"),
    JointType("pin in slot", "Ct", 2, "a pin sliding along and turning in a slot, in a plane", "higher", "point",
              "<loop_joint type=\"contact\"> with a point (or circle) profile on a line", "contact"),
)


def joint_type(name: str) -> JointType:
    """The entry of a screwkin joint type (``Joint.type``) or of a table name."""
    for t in JOINT_TYPES:
        if name in (t.name, t.type):
            return t
    raise KeyError(name)
