"""The course-solution equations of a mechanism, in symbols (sympy).

Planar mechanisms of revolute and prismatic joints: the vector-loop method
(screwkin.analysis.course.vector_loops: the loops, A, B, c, det A and its conditions); from given
estimates, the textbook Newton iteration on those loops (screwkin.analysis.course.newton).

Spatial (and spherical) mechanisms: the product-of-exponentials structure equations of
each chain (screwkin.analysis.screws.structure) and the constraint Jacobian's rank at the
configuration against its generic rank.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import UsageError
from ...model.linalg import rank
from ..screws import structure
from ..singular import Generic, classify, scaled_jacobians
from .vector_loops import VectorLoops
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import numpy as np
    from screwkin.analysis.course.symbols import PlanarEquations

__all__ = ["SpatialEquations", "equations"]


@dataclass(frozen=True)
class SpatialEquations:
    path: str
    motion_space: str
    chains: tuple  # screwkin.analysis.screws.structure entries
    rows: int  # constraint rows
    columns: int
    rank: int  # rank of K at the configuration
    generic_rank: int
    sigma_min: float  # relative smallest singular value of the dimensionless K (constraint measure)
    singular: bool
    singular_conditions: tuple
    length: float


def _spatial(mech: Mechanism, q: np.ndarray, inputs: list, output) -> SpatialEquations:
    topo = mech.topology(q)
    if not mech.cuts and not output:
        raise UsageError(f"{mech.path}: the mechanism has no loops: give --output LINK for the chain to a link")
    st = structure(mech, q, output)
    K = mech.closure.jacobian(q)
    g = Generic(mech, list(inputs), output)
    S = scaled_jacobians(mech, q)
    r = rank(S.K, mech.tolerances) if S.K.size else 0
    rep = classify(mech, q, inputs=list(inputs), output=output, generic=g)
    sigma = float(rep.sigmas.get("constraint", 1.0))
    singular = bool(rep.constraint)
    conds = []
    if g.rank_K:
        conds.append(f"constraint singularity where the {K.shape[0]} x {K.shape[1]} constraint Jacobian K loses rank: "
                     f"rank K < {g.rank_K} (generic); here rank K = {r}, relative sigma_{g.rank_K} = {sigma:.3g}"
                     + (": SINGULAR" if singular else ": not singular"))
    conds.append(f"actuator singularity where K's passive columns lose rank (rank {g.rank_Kp} generic): relative "
                 f"sigma = {rep.sigmas.get('actuator', 1.0):.3g}" + (": SINGULAR" if rep.actuator else ": not singular"))
    return SpatialEquations(mech.path, topo.motion_space, tuple(st), K.shape[0], K.shape[1], int(r), int(g.rank_K),
                            sigma, singular, tuple(conds), float(S.L))


def equations(mech: Mechanism, q: np.ndarray, inputs: list | None=None, output=None, links: list | tuple = ()) -> PlanarEquations | SpatialEquations:
    """The equations at the assembled configuration q: :class:`PlanarEquations` for planar
    mechanisms of revolute and prismatic joints, rolling and gear pairs (the no-slip law
    substituted: screwkin.analysis.course.rolling), :class:`SpatialEquations` for spatial and
    spherical ones.  ``links``: planar, links whose absolute angle is an input (VectorLoops)."""
    topo = mech.topology(q)
    if topo.motion_space != "planar":
        return _spatial(mech, q, list(inputs) if inputs else list(mech.actuated), output)
    return VectorLoops(mech, q, inputs, links).result()
