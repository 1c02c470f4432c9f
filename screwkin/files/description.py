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
import pinocchio as pin
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Callable

__all__ = [
    "TREE_JOINT_DOF",
    "CUT_JOINT_DOF",
    "JOINT_DYNAMICS",
    "LinkSpec",
    "TargetSpec",
    "TARGETS_NS",
    "TARGET_KINDS",
    "JointSpec",
    "Coupling",
    "Transmission",
    "CutJointSpec",
    "MechanismSpec",
    "placement",
    "resolve_actuation",
    "resolve_chains",
    "Limits",
    "LIMITS",
    "data_bytes",
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

#: A joint's own dynamics kept from the file and written back (JointSpec): MJCF's names.
JOINT_DYNAMICS = ("armature", "damping", "frictionloss")

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
    "helical": 1,  # screw pair: turns by t about the axis and moves lead * t / 2 pi along it
    "rolling": 1,  # two circles (or a circle on a line) rolling without slip, in a plane
    "gear": 1,  # the same with pitch circles
    "contact": 2,  # profiles sliding on each other in a plane (cam, pin in a slot): one row besides the plane's
}

#: Cut-joint types that are not lower pairs (or, helical, need a coupling of unwrapped angles).
HIGHER_PAIRS = ("helical", "rolling", "gear", "contact")

#: Profile shapes of a sliding contact.
PROFILE_SHAPES = ("circle", "line", "point")


@dataclass(frozen=True)
class Limits:
    """What screwkin accepts from a mechanism file: sizes checked before Pinocchio
    sees the file, and bounds beyond which a number is a mistake, not a robot.

    Sizes (the largest real robots we know are far inside them: PAL's tiago_dual
    has 102 links and about 60 moving coordinates, humanoids with hands about 70,
    the biggest parallel robot of the example corpus, kangaroo, 11 loops):

    file_bytes:  20 MB of URDF/SDF text (real URDFs are under 1 MB; generated
                 ones with inline data a few MB).
    elements:    200,000 XML elements (tiago_dual has 3,851, PR2 2,314).
    yaml_bytes:  1 MB of YAML sidecar (real ones are a few hundred bytes).
    links, joints: 2,000 each (tree and fixed joints; 20 times tiago_dual).
    loop_joints: 200 loop (cut) joints (18 times kangaroo's 11).
    meshes:      2,000 distinct mesh files looked for when loading (PR2 names 26);
                 beyond them a missing mesh is not reported (the view still finds each).
    targets: 1,000 ``<screwkin:target>`` elements (a synthesized design has 3 to 200).
    coordinates: 500 moving joint coordinates (nv).  Pinocchio's ``Data`` holds
                 nv x nv x nv tensors: about :func:`data_bytes` = 64 nv^3 bytes
                 (measured: 0.14 GB at nv = 100, 0.6 GB at 200, 4.1 GB and 7.6 s
                 at 400), so a 2,000-link chain would need 512 GB; 500 is 8 GB.

    Magnitudes (checked on every number the file gives; a value beyond them is
    reported as "not a plausible value"):

    length:  10 km for positions (origin xyz, loop-joint xyz, geometry sizes).
    angle:   10,000 rad for rpy angles (1,600 turns; real files stay within 2 pi).
    mass:    1,000 t per link (mining excavators are under 1,000 t); not negative.
    inertia: 1e10 kg m^2 per component (1,000 t at 100 m).
    axis_min, axis_max: length of a joint axis vector: Pinocchio normalizes it
             through its squared norm, which under- or overflows outside about
             1e-150 .. 1e150; real files write unit vectors (or close: 1.9).
    Joint <limit> lower/upper may be any finite value with lower <= upper: ROS and
    Gazebo write +-1e16 and +-1.79769e+308 for "unlimited".
    """

    file_bytes: int = 20_000_000
    elements: int = 200_000
    yaml_bytes: int = 1_000_000
    links: int = 2000
    joints: int = 2000
    loop_joints: int = 200
    meshes: int = 2000
    coordinates: int = 500
    targets: int = 1000
    length: float = 1e4
    angle: float = 1e4
    mass: float = 1e6
    inertia: float = 1e10
    axis_min: float = 1e-6
    axis_max: float = 1e6


#: The limits in force (one place to change them).
LIMITS = Limits()


