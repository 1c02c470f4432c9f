"""The one place for numerical tolerances.

All analyses take a :class:`Tolerances` object; nothing else in the package
hard-codes a threshold.  Division guards (``max(x, TINY)``) and display cut-offs are named
module constants where they are used; tests/test_literals.py fails on a new comparison
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
                    the mean squared row norm of the Jacobian (model/newton.py): small, so that
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


DEFAULT = Tolerances()
