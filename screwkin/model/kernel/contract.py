"""The one contract between the loops and the closure rows: ``ClosureKernel``.

Every execution strategy of the loop-closure rows implements it (model.kernel.closure: Pinocchio,
one configuration at a time; model.kernel.compiled: the same rows compiled by numba;
model.kernel.stacks: numpy, a stack of configurations in one pass; model.kernel.algebraic:
polynomials in complex unknowns), and the loops take it (model.kernel.newton: the damped solve and
the undamped polish; the local analysis's confirmation, rows plus held rows).  What a backend
cannot give it says by raising ``NotProvided`` (a ``NotImplementedError``), never by lacking the
method.  tests/model/kernel/test_kernel_contract.py checks every backend against Pinocchio's.

Shapes: N configurations in a stack; nq coordinates and nv velocity columns per configuration
(the polynomial backend: its complex unknowns and their tangent coordinates); m rows.
"""

from __future__ import annotations

import abc
from typing import Any
from collections.abc import Callable

from numpy.typing import NDArray

from .scaling import dimensionless
from ..linalg import complement

__all__ = ["ClosureKernel", "NotProvided", "Step", "Verdict"]

Array = NDArray[Any]

#: step(K (n, m, nv), r (n, m), free (k,), mu (n,)) -> (dQ_free (n, k), predicted squared decrease (n,))
Step = Callable[[Array, Array, Array, Array], tuple[Array, Array]]
#: the damped loop's verdict on a step (model.kernel.newton.judge, or its compiled form)
Verdict = Callable[..., tuple[Array, Array, Array, Array, Array]]


class NotProvided(NotImplementedError):
    """A backend that cannot give a method of the contract raises this: the polynomial rows have no
    constraint Jacobian in Pinocchio's velocities and no acceleration term; a stack with a target
    (a workspace grid's inverse kinematics) has no acceleration term."""


class ClosureKernel(abc.ABC):
    """The loop-closure rows r(q) = 0 of a mechanism, evaluated on a stack of configurations.

    Attributes every backend sets: ``nq`` and ``nv`` (coordinates and velocity columns of one
    configuration), ``m`` (rows of ``evaluate``), ``length_rows`` (m,) bool (the rows of
    ``evaluate`` that are lengths [m]), ``sliding`` (the velocity columns of sliding joints [m]).
    """

    nq: int
    nv: int
    m: int
    length_rows: Array
    sliding: Array

    @abc.abstractmethod
    def evaluate(self, Q: Array, jacobian: bool = True) -> tuple[Array, Array | None]:
        """The rows the solver drives to zero at each configuration of Q (N, nq): r (N, m), and with
        ``jacobian`` their derivative along the velocity columns K (N, m, nv) = dr/dv (else None).
        For the Pinocchio and stacked backends these are ClosureSystem.evaluate(solver=True)'s rows
        (orientations as differences of world vectors, whose only root is the joint's)."""

    @abc.abstractmethod
    def integrate(self, Q: Array, V: Array) -> Array:
        """Q (N, nq) moved by the velocity steps V (N, nv) on the configuration manifold (pin.integrate
        for a stack; the polynomial backend: along its circles and spheres): (N, nq)."""

    def constraint_jacobian(self, Q: Array) -> Array:
        """The minimal rows' Jacobian K0 (N, m0, nv) at configurations Q (N, nq) that close the loops:
        6 - dof rows per cut joint, the constraint wrenches in (force, moment) order (ClosureSystem's
        ``jacobian``).  Raises NotProvided where the backend has no such rows."""
        raise NotProvided(f"{type(self).__name__} has no constraint Jacobian")

    def bias(self, Q: Array, V: Array) -> Array:
        """The acceleration term K0'(q, v) v (N, m0) of the minimal rows at Q (N, nq) moving at V
        (N, nv) with zero joint accelerations: K0 a + bias = 0 is the closure differentiated twice.
        Raises NotProvided where the backend has no such term."""
        raise NotProvided(f"{type(self).__name__} has no acceleration term")

    def free_columns(self, frozen: Any) -> Array:
        """The velocity indices (k,) not in ``frozen`` (a sequence of indices): the columns a solve moves."""
        return complement(self.nv, frozen)

    def dimensionless(self, K: Array, length: float) -> Array:
        """K (..., m, nv) of ``evaluate`` made dimensionless with the characteristic length [m]
        (model.kernel.scaling: length rows / length, sliding columns * length), a copy."""
        return dimensionless(K, self.length_rows, self.sliding, length)

    def reversed_joints(self, q: Array, placed: bool = False) -> list[str]:
        """The cut joints that configuration q (nq,) assembles with a reversed axis (a root of the
        solver's rows that is not the joint); ``placed``: the backend's own placements are already
        q's.  None by default (a backend whose rows have no such root)."""
        return []

    def newton_parts(self) -> tuple[Step, Verdict] | None:
        """The damped loop's step and verdict for this backend (compiled ones), or None: the loop's
        own (model.kernel.newton.stacked_steps, model.kernel.newton.judge)."""
        return None

    @property
    def name(self) -> str:
        """What error messages call the mechanism (its file)."""
        return "<mechanism>"
