"""What a synthesized four-bar may be: where its fixed pivots may go, how long its links may be, its
Grashof type, how small its transmission angle may get -- as penalties a global search minimizes
(zero when met, growing with how far a design is from meeting them, over arrays of designs) and as
a verdict on a finished design.

The transmission angle mu is taken over the motion the task needs: from the first precision
position to the last, the input turning one way (a full turn when the input must turn fully).  Its
extremes there are located in closed form: the diagonal z from the crank's tip to the rocker's
pivot, z^2 = a^2 + g^2 - 2 a g cos(phi), is stationary at phi = 0 and pi only (phi from the ground
line), and mu grows with z (screwkin.analysis.motion.transmission).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ....errors import UsageError
from ...motion.transmission import FOUR_BAR_CLASSES, four_bar_classes, four_bar_cos_mu, four_bar_transmission

__all__ = ["Constraints", "GRASHOF_TYPES", "mu_over", "motion_mu", "grashof_type"]

#: The Grashof types ``--grashof`` takes: the names ``screwkin study`` prints, with "grashof" for any
#: Grashof linkage (s + l < p + q).
GRASHOF_TYPES = ("crank-rocker", "double-crank", "double-rocker", "rocker-crank", "change-point", "non-Grashof",
                 "grashof")
_CODES = {"change-point": 0, "non-Grashof": 1, "crank-rocker": 2, "double-crank": 3, "double-rocker": 4,
          "rocker-crank": 5}
_SHORTEST = {"double-crank": 0, "crank-rocker": 1, "double-rocker": 2, "rocker-crank": 3}  # ground, crank, coupler, rocker


def grashof_type(g: float | np.ndarray, a: float | np.ndarray, b: float | np.ndarray, c: float | np.ndarray, equal: float) -> list:
    """The short Grashof type names (as GRASHOF_TYPES) of four-bars with ground g, crank a, coupler b,
    rocker c (arrays broadcast)."""
    names = {v: k for k, v in _CODES.items()}
    codes = np.atleast_1d(four_bar_classes(g, a, b, c, equal))
    return [names[int(k)] for k in codes]


def mu_over(g: float | np.ndarray, a: float | np.ndarray, b: float | np.ndarray, c: float | np.ndarray, phi0: float | np.ndarray, travel: float | np.ndarray) -> tuple:
    """(mu_min, mu_max) [rad] of four-bars over the crank's motion from phi0 (its angle from the ground
    line A0 -> B0) through ``travel`` (signed, [rad]; |travel| >= 2 pi: a full turn): at the two ends and
    at phi = 0 and pi when the motion passes them.  Arrays broadcast; NaN where z leaves [|b - c|, b + c]
    (the linkage does not assemble there)."""
    g, a, b, c, phi0, travel = np.broadcast_arrays(*(np.asarray(v, float) for v in (g, a, b, c, phi0, travel)))

    def mu(phi: float | np.ndarray) -> np.ndarray:
        with np.errstate(invalid="ignore", divide="ignore"):
            cos = four_bar_cos_mu(g, a, b, c, phi)
        return np.where(np.abs(cos) <= 1, np.arccos(np.clip(cos, -1, 1)), np.nan)

    lo, hi = np.minimum(phi0, phi0 + travel), np.maximum(phi0, phi0 + travel)
    full = np.abs(travel) >= 2 * math.pi
    ends = [mu(phi0), mu(phi0 + travel)]
    vals = np.stack(ends)
    for stationary in (0.0, math.pi):
        k = np.ceil((lo - stationary) / (2 * math.pi))  # the first phi = stationary + 2 pi k at or after lo
        inside = full | (stationary + 2 * math.pi * k <= hi)
        vals = np.concatenate([vals, np.where(inside, mu(np.full_like(phi0, stationary)), np.nan)[None]])
    bad = np.isnan(ends[0]) | np.isnan(ends[1])
    low = np.where(np.isnan(vals), np.inf, vals).min(axis=0)
    high = np.where(np.isnan(vals), -np.inf, vals).max(axis=0)
    return np.where(bad, np.nan, low), np.where(bad, np.nan, high)


def motion_mu(g: float | np.ndarray, a: float | np.ndarray, b: float | np.ndarray, c: float | np.ndarray, phi0: float | np.ndarray, travel: float | np.ndarray, equal: float) -> tuple[np.ndarray, np.ndarray]:
    """(mu_min, mu_max) [rad] over the motion a design runs: the whole turn when its input turns fully
    (a motor keeps turning it: four_bar_transmission's located extremes), else the crank's travel from
    phi0 (mu_over).  Arrays broadcast."""
    lo_t, hi_t = mu_over(g, a, b, c, phi0, travel)
    lo_f, hi_f, turns, _ = four_bar_transmission(g, a, b, c, equal)
    return np.where(turns, lo_f, lo_t), np.where(turns, hi_f, hi_t)


@dataclass(frozen=True)
class Constraints:
    """bounds: ((x0, y0), (x1, y1)), the box the fixed pivots must lie in [m]; lengths: (low, high) of
    every link, the ground's included [m]; grashof: one of GRASHOF_TYPES; min_transmission: mu must stay
    within [this, 180 deg - this] over the motion [rad].  None: not asked."""

    bounds: tuple | None = None
    lengths: tuple | None = None
    grashof: str | None = None
    min_transmission: float | None = None

    def check(self) -> Constraints:
        """These constraints, refused (UsageError, in the options' words) where the box's corners are out
        of order or the length range is not 0 < MIN < MAX: the one check of the command and the API."""
        if self.bounds is not None:
            (x0, y0), (x1, y1) = self.bounds
            if not (x1 > x0 and y1 > y0):
                raise UsageError("--bounds: the second corner must be above and to the right of the first "
                                 "(X1 > X0, Y1 > Y0)")
        if self.lengths is not None and not 0 < self.lengths[0] < self.lengths[1]:
            raise UsageError(f"--lengths: give 0 < MIN < MAX, got {self.lengths[0]:g} m .. {self.lengths[1]:g} m")
        return self

    def tightened(self, length: float, angle: float) -> Constraints:
        """These constraints with a margin (``length`` [m] inside the bounds and the length range,
        ``angle`` [rad] on the transmission angle): a refinement that settles on a constraint's edge then
        stays on its right side of it."""
        bounds = lengths = None
        if self.bounds is not None:
            (x0, y0), (x1, y1) = self.bounds
            bounds = ((x0 + length, y0 + length), (x1 - length, y1 - length))
        if self.lengths is not None:
            lengths = (self.lengths[0] + length, self.lengths[1] - length)
        t = None if self.min_transmission is None else self.min_transmission + angle
        return Constraints(bounds, lengths, self.grashof, t)

    def pivot_box(self, centre: np.ndarray, size: float) -> tuple:
        """(low, high) corners [m] of where a search puts the fixed pivots: the bounds, else ``centre``
        +- 2 ``size`` (the task's own size: its points' or poses')."""
        if self.bounds is not None:
            (x0, y0), (x1, y1) = self.bounds
            return np.array([x0, y0]), np.array([x1, y1])
        return centre - 2 * size, centre + 2 * size

    @property
    def any(self) -> bool:
        return any(v is not None for v in (self.bounds, self.lengths, self.grashof, self.min_transmission))

    def describe(self) -> list:
        """The constraints in words (for the report), one per line."""
        out = []
        if self.bounds is not None:
            (x0, y0), (x1, y1) = self.bounds
            out.append(f"fixed pivots inside x {x0:.6g} .. {x1:.6g} m, y {y0:.6g} .. {y1:.6g} m")
        if self.lengths is not None:
            out.append(f"every link (the ground's too) {self.lengths[0]:.6g} .. {self.lengths[1]:.6g} m long")
        if self.grashof is not None:
            out.append("Grashof: any Grashof linkage (s + l < p + q)" if self.grashof == "grashof"
                       else f"Grashof type: {self.grashof}")
        if self.min_transmission is not None:
            t = math.degrees(self.min_transmission)
            out.append(f"transmission angle {t:.6g} .. {180 - t:.6g} deg over the motion")
        return out

    def penalty(self, A0: np.ndarray, B0: np.ndarray, g: float | np.ndarray, a: float | np.ndarray, b: float | np.ndarray, c: float | np.ndarray, mu_lo: np.ndarray, mu_hi: np.ndarray, scale: float):
        """How far each design is from meeting the constraints (0 where it meets them): lengths over
        ``scale`` plus angles in rad, summed; arrays of designs (A0, B0 (n, 2), the rest (n,))."""
        g, a, b, c = (np.asarray(v, float) for v in (g, a, b, c))
        out = np.zeros(np.broadcast(g, a, b, c).shape)
        if self.bounds is not None:
            (x0, y0), (x1, y1) = self.bounds
            for P in (np.asarray(A0, float), np.asarray(B0, float)):
                out += (np.maximum(x0 - P[..., 0], 0) + np.maximum(P[..., 0] - x1, 0) + np.maximum(y0 - P[..., 1], 0)
                        + np.maximum(P[..., 1] - y1, 0)) / scale
        if self.lengths is not None:
            low, high = self.lengths
            for v in (g, a, b, c):
                out += (np.maximum(low - v, 0) + np.maximum(v - high, 0)) / scale
        if self.grashof is not None:
            L = np.stack([g, a, b, c])
            s, l = L.min(axis=0), L.max(axis=0)
            excess = (s + l - (L.sum(axis=0) - s - l)) / scale  # > 0: non-Grashof
            if self.grashof == "non-Grashof":
                out += np.maximum(-excess, 0)
            elif self.grashof == "change-point":
                out += np.abs(excess)
            else:
                out += np.maximum(excess, 0)
                if self.grashof in _SHORTEST:
                    k = _SHORTEST[self.grashof]
                    others = np.delete(L, k, axis=0).min(axis=0)
                    out += np.maximum(L[k] - others, 0) / scale
        if self.min_transmission is not None:
            t = self.min_transmission
            lo = np.where(np.isnan(mu_lo), 0.0, mu_lo)
            hi = np.where(np.isnan(mu_hi), math.pi, mu_hi)
            out += np.maximum(t - lo, 0) + np.maximum(hi - (math.pi - t), 0)
        return out

    def unmet(self, A0: np.ndarray | tuple, B0: np.ndarray | tuple, g: float | np.ndarray, a: float | np.ndarray, b: float | np.ndarray, c: float | np.ndarray, mu: tuple[float, float] | None, equal: float, tol: float) -> list:
        """What one finished design does not meet (words; empty when it meets them all): ``mu`` its
        (min, max) transmission angle over the motion [rad] or None, ``tol`` [m] the slack on
        positions and lengths."""
        out = []
        if self.bounds is not None:
            (x0, y0), (x1, y1) = self.bounds
            for name, P in (("A0", A0), ("B0", B0)):
                if not (x0 - tol <= P[0] <= x1 + tol and y0 - tol <= P[1] <= y1 + tol):
                    out.append(f"fixed pivot {name} ({P[0]:.6g}, {P[1]:.6g}) is outside the bounds")
        if self.lengths is not None:
            for name, v in (("ground", g), ("crank", a), ("coupler", b), ("rocker", c)):
                if not self.lengths[0] - tol <= v <= self.lengths[1] + tol:
                    out.append(f"{name} {v:.6g} m is outside {self.lengths[0]:.6g} .. {self.lengths[1]:.6g} m")
        if self.grashof is not None:
            got = grashof_type(g, a, b, c, equal)[0]
            ok = got in ("crank-rocker", "double-crank", "double-rocker", "rocker-crank") if self.grashof == "grashof" \
                else got == self.grashof
            if not ok:
                out.append(f"it is a {got} four-bar, not {self.grashof}")
        if self.min_transmission is not None:
            t = self.min_transmission
            if mu is None or mu[0] < t - equal or mu[1] > math.pi - t + equal:
                shown = "unknown" if mu is None else f"{math.degrees(mu[0]):.4g} .. {math.degrees(mu[1]):.4g} deg"
                out.append(f"transmission angle {shown} leaves {math.degrees(t):.4g} .. {180 - math.degrees(t):.4g} deg")
        return out


assert set(FOUR_BAR_CLASSES) and set(_CODES) | {"grashof"} == set(GRASHOF_TYPES)
