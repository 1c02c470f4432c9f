"""Plain results of linkage synthesis: frozen dataclasses that never format themselves
(screwkin/present/synthesis.py writes them as text and JSON).

Conventions: lengths in metres, angles in radians, points and poses in the plane of the
linkage (z = 0) in the ground's frame.  A pose is (x, y, theta): the origin of a frame and
the angle of its x axis from the ground's x axis, counterclockwise.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ....errors import MechanismFileError

__all__ = ["SynthesisError", "FourBar", "Target", "Dyad", "Design", "MotionResult", "FunctionResult",
           "PathResult", "PrecisionCheck", "Check", "Chain", "ChainFile", "ChainsResult", "Candidate"]


class SynthesisError(MechanismFileError):
    """No linkage (or no acceptable one) for the request: exit code 1, one line naming what
    was asked (``synthesize motion``) and why."""

    def __init__(self, what: str, problem: str) -> None:
        super().__init__(what, problem)


@dataclass(frozen=True)
class FourBar:
    """A planar four-bar at its first (drawn) position: ground pivots A0 (the crank's, the
    input) and B0 (the rocker's, the output), moving pivots A (crank-coupler) and B
    (coupler-rocker), and ``tool``: the pose (x, y, theta) of the frame guided by the coupler
    (a coupler point: theta is the coupler's own angle, unused), or None."""

    A0: tuple
    A: tuple
    B: tuple
    B0: tuple
    tool: tuple | None = None

    @property
    def lengths(self) -> dict:
        """ground A0B0, crank A0A, coupler AB, rocker B0B [m]."""
        d = lambda p, q: float(np.hypot(p[0] - q[0], p[1] - q[1]))  # noqa: E731
        return {"ground": d(self.A0, self.B0), "crank": d(self.A0, self.A), "coupler": d(self.A, self.B),
                "rocker": d(self.B0, self.B)}


@dataclass(frozen=True)
class Target:
    """What the linkage must do at one precision position: ``kind`` "pose" (x, y, theta of the
    guided frame), "point" (x, y of the coupler point) or "angle" (the output link's angle,
    (psi,)), at the input joint value ``input`` [rad] (from the file's configuration, which
    is the first precision position)."""

    kind: str
    value: tuple
    input: float
    label: str = ""


@dataclass(frozen=True)
class Dyad:
    """A crank (or rocker) of a four-bar: its fixed pivot (centre point), its moving pivot at
    the first position (circle point, world) and in the coupler's frame (``local``)."""

    fixed: tuple
    moving: tuple
    local: tuple

    @property
    def length(self) -> float:
        return float(np.hypot(self.moving[0] - self.fixed[0], self.moving[1] - self.fixed[1]))


@dataclass(frozen=True)
class Design:
    """A synthesized four-bar ready to be written: its geometry, the linkage description
    for screwkin.files.writer, what it must do (targets), the joint that drives it and the
    link whose motion is checked."""

    kind: str  # "motion" | "function" | "path"
    fourbar: FourBar
    linkage: object  # screwkin.files.writer.PlanarLinkage
    targets: tuple  # Target
    input_joint: str = "crank_joint"
    output_link: str = "coupler_frame"
    span: tuple | None = None  # (low, high) input values the motion must cover; None: a full turn either way
    notes: tuple = ()
    exact: bool = True  # the targets are met exactly (False: least squares; a miss is not a defect)
    input_offset: float | None = None  # function generation: the crank's phi as typed at crank_joint = 0 [rad]


@dataclass(frozen=True)
class Candidate:
    """One design a constrained global search found (analysis.design.synthesis.optimal), judged in
    closed form: ``error`` the largest miss of a precision position (m; a function generator's in rad),
    ``rms`` their root mean square, ``transmission`` (min, max) over the motion [rad] or None,
    ``grashof`` its type (as study prints it), ``defects`` (branch, order, limit: words) and ``unmet``
    (the constraints it does not meet: words; empty when it meets them all)."""

    design: Design
    error: float
    rms: float
    transmission: tuple | None
    grashof: str
    defects: tuple
    unmet: tuple
    run: str  # which run of the search found it (its branch, direction)

    @property
    def feasible(self) -> bool:
        return not self.unmet


@dataclass(frozen=True)
class MotionResult:
    """Motion generation: the poses, the dyads offered (candidates) and the pair chosen."""

    poses: tuple  # (x, y, theta)
    method: str  # "three positions, fixed pivots given" | ... | "Burmester (four positions)" | ...
    candidates: tuple  # Dyad
    pick: tuple  # (crank index, rocker index) into candidates
    design: Design
    curves: tuple = ()  # for pictures: ((centre points (n, 2), circle points (n, 2)), ...) per 4-position subset
    poles: tuple = ()  # ((i, j, (x, y)), ...) poles of the displacements between positions
    ranked: tuple = ()  # ((crank, rocker, score), ...) pairs in the order they were tried
    search: object = None  # search.SearchReport of a constrained global search, or None


@dataclass(frozen=True)
class FunctionResult:
    """Function generation (Freudenstein): psi = psi(phi) through the precision points."""

    function: str
    x_range: tuple
    input_range: tuple  # (phi0, phi1) [rad]
    output_range: tuple  # (psi0, psi1) [rad]
    spacing: str
    x: tuple  # precision points
    phi: tuple
    psi: tuple
    K: tuple  # (K1, K2, K3) of K1 cos(phi) - K2 cos(psi) + K3 = cos(phi - psi)
    least_squares: bool
    sample_x: np.ndarray = field(repr=False)  # dense sample of the range
    structural_error: np.ndarray = field(repr=False)  # psi_generated - psi_desired [rad] there (nan: not assembled)
    error_at_points: tuple = ()  # [rad]
    design: Design | None = None
    defects: tuple = ()  # found in closed form (the check finds them again with screwkin)
    search: object = None  # search.SearchReport of a constrained global search, or None

    @property
    def max_structural_error(self) -> float:
        e = np.abs(self.structural_error)
        return float(np.nanmax(e)) if np.isfinite(e).any() else float("nan")


@dataclass(frozen=True)
class PathResult:
    """Path generation: a coupler point through the points, by least squares."""

    points: tuple
    timing: tuple | None  # prescribed crank angles (relative to the first point) [rad], or None
    crank_angles: tuple  # crank joint values at the points, from the first [rad]
    errors: tuple  # distance from each point to the coupler point there [m]
    starts: int
    converged: int  # polished starts that reached every point within the tolerance
    tolerance: float
    design: Design
    search: object = None  # search.SearchReport of a constrained global search, or None


@dataclass(frozen=True)
class PrecisionCheck:
    """One precision position as the written file reaches it (PositionSolver.solve)."""

    target: Target
    reached: bool  # within the tolerance
    value: tuple  # what the file gives: pose (x, y, theta) / point (x, y) / (psi,)
    error: float  # position error [m] (pose, point) or angle error [rad] (angle)
    angle_error: float  # pose: orientation error [rad]; else 0
    residual: float  # closure residual of the solution
    closed_form_error: float  # distance between the file's solution and the closed-form four-bar there


@dataclass(frozen=True)
class Check:
    """A written design checked with screwkin's own analyses."""

    file: str
    assembled_iterations: int  # Newton iterations to close the file's configuration (0: drawn closed)
    precision: tuple  # PrecisionCheck
    grashof: str | None
    lengths: dict
    transmission_range: tuple | None  # (min, max) [rad] over the motion between the precision positions
    defects: tuple  # strings
    direction: int  # +1 counterclockwise crank motion, -1 clockwise, 0 undecided
    travel: tuple  # crank travel [rad] from the first position to each position (None: not reached)
    tolerance: float
    letters: dict = field(default_factory=dict)  # joint name -> its letter in `draw` (course.skeleton.numbering)

    @property
    def valid(self) -> bool:
        return not self.defects


@dataclass(frozen=True)
class Chain:
    """A kinematic chain: links as nodes, joints as edges ((i, j, "R" | "P"))."""

    index: int
    name: str
    links: int
    joints: tuple
    degrees: tuple  # joints on each link
    automorphisms: int
    inversions: tuple  # one ground link per class of links under the chain's automorphisms
    orbits: tuple  # the classes themselves
    inversion_names: tuple = ()  # per inversion: "Watt I" ... "Stephenson III" (model.six_bar), else None


@dataclass(frozen=True)
class ChainFile:
    """One mechanism (a chain with a ground link) written and checked."""

    chain: int
    ground: int
    file: str
    assembled_iterations: int
    mobility: int | None
    problem: str = ""


@dataclass(frozen=True)
class ChainsResult:
    links: int
    dof: int
    prismatic: int
    joints: int
    chains: tuple  # Chain
    files: tuple = ()  # ChainFile
    candidates: int = 0  # graphs looked at (after the degree and rigidity pruning)
