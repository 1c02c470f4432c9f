"""The one place for numerical tolerances.

All analyses take a :class:`Tolerances` object; nothing else in the package
hard-codes a threshold.  Division guards (``max(x, TINY)``) and display cut-offs are named
module constants where they are used; tests/architecture/test_literals.py fails on a new comparison
against a bare small literal.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Tolerances", "DEFAULT"]


@dataclass(frozen=True)
class Tolerances:
    """Numerical tolerances, with their units.

    closure:        largest accepted loop-closure residual norm [m, rad].
    rank_rtol:      singular values below ``rank_rtol * sigma_max`` count as zero [-].
    rank_atol:      singular values below this always count as zero [same units as the matrix].
    geometry:       tolerance of geometric tests (parallel or intersecting axes,
                    concurrent axes, planarity; two configurations, assembly modes or
                    points the same, a link turned, a joint tilted out of the plane)
                    [m for distances (times the characteristic length where it says so),
                    rad-like for directions].
    dummy_mass:     a link without geometry and lighter than this is a massless
                    link that may sit inside a compound joint [kg].
    singular:       a solution whose passive constraint Jacobian has a relative
                    smallest singular value below this is flagged singular (a
                    double root converges only to about the square root of the
                    closure tolerance, so this is looser than rank_rtol) [-].
    motion:         relative size below which a twist counts as no motion, next to
                    the largest twist of the same analysis [-].
    max_iterations: iteration limit of the closure solver [-].
    lm_damping:     initial damping of the damped-Newton (Levenberg-Marquardt) step, relative to
                    the mean squared row norm of the Jacobian (model/kernel/newton.py): small, so that
                    Newton converges quadratically from a good start [-].
    lm_damping_min: the damping is never lowered below this by accepted steps [-].
    lm_damping_max: a solver whose damping grows past this (every step refused) gives up [-].
    assembly_starts: starting configurations the assembly search tries in all when the
                    file's configuration does not close the loops: ``perturbations``
                    random perturbations of it, then random configurations within the
                    joint limits (seeded: the same file gives the same answer) [-].
    perturbations:  how many of those are perturbations of the file's configuration [-].
    generic_starts: further random configurations closed for the generic ranks: the
                    first configuration that closes may be singular or on a degenerate
                    branch (a student's straight drawing often is), so ranks are taken
                    over it, its neighbours and these, and the largest decides [-].
    samples:        nearby assembled configurations sampled for the generic rank [-].
    sample_step:    size of the random step to a nearby configuration [rad or m].
    max_step:       the longest continuation step a sweep takes [rad, or characteristic lengths]: a
                    coarser grid is followed by shorter steps between its values [-].
    min_step:       the shortest continuation step: a motion no shorter step can continue past a
                    configuration stops there, said so [rad, or characteristic lengths].
    jump:           a continuation step's correction (the closure solve after the tangent's
                    prediction) may move the configuration by at most this fraction of the
                    step; a larger one jumped away from the curve, to another branch [-].
    jump_floor:     a correction this small (dimensionless) is accepted whatever the step [-].
    limit_share:    the input's direction projected on the curve's tangent shorter than this:
                    the configuration is a limit position itself, and the tangent there is the
                    previous one's projected instead [-].
    near_far:       a --near value the chosen mode misses by more than this is said to be missed
                    [rad for angles, times the characteristic length for lengths].
    moves:          a joint moves (in the generic configurations) where its row of the
                    dimensionless motion basis is longer than this [-].
    stationary:     a joint is stationary (its rate forced to zero by the loops; its loop's
                    Gram cofactor zero) where its dimensionless rate is below this [-].
    equal:          two values reached by different routes (a closed form and a solve, the
                    ends of a range, a travel and a precision position) are the same when
                    they differ by less than this, relative to their scale (1 below 1) [-].
    zero:           a value is zero up to the round-off of exact arithmetic when it is below
                    this, relative to its scale (an exactly known constant, a step of nothing,
                    a singular 2x2 system) [-].
    balanced:       statics: the loads balance when the residual of the balance is below
                    this times their size [-].
    indeterminate:  statics: an effort or reaction is indeterminate when the part of it the
                    indeterminate directions change is above this times its size [-].
    local_order:    the local analysis (analysis/local.py) continues the loops' Taylor series to this
                    order at most: what it says holds to this order [-].
    local_form:     a term of that series (a quadratic form on ker K, a higher coefficient) is zero when
                    it is below this, relative to the size of the screws' products of its order [-].
    local_step:     the step along a branch's tangent where the local analysis closes the loops again
                    to confirm the branch (dimensionless: rad, or characteristic lengths) [-].
    local_starts:   starting directions on the unit sphere of ker K from which the roots of several
                    quadratic forms in three or more variables are refined [-].
    local_samples:  the local analysis continues the series along at most this many directions sampled
                    on one tangent space (an irreducible quadric cone on a kernel of dimension d has
                    about d^2 / 4: 361 for a 40-joint loop folded flat, all continued); beyond, an even
                    spread of them, and the answer says so (mobility --local-samples N) [-].
    closed_form:    closed forms (model/subproblems.py, model/leg_chains.py, analysis/position/pieper.py): lines
                    meet at a point, a pivot lies on its axis, a discriminant is not negative, a rotation
                    matrix is not singular, two axes are not parallel, when within this, relative to the
                    scale (the characteristic length for lengths, 1 for directions) [-].
    closed_check:   a closed form's solution is kept when it reproduces its target (a point turned onto
                    another, a leg's direction, a leg's plane) to within this, relative to the scale [-].
    unit_circle:    a root z of a closed form's polynomial in e^{it} is a real angle when |z| is within this
                    of 1; the others are complex solutions [-].
    newton_step:    Newton's refinement of a closed form's root stops when its step is below this [rad].
    stalled:        a Newton solve whose residual (dimensionless) is still above this after six steps and
                    fell by less than half in the last one does not converge (singular loci) [-].
    crossing_rank:  two singular curves cross where the loci's system drops rank: its second smallest
                    singular value below this relative to the largest [-].
    cusp:           a point of a singular curve is a cusp where the plane's velocity along the curve is
                    below this relative to its size on either side [-].

    The homotopy (model/homotopy/: the certified mode search), its path tracker (``track_``, tracking.py)
    and its monodromy and trace test (``homotopy_``, monodromy.py, parameter.py); all dimensionless,
    in the complex coordinates of the polynomial closure [-]:
    track_tol:      a corrected point's last Newton step, relative to 1 + |x|, below which it converged.
    track_target:   the predictor error (the first Newton step, relative) the step size aims at.
    track_contraction: the most the corrector's second Newton step may be of its first (no path jumping).
    track_first_step, track_min_step, track_max_step: step sizes in t (a path whose step falls below
                    track_min_step fails); track_max_steps: steps per path, accepted and refused.
    track_diverge:  |x| beyond which a path goes to infinity.
    track_polish:   Newton iterations at t = 1; track_root_tol: |H| there (before the last), relative to
                    1 + |x|, below which a path has arrived at a root.
    track_max_jump: the most a step may move a point, relative to 1 + |x|.
    track_closed:   a Cauchy endgame's loop has closed when a path is back within this of its start.
    track_endgame:  the Cauchy endgame's radius around t = 1 (a path not arriving at a regular root is
                    tracked to 1 - this, then around the circle).
    homotopy_max_rounds: monodromy rounds in all; homotopy_patience: rounds without a new root before
                    the trace test is tried; homotopy_tries: trace tests before giving up.
    homotopy_trace_tol: the trace test's threshold (a relative singular value).
    homotopy_max_roots: the most roots (orbits) kept, a bound on the work.
    homotopy_newton_starts: random starts of damped Newton added to the trace test's witnesses after a
                    test that did not close.
    homotopy_loop_scale: the monodromy loops' random offsets, relative to the base offset's size;
                    homotopy_loops: new loops a round makes at least.
    homotopy_budget: paths tracked in all, past which the search stops; homotopy_count_budget: the
                    budget of a search a published count settles (no trace test); homotopy_fallback_budget:
                    the budget of a trace test run where a published count was not reached.
    homotopy_trace_limit: the most roots (orbits) the trace test is tried for.
    homotopy_redraws: how many times the trace test may start again with another line and slice.
    homotopy_root:  |G(x) - c0| below which (relative to 1 + |c0|) a point is a root at the base.
    homotopy_closes: every closure row and constraint below this (relative to (1 + |x|)^2) at a target
                    root, or it is a root of the random combination only.
    homotopy_real:  |Im x| below this (relative to 1 + |x|) is a real root.
    homotopy_cauchy: the equations at a Cauchy endgame's estimate below this (relative) make it a
                    finite endpoint.
    homotopy_same:  two roots closer than this (relative) are one.
    """

    closure: float = 1e-10
    rank_rtol: float = 1e-8
    rank_atol: float = 1e-10
    geometry: float = 1e-6
    dummy_mass: float = 1e-4
    motion: float = 1e-6
    singular: float = 1e-4
    max_iterations: int = 200
    lm_damping: float = 1e-9
    lm_damping_min: float = 1e-12
    lm_damping_max: float = 1e10
    assembly_starts: int = 48
    perturbations: int = 8
    generic_starts: int = 4
    samples: int = 3
    sample_step: float = 0.05
    max_step: float = 0.1
    min_step: float = 1e-10
    jump: float = 0.5
    jump_floor: float = 1e-7
    limit_share: float = 1e-7
    near_far: float = 0.5
    moves: float = 1e-6
    stationary: float = 1e-7
    equal: float = 1e-9
    zero: float = 1e-12
    balanced: float = 1e-8
    indeterminate: float = 1e-7
    local_order: int = 6
    local_form: float = 1e-6
    local_step: float = 1e-2
    local_starts: int = 64
    local_samples: int = 400
    closed_form: float = 1e-9
    closed_check: float = 1e-7
    unit_circle: float = 1e-5
    newton_step: float = 1e-15
    stalled: float = 1e-6
    crossing_rank: float = 1e-6
    cusp: float = 1e-6
    track_tol: float = 1e-7
    track_target: float = 1e-4
    track_contraction: float = 0.25
    track_first_step: float = 0.05
    track_min_step: float = 1e-9
    track_max_step: float = 0.3
    track_max_steps: int = 3000
    track_diverge: float = 1e8
    track_polish: int = 3
    track_root_tol: float = 1e-9
    track_max_jump: float = 2.0
    track_closed: float = 1e-6
    track_endgame: float = 0.01
    homotopy_max_rounds: int = 40
    homotopy_patience: int = 2
    homotopy_tries: int = 6
    homotopy_trace_tol: float = 1e-10
    homotopy_max_roots: int = 4000
    homotopy_newton_starts: int = 400
    homotopy_loop_scale: float = 10.0
    homotopy_loops: int = 1
    homotopy_budget: int = 4000
    homotopy_count_budget: int = 30000
    homotopy_fallback_budget: int = 8000
    homotopy_trace_limit: int = 24
    homotopy_redraws: int = 1
    homotopy_root: float = 1e-10
    homotopy_closes: float = 1e-8
    homotopy_real: float = 1e-7
    homotopy_cauchy: float = 1e-6
    homotopy_same: float = 1e-7


DEFAULT = Tolerances()
