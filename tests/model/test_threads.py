"""Threads can share a mechanism (issue 23 item 1): every computation reads its placements and
Jacobians from a Data of its own (a KinematicState's, or the closure system's per-thread one),
so results do not depend on what another thread (or an earlier call) left in a shared Data.
The reference is the same computation run alone, one configuration at a time."""

from __future__ import annotations

import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pinocchio as pin

import screwkin
from screwkin.analysis.singular import classify
from screwkin.model.state import KinematicState

ROBOTS = Path(__file__).resolve().parents[2] / "robots"


def _work(mech, q, start):
    """Closure solve from a perturbed start, the constraint Jacobian, a frame Jacobian and the
    singularity measures at the result."""
    a = mech.closure.solve(start)
    state = KinematicState(mech, a.q)
    report = classify(mech, a.q, output="platform")
    return (a.q, state.constraint_jacobian, state.link_jacobian("platform"),
            np.array([report.sigmas[k] for k in sorted(report.sigmas)]))


def test_threads_sharing_a_mechanism_get_the_answers_of_one_thread():
    mech = screwkin.load(ROBOTS / "gough_stewart_6ups.urdf")
    q0 = mech.generic_configurations()[1][0]
    rng = np.random.default_rng(3)
    starts = [pin.integrate(mech.model, q0, 0.05 * rng.normal(size=mech.nv)) for _ in range(16)]
    alone = [_work(mech, s, s) for s in starts]
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)  # switch threads as often as Python allows: interleave everything
    try:
        with ThreadPoolExecutor(4) as pool:
            together = list(pool.map(lambda s: _work(mech, s, s), starts * 3))
    finally:
        sys.setswitchinterval(interval)
    for k, got in enumerate(together):
        ref = alone[k % len(starts)]
        for a, b in zip(got, ref, strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)


def test_an_analysis_does_not_depend_on_what_ran_before():
    """The same structure equations whether another configuration was analysed just before."""
    from screwkin.analysis.screws import structure
    mech = screwkin.load(ROBOTS / "arm_6r.urdf")
    q1, q2 = pin.randomConfiguration(mech.model), pin.randomConfiguration(mech.model)
    first = structure(mech, q1)
    structure(mech, q2)
    KinematicState(mech, q2).link_jacobian("flange")
    again = structure(mech, q1)
    for a, b in zip(first, again, strict=True):
        np.testing.assert_array_equal(a["space_jacobian"], b["space_jacobian"])
        np.testing.assert_array_equal(a["g"], b["g"])
