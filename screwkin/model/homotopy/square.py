"""The closure's rows made a square system: as many equations as unknowns (the model.homotopy.monodromy
family G(x) = c, with c = 0 the closed mechanism).

Rows beyond the count (a revolute cut joint's three alignment rows where two are independent, a
weld's six) are combined by a random complex matrix (Sommese and Wampler 2005, section 13.5:
randomization keeps every isolated root isolated); roots of the combination that are not roots of
every row are told apart afterwards (``closes``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..kernel.algebraic import PolynomialClosure

__all__ = ["SquareSystem"]


class SquareSystem:
    """As many equations as tangent coordinates: the m rows of a PolynomialClosure taken down to nt
    by a random complex combination A (none when m = nt).  Roots of the combination that are not
    roots of every row (spurious) are told apart by ``closes``.  The equations are offsets in the
    sense of model.homotopy.monodromy: G(x) = c with c = 0 the closed mechanism."""

    def __init__(self, closure: PolynomialClosure, rng: np.random.Generator) -> None:
        self.closure = closure
        self.n, self.width = closure.nt, closure.n
        need, m = closure.nt, closure.m
        if m < need:
            raise ValueError(f"{m} independent closure rows for {need} unknowns")
        self.A = None if m == need else (rng.normal(size=(need, m)) + 1j * rng.normal(size=(need, m))) / np.sqrt(2 * m)

    def equations(self, X: np.ndarray, jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        r, J = self.closure.rows(X, jacobian)
        if self.A is None:
            return r, J
        return r @ self.A.T, (np.einsum("ij,pjk->pik", self.A, J) if jacobian else None)

    def offsets(self, X: np.ndarray) -> np.ndarray:
        """The offset c for which X solves G(x) = c."""
        return self.equations(X, jacobian=False)[0]

    def retract(self, X: np.ndarray, dT: np.ndarray) -> np.ndarray:
        return self.closure.retract(X, dT)

    def tangent(self, X: np.ndarray) -> np.ndarray:
        return self.closure.tangent(X)

    def on_variety(self, X: np.ndarray, tol: float = 1e-10) -> np.ndarray:
        """(P,) whether X keeps the circles and unit quaternions to round-off (relative to |x|^2)."""
        g = np.abs(self.closure.constraints(X[:, :self.width])).max(axis=1, initial=0.0)
        return g <= tol * (1.0 + np.abs(X).max(axis=1)) ** 2

    def closes(self, X: np.ndarray) -> np.ndarray:
        """(P,) the largest of every closure row (uncombined) and constraint at X."""
        g = self.closure.constraints(X)
        r = self.closure.residual_all(X)
        return np.maximum(np.abs(g).max(axis=1, initial=0.0), np.abs(r).max(axis=1, initial=0.0))
