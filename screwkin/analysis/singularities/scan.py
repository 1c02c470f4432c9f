"""Singularity scan of a serial chain over random configurations within its joint limits.

Where in its joint space does a serial arm lose a direction of motion of its
output link?  The chain's output Jacobian (twist (v, w) of the output frame
origin, world axes, translations divided by a characteristic length L) is
evaluated at many random configurations by the batched structure equations of
screwkin.analysis.singularities.batch, with one of two measures:

- ``sigma_ratio``: smallest over largest singular value (1 isotropic, 0 singular),
  the measure ``screwkin singularities`` reports for serial singularities;
- ``det``: the determinant (6-joint chains), independent of the frame and of L.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...errors import UsageError
from ...model.manifold import set_continuous_angle
from .batch import SerialJacobians
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["ScanResult", "scan"]

MEASURES = ("sigma_ratio", "det")


@dataclass(frozen=True)
class ScanResult:
    output: str
    joints: tuple  # the chain's joints, base to tip
    measure: str
    length: float  # characteristic length L [m] (translations divided by it for sigma_ratio)
    threshold: float  # sigma_ratio below this counts as singular (the tolerances' "singular")
    seed: int
    Q: np.ndarray  # (N, nq) sampled configurations
    theta: np.ndarray  # (N, n) the chain joints' values [rad or m]
    values: np.ndarray  # (N,) the measure at each
    point: bool = False  # the output's origin analysed as a point

    @property
    def samples(self) -> int:
        return len(self.values)

    @property
    def worst(self) -> int:
        """Index of the configuration nearest a singularity."""
        return int(np.argmin(np.abs(self.values)))

    def singular_fraction(self) -> float | None:
        if self.measure != "sigma_ratio":
            return None
        return float(np.mean(self.values < self.threshold))


def scan(mech: Mechanism, output: str, samples: int = 100000, seed: int = 0, measure: str = "sigma_ratio",
         length: float | None = None, workers: int | None = None, method: str = "svd",
         point: bool = False) -> ScanResult:
    """Sample ``samples`` configurations of the chain from the ground to ``output``,
    uniform within the joint limits (revolute joints without limits: a full turn), and
    evaluate the measure at each.  Mechanisms with closed loops are refused: their
    configurations are not free to sample (``screwkin map`` and ``sweep --singularities``
    scan them along their inputs).  length: the characteristic length [m] (default
    ``mech.length``, the same as every other command); point: the output's origin as a
    point (3 translations; sigma_ratio only)."""

    if measure not in MEASURES:
        raise UsageError(f"unknown measure '{measure}': {' or '.join(MEASURES)}")
    if samples < 1:
        raise UsageError("the number of samples must be at least 1")
    if mech.cuts:
        raise UsageError(f"{mech.path}: scan samples the configurations of a serial chain; this mechanism has "
                         f"{len(mech.cuts)} closed loop(s): use `screwkin map` or `screwkin sweep --singularities`")
    sj = SerialJacobians(mech, output, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    chain = sj.chain
    if measure == "det" and point:
        raise UsageError("--point takes the sigma_ratio measure (a 3 x n Jacobian has no determinant)")
    if measure == "det" and len(chain.joints) != 6:
        raise UsageError(f"{mech.path}: the chain to '{output}' has {len(chain.joints)} joints: a determinant needs "
                         "six (a square Jacobian); use --measure sigma_ratio")
    model = mech.model
    rng = np.random.default_rng(seed)
    Q = np.tile(mech.neutral(), (samples, 1))
    theta = np.empty((samples, len(chain.joints)))
    for k, name in enumerate(chain.joints):
        c = mech.coordinate(name)
        lo, hi = model.lowerPositionLimit[c.idx_q], model.upperPositionLimit[c.idx_q]
        prismatic = "JointModelP" in model.joints[c.joint_id].shortname()
        if c.nq == 2:  # continuous
            lo, hi = -np.pi, np.pi
        elif prismatic and not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
            raise UsageError(f"{mech.path}: prismatic joint '{name}' has no finite <limit> range: the scan "
                             "cannot sample it")
        elif not prismatic and not (np.isfinite(lo) and np.isfinite(hi) and 0 < hi - lo <= 2 * np.pi):
            lo, hi = -np.pi, np.pi
        x = rng.uniform(lo, hi, samples)
        theta[:, k] = x
        if c.nq == 2:
            set_continuous_angle(Q, c.idx_q, x)
        else:
            Q[:, c.idx_q] = x
    L = float(length) if length else mech.length
    workers = workers or os.cpu_count() or 1
    if measure == "det":
        values = sj.measures(Q, "det", workers=workers)
    else:
        values = sj.measures(Q, "sigma_ratio", scale_translation=L, workers=workers, method=method, point=point)
    return ScanResult(output, tuple(chain.joints), measure, L, mech.tolerances.singular, seed, Q, theta, values,
                      point)