def data_bytes(nv: int) -> float:
    """Approximate memory of one ``pinocchio.Data`` for nv velocity coordinates [bytes]."""
    return 64.0 * nv**3


def placement(xyz: tuple, rpy: tuple) -> pin.SE3:
    """The pinocchio.SE3 of a URDF ``<origin xyz rpy>``."""

    return pin.SE3(pin.rpy.rpyToMatrix(np.asarray(rpy, float)), np.asarray(xyz, float))


@dataclass
class LinkSpec:
    """A link as written in the file.

    mass: [kg], None when the file gives no ``<inertial>``.
    has_geometry: the link has a visual or collision element.
    inertia_problem: why its mass and inertia cannot be a body's (files/inertia.py), or None.
    """

    name: str
    mass: float | None = None
    has_geometry: bool = False
    inertia_problem: str | None = None

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
    mimic: tuple | None = None  # (joint, multiplier, offset) of a URDF <mimic>, as written
    # the joint's own dynamics, as the file writes them (0: none), per degree of freedom: MJCF armature
    # (a rotor's reflected inertia [kg m^2 or kg]), damping [N m s/rad or N s/m] and frictionloss
    # [N m or N]; URDF <dynamics damping friction> (friction is MuJoCo's frictionloss, as its URDF reader has it)
    armature: float = 0.0
    damping: float = 0.0
    frictionloss: float = 0.0
    # an MJCF hinge's or slide's spring: stiffness [N m/rad or N/m] pulling the joint's value (MuJoCo's
    # qpos) towards springref [rad or m] (0: no spring)
    stiffness: float = 0.0
    springref: float = 0.0

    @property
    def dof(self) -> int:
        return TREE_JOINT_DOF[self.type]

    @property
    def dynamics(self) -> dict:
        """The joint's armature, damping and frictionloss that are not 0, and its spring (stiffness and
        springref) where it has one (name -> value, MJCF's names)."""
        out = {k: getattr(self, k) for k in JOINT_DYNAMICS if getattr(self, k)}
        if self.stiffness:
            out.update(stiffness=self.stiffness, springref=self.springref)
        return out


@dataclass(frozen=True)
class Coupling:
    """A coupling of joint values: ``joint = multiplier * mimics + offset`` [rad or m], from
    URDF ``<mimic>`` elements (a chain of mimics resolved to the first joint of the chain).
    The coupled joint has no coordinate of its own."""

    joint: str
    mimics: str
    multiplier: float
    offset: float


def resolve_chains(links: dict, circle: Callable) -> list:
    """The Couplings of ``links`` (joint -> (joint it follows, multiplier, offset)), each resolved to the
    first joint of its chain: j = m k + o with k = m' p + o' gives j = (m m') p + (m o' + o).  A chain
    that goes round in a circle gives no coupling: ``circle(joint)`` is told (a reader's warning or
    problem)."""
    out = []
    for name in links:
        target, mult, off = links[name]
        seen = {name}
        while target in links:
            if target in seen:
                circle(name)
                break
            seen.add(target)
            t2, m2, o2 = links[target]
            target, mult, off = t2, mult * m2, mult * o2 + off
        else:
            out.append(Coupling(name, target, float(mult), float(off)))
    return out


