"""What a position solve answers: one assembly mode (``Solution``: every coordinate, its closure,
how singular, rates and accelerations, absolute link motion, why it may not be reachable), the set of
them for the inputs given (``PositionResult``, with how complete the set is: ``modes``), and a Newton
iteration as ``--trace`` shows it (``TraceStep``).  Plain frozen data; analysis.position.position
computes them, present/ writes them.

Units: SI (m, rad, s); twists and accelerations (linear, angular), world axes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

__all__ = ["Solution", "PositionResult", "TraceStep", "NEWTON_FROM_FILE", "search_method"]

#: PositionResult.method where solve's default answered the mode Newton reaches from the file's
#: configuration, and searched nothing (analysis.position.position).
NEWTON_FROM_FILE = "newton from the file's configuration"


def search_method(count) -> str:
    """How a search found its modes, from its certified.ModeCount (None: damped Newton from random starts),
    in the words of PositionResult.method: "closed form (dyads)", "closed form (a univariate polynomial of
    degree n in tan(phi/2))" (a planar platform on three distances), "homotopy search" (with random starts
    where it did not settle every mode), "random starts" or "no loops"."""
    if count is None:
        return "random starts"
    return "homotopy search" if count.method.startswith("monodromy") else count.method


@dataclass(frozen=True)
class TraceStep:
    """One Newton iteration: residual r (solver rows), Jacobian K (free columns), step dq."""

    iteration: int
    residual: np.ndarray
    jacobian: np.ndarray
    step: np.ndarray
    accepted: bool


@dataclass(frozen=True)
class Solution:
    """One assembly mode for the given inputs.

    joints:   every joint coordinate name -> value [rad or m] (continuous and
              revolute angles in (-pi, pi]);
    residual: closure residual norm [m, rad]; iterations: Newton iterations;
    singular: the passive joints are not determined to first order (a double
              root, e.g. a limit position; or a constraint singularity): the
              actuator or constraint measure of screwkin.analysis.singular.measures is
              below the singular tolerance;
    sigma_min: the smaller of those two measures (relative singular values);
    output_pose: 4x4 world pose of the output link, or None;
    rates / accelerations: coordinate name -> rate [rad/s, m/s] /
              acceleration [rad/s^2, m/s^2], or None;
    output_twist / output_acceleration: (v, w) of the output frame origin in
              world axes; classical acceleration (a, alpha);
    labels:   why this mode is not one the mechanism reaches by moving from its
              reference configuration (empty: it is), each "what: names";
    continuum: the inputs leave a finite motion here (solutions joined by it were merged);
    link_angles: planar mechanisms: link name -> absolute angle [rad] (screwkin.analysis.motion.planar.LinkAngles).
    """

    q: np.ndarray = field(repr=False)
    joints: dict
    residual: float
    iterations: int
    singular: bool
    sigma_min: float
    output_pose: np.ndarray | None = None
    rates: dict | None = None
    accelerations: dict | None = None
    output_twist: np.ndarray | None = None
    output_acceleration: np.ndarray | None = None
    qdot: np.ndarray | None = field(default=None, repr=False)
    qddot: np.ndarray | None = field(default=None, repr=False)
    outside_limits: tuple = ()  # joints whose value is outside the file's <limit> (angles compared modulo 2 pi)
    labels: tuple = ()
    continuum: bool = False
    merged: int = 1  # how many distinct solver results this solution stands for
    link_angles: dict | None = None
    sigmas: dict | None = None  # screwkin.analysis.singular.measures at this configuration
    coupled: dict | None = None  # <mimic> joints' values [rad or m] (they have no coordinate)
    loop_joints: dict | None = None  # one-coordinate loop (cut) joints: value [rad or m] (model/state.py)
    loop_rates: dict | None = None  # ... their rates [rad/s or m/s]
    loop_accelerations: dict | None = None  # ... and accelerations [rad/s^2 or m/s^2]
    links: dict | None = None  # link name -> absolute motion (analysis.motion.links.link_motions)
    points: dict | None = None  # named points -> their motion (analysis.motion.links.point_motions)
    linkage: dict | None = None  # a four-bar's diagonal construction (mu, z, alpha, beta) or a slider-crank's mu
    leg_lengths: dict | None = None  # prismatic joint -> distance between the joint centres its leg connects [m]
    guide_angles: dict | None = None  # planar: prismatic joint (tree or loop) -> its slide's angle from the ground's x [rad]
    guide_positions: dict | None = None  # prismatic joint on the ground -> slider's position along its guide [m] (state.py)
    angle_sets: int | None = None  # joint-angle sets that reach this mode (certified search; None: not counted)
    simple: bool | None = None  # a simple root: isolated, its Jacobian of full rank (however ill-conditioned)

    @property
    def physical(self) -> bool:
        """Reached by moving from the reference configuration, within the joint limits."""
        return not self.labels

    @property
    def output_position(self):
        return None if self.output_pose is None else self.output_pose[:3, 3].copy()

    @property
    def output_rpy(self):
        """Roll, pitch, yaw [rad] of the output frame (URDF convention: R = Rz(yaw) Ry(pitch) Rx(roll))."""
        return None if self.output_pose is None else pin.rpy.matrixToRpy(self.output_pose[:3, :3])


@dataclass(frozen=True)
class PositionResult:
    inputs: dict
    input_joints: tuple
    solutions: tuple
    starts: int
    free_dofs: int  # DOFs the inputs leave undetermined (0 when the inputs fix the mechanism)
    trace: tuple = ()
    output: str | None = None
    angular: tuple = ()  # names of the coordinates that are angles (the others are lengths)
    angular_coupled: tuple = ()  # names of the coupled (mimic) joints that are angles
    angular_loop: tuple = ()  # names of the loop (cut) joints with a coordinate that is an angle
    notes: tuple = ()  # what the solver chose that the user should know (a --near value it missed)
    held: dict | None = None  # links held at an absolute angle (--set-angle of a floating link) -> angle [rad]
    modes: object | None = None  # analysis.position.certified.ModeCount: how many modes and how that is known
    #: how the solutions were found: "every joint given", "newton from the file's configuration", "newton from
    #: --near's configuration", "closed form (dyads)", "closed form (a univariate polynomial of degree n in
    #: tan(phi/2))", "homotopy search", "random starts", "no loops"
    method: str = ""

    @property
    def physical(self) -> tuple:
        """The solutions without labels (the modes the mechanism reaches by moving)."""
        return tuple(s for s in self.solutions if s.physical)