@dataclass(frozen=True)
class Transmission:
    """How an actuator drives the mechanism, as the file writes it and as screwkin uses it.

    The actuator acts on ``input`` = sum of coef * joint over ``terms`` (one joint with coef 1: a
    joint actuator; several: an MJCF fixed tendon; a coupled joint: its coupling), which the
    couplings make ``scale * joint + offset`` of one joint coordinate ``joint`` (None when it stays a
    combination of several independent coordinates: not an input here).  ``gear``: MuJoCo's gear or
    a ROS ``<mechanicalReduction>``: the actuator's effort is the input's generalized force / gear.
    So the actuator's effort is the joint's generalized force / (scale * gear), and the input's
    value (scale * q + offset) [rad or m, or the tendon's units].  ``word``: what the file calls
    the gear ("gear" in MJCF, "mechanicalReduction" in URDF)."""

    name: str  # what the user calls the input: the tendon's or the (coupled) joint's name
    actuator: str  # the actuator's name: MJCF's, or URDF's <actuator> (else its <transmission>'s)
    kind: str  # "joint", "coupled joint", "tendon"
    terms: tuple  # ((joint, coef), ...) as written
    joint: str | None  # the coordinate it moves
    scale: float = 1.0
    offset: float = 0.0
    gear: float = 1.0
    word: str = "gear"

    @property
    def plain(self) -> bool:
        """A joint's own value, driven one to one: nothing to say about it."""
        return self.kind == "joint" and self.scale == 1.0 and self.offset == 0.0 and self.gear == 1.0

    def text(self) -> str:
        """The transmission in words: ``split = 0.5 right + 0.5 left = 1 left (fixed tendon of actuator 'a')``."""
        written = " + ".join(f"{c:g} {j}" for j, c in self.terms).replace("+ -", "- ")
        out = f"{self.name} = {written}" if self.kind == "tendon" else self.name
        if self.joint is not None and self.kind != "joint":
            out += f" = {self.scale:g} {self.joint}" + (f" {'+' if self.offset >= 0 else '-'} {abs(self.offset):g}"
                                                         if self.offset else "")
        what = {"tendon": "fixed tendon", "coupled joint": "coupled joint", "joint": "joint"}[self.kind]
        out += f" ({what} of actuator {self.actuator!r}" + (f", {self.word} {self.gear:g}" if self.gear != 1.0
                                                             else "") + ")"
        return out


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
    # higher pairs: rolling/gear radii [m] (radius1 inf: a line along F1's x axis), "external" or
    # "internal" contact; contact profiles (shape, radius); helical lead [m per turn]
    radius1: float | None = None
    radius2: float | None = None
    contact: str = "external"
    profile1: tuple | None = None  # (shape, radius or None)
    profile2: tuple | None = None
    lead: float | None = None

    @property
    def dof(self) -> int:
        return CUT_JOINT_DOF[self.type]


#: The XML namespace of screwkin's own elements in a URDF (``<screwkin:targets>``, docs/format.md):
#: urdfdom and Pinocchio skip elements they do not know, and a namespace keeps the name ours.
TARGETS_NS = "urn:screwkin:urdf"
#: What a <screwkin:target> states: a frame's pose, a point, or an angle about a pivot.
TARGET_KINDS = ("pose", "point", "angle")


@dataclass(frozen=True)
class TargetSpec:
    """What a synthesized linkage was designed to do at one precision position, as its file
    states it (``<screwkin:targets>``): with the joint ``input`` at ``value`` [rad or m, the
    file's coordinate], the frame of ``link`` must be at ``xyz`` [m, world] turned ``yaw``
    [rad] about z (``kind`` "pose"), have its origin at ``xyz`` ("point"), or be turned ``yaw``
    about its pivot ``xyz`` ("angle").  ``label``: how a person reads it (the values as typed)."""

    kind: str  # "pose" | "point" | "angle"
    link: str
    input: str
    value: float
    xyz: tuple
    yaw: float | None = None
    label: str = ""


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
    package_dirs: list = field(default_factory=list)  # --package-dir folders for package:// meshes
    couplings: list = field(default_factory=list)  # Coupling, from <mimic>
    targets: tuple = ()  # TargetSpec, from <screwkin:targets> (a synthesized design's precision positions)
    inputs: list = field(default_factory=list)  # Transmission of each actuator that is not a plain joint's
    reference: dict = field(default_factory=dict)  # joint -> value where the file draws it (MJCF ref), when not 0
    # every file the model was read from: the file, its MJCF or xacro includes, the meshes found, the YAML sidecar
    # (an output that is one of them is refused: commands/_options.check_not_read)
    files_read: list = field(default_factory=list)

    @property
    def root(self) -> str:
        children = {j.child for j in self.joints}
        roots = [name for name in self.links if name not in children]
        return roots[0]


def resolve_actuation(spec: MechanismSpec, actuated: list | None=None) -> tuple:
    """The actuated joint names and where they were declared.

    Precedence: the caller's list (the command line), the YAML ``name_mot``,
    then ROS ``<transmission>`` elements (an MJCF file's actuators on joints).  Returns ``(names, source)``;
    ``([], None)`` when nothing declares inputs.
    """
    if actuated:
        return list(actuated), "command line"
    if spec.yaml_actuated:
        return list(spec.yaml_actuated), "yaml name_mot"
    if spec.transmissions:
        return list(spec.transmissions), "mjcf actuator" if spec.format == "mjcf" else "transmission"
    return [], None


def finite(values) -> bool:
    return all(math.isfinite(v) for v in values)
