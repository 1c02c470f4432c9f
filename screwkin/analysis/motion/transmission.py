"""How well a four-bar or slider-crank transmits its input's motion, in closed form: the Grashof
class, and the transmission angle's extremes over the input's whole motion -- located, not
read off samples.

Four-bar (ground g = AD, input a = AB, coupler b = BC, output c = DC; the input's angle phi
measured at A from the ground line A -> D).  The diagonal z = |BD| from the input's tip to the
output's pivot obeys z^2 = a^2 + g^2 - 2 a g cos(phi), and the transmission angle mu (at C,
between C -> B and C -> D; triangle BCD) obeys cos(mu) = (b^2 + c^2 - z^2) / (2 b c): mu grows
with z and depends on nothing else, so it is the same on both circuits.  z is stationary only at
phi = 0 (z = |g - a|) and phi = pi (z = g + a).  Where the input turns fully (Grashof
crank-rocker, double crank) these two positions are mu's extremes (the textbook's
mu_min = acos((b^2 + c^2 - (g - a)^2) / 2bc) at phi = 0 and mu_max at phi = pi); where it
rocks, its range ends at the limit positions z = |b - c| (the output dyad folded: mu = 0) or
z = b + c (stretched: mu = 180 deg) and the extremes are there, or at phi = 0 or pi when the
range contains them.  So over the motion z runs over [max(|g - a|, |b - c|), min(g + a, b + c)],
and mu over the images of those ends.

Slider-crank (crank a, rod b, slide offset e from the crank's pivot; phi from the slide's
direction): the rod's component across the slide is s = e - a sin(phi), and mu (between the rod
and the slide's normal) obeys cos(mu) = |s| / b.  Over the motion s runs over
[max(e - a, -b), min(e + a, b)] (the limit positions are where |s| = b: mu = 0), so
mu_max = acos(min |s| / b) (90 deg when s passes 0) and mu_min = acos(max |s| / b).

A dead point is a position of the motion where mu is 0 or 180 deg: the input cannot move the
output there (a limit position of the input, or a change-point linkage folding flat).  The
functions take arrays (one value per design) and broadcast.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...model.geometry import line_angle, nearest_turn, vector_angle

__all__ = ["FOUR_BAR_CLASSES", "four_bar_classes", "four_bar_transmission", "slider_crank_transmission",
           "TransmissionRange", "transmission_range", "transmission_angle", "slide_transmission_angle",
           "four_bar_cos_mu"]

#: The Grashof classes of a four-bar as screwkin words them, by the codes four_bar_classes returns.
FOUR_BAR_CLASSES = (
    "change point (s + l = p + q): the linkage can fold flat",
    "non-Grashof (triple rocker): no link turns fully",
    "Grashof crank-rocker: the input turns fully",
    "Grashof double crank (drag link): input and output turn fully",
    "Grashof double rocker: only the coupler turns fully",
    "Grashof rocker-crank: the output turns fully, the input rocks",
)
_BY_SHORTEST = np.array([3, 2, 4, 5])  # shortest link ground, input, coupler, output -> class code


def four_bar_classes(g, a: float, b: float, c, equal: float) -> np.ndarray:
    """Grashof class codes (indices into FOUR_BAR_CLASSES) of four-bars with ground g, input a,
    coupler b and output c: s + l against p + q (a change point within ``equal`` times the longest
    link), and, for a Grashof linkage, which link is the shortest (the first of ground, input,
    coupler, output when two are)."""
    L = np.stack(np.broadcast_arrays(*(np.asarray(v, float) for v in (g, a, b, c))))
    s, l = L.min(axis=0), L.max(axis=0)
    p_q = L[0] + L[1] + L[2] + L[3] - s - l
    code = _BY_SHORTEST[np.argmin(L, axis=0)]
    code = np.where(s + l > p_q, 1, code)
    return np.where(np.abs(s + l - p_q) < equal * l, 0, code)


def _acos(x: np.ndarray | float) -> np.ndarray | float:
    return np.arccos(np.clip(x, -1.0, 1.0))


def transmission_angle(B: np.ndarray, C: np.ndarray, D: np.ndarray | tuple) -> float:
    """mu [rad] of four-bars from their joint centres: the angle at the coupler-output joint C between
    C -> B (the coupler) and C -> D (the output link), in [0, pi]; points (..., 2) or (..., 3).

    >>> round(float(np.degrees(transmission_angle([0.0, 1.0], [0.0, 0.0], [1.0, 0.0]))), 9)
    90.0
    """
    B, C, D = (np.asarray(v, float) for v in (B, C, D))
    return vector_angle(B - C, D - C)


def slide_transmission_angle(B: np.ndarray, C: np.ndarray, normal: np.ndarray) -> np.ndarray | float:
    """mu [rad] of slider-cranks from the rod's ends B (on the crank) and C (the slider's pin): the angle
    between the rod B -> C and the slide's normal ``normal``, in [0, pi/2]."""
    return line_angle(np.asarray(C, float) - np.asarray(B, float), normal)


def four_bar_cos_mu(g: float, a: float, b: float, c: float, phi: np.ndarray) -> np.ndarray:
    """cos(mu) of four-bars (ground g, input a, coupler b, output c) at the input angle phi [rad] from the
    ground line, from the lengths (module docstring): (b^2 + c^2 - z^2) / (2 b c) with the diagonal
    z^2 = a^2 + g^2 - 2 a g cos(phi); beyond [-1, 1] where the linkage does not assemble at phi."""
    z2 = a * a + g * g - 2 * a * g * np.cos(phi)
    return (b * b + c * c - z2) / (2 * b * c)


def four_bar_transmission(g: float, a: float, b: float, c: float, equal: float) -> tuple:
    """(mu_min, mu_max [rad], turns, dead points) of four-bars over their input's motion (module
    docstring): ``turns`` where the input turns fully; ``dead`` the number of positions of the
    motion where mu is 0 or 180 deg (the two limit positions of an input that rocks, and a
    change point's flat positions, within ``equal`` times the longest link).  At a limit position
    mu is exactly 0 or 180 deg (the output dyad folded or stretched)."""
    g, a, b, c = np.broadcast_arrays(*(np.asarray(v, float) for v in (g, a, b, c)))
    lo = (a * a + g * g - (b + c) ** 2) / (2 * a * g)  # cos(phi) where z = b + c (as planar.identify)
    hi = (a * a + g * g - (b - c) ** 2) / (2 * a * g)  # cos(phi) where z = |b - c|
    stops_low, stops_high = hi < 1, lo > -1  # phi = 0 (pi) is beyond a limit position: z ends at |b - c| (b + c)
    l = np.maximum.reduce([g, a, b, c])
    flat_low = np.abs(np.abs(g - a) - np.abs(b - c)) < equal * l  # z reaches |b - c| at phi = 0
    flat_high = np.abs((g + a) - (b + c)) < equal * l  # z reaches b + c at phi = pi
    # a change point's "limit" at its flat position is round-off: the input passes it (turning fully)
    stops_low, stops_high = stops_low & ~flat_low, stops_high & ~flat_high
    turns = ~stops_low & ~stops_high
    with np.errstate(invalid="ignore", divide="ignore"):
        mu_min = _acos((b * b + c * c - (g - a) ** 2) / (2 * b * c))
        mu_max = _acos((b * b + c * c - (g + a) ** 2) / (2 * b * c))
    mu_min = np.where(stops_low | flat_low, 0.0, mu_min)
    mu_max = np.where(stops_high | flat_high, np.pi, mu_max)
    inside = (~stops_low & flat_low).astype(int) + (~stops_high & flat_high).astype(int)
    dead = np.where(turns, inside, 2 + inside)
    return mu_min, mu_max, turns, dead


def slider_crank_transmission(a: float, b: float, e: float, equal: float) -> tuple:
    """(mu_min, mu_max [rad], turns, dead points) of slider-cranks (crank a, rod b, offset e) over
    the crank's motion (module docstring)."""
    a, b, e = np.broadcast_arrays(*(np.asarray(v, float) for v in (a, b, e)))
    e = np.abs(e)  # the extremes are those of |s|: the offset's side does not matter
    turns = a + e <= b
    s_lo, s_hi = np.maximum(e - a, -b), np.minimum(e + a, b)
    far = np.maximum(np.abs(s_lo), np.abs(s_hi))
    near = np.where((s_lo <= 0) & (s_hi >= 0), 0.0, np.minimum(np.abs(s_lo), np.abs(s_hi)))
    flat = np.abs(a + e - b) < equal * np.maximum(b, a + e)  # |s| reaches b at phi = -pi/2 of a turning crank
    with np.errstate(invalid="ignore", divide="ignore"):
        mu_min = np.where(~turns | flat, 0.0, _acos(far / b))
        mu_max = _acos(near / b)
    dead = np.where(turns, flat.astype(int), 2)
    return mu_min, mu_max, turns, dead


@dataclass(frozen=True)
class TransmissionRange:
    """The transmission angle over the input's whole motion on the circuit of the configuration
    analysed (a full turn, or from limit position to limit position), located in closed form."""

    low: float  # smallest mu [rad]
    high: float  # largest mu [rad]
    low_at: tuple  # input joint values where mu is smallest [rad]
    high_at: tuple
    turns: bool  # the input turns fully
    dead_points: int  # positions where mu is 0 or 180 deg
    dead_at: tuple  # their input joint values [rad]

    @property
    def deviation(self) -> float:
        """The largest |90 deg - mu| over the motion [rad]: how far the linkage gets from pushing
        the output square."""
        return float(max(math.pi / 2 - self.low, self.high - math.pi / 2))


def _mu_at(info, phi: np.ndarray):
    """mu [rad] at input angles phi (from the ground line, or the slide's direction)."""
    L = info.lengths
    if info.kind == "four-bar":
        return _acos(four_bar_cos_mu(L["ground"], L["input"], L["coupler"], L["output"], phi))
    s = info.signed_offset - L["crank"] * np.sin(phi)
    return _acos(np.abs(s) / L["rod"])


def transmission_range(info, equal: float) -> TransmissionRange:
    """The transmission angle's extremes over the input's motion for a planar.LinkageInfo: the
    values from the lengths (four_bar_transmission, slider_crank_transmission: the same numbers a
    study's family path computes), and where they are reached: the input values among the
    stationary positions of z (phi = 0, pi) or s (phi = +-pi/2, s = 0) and the ends of the input's
    range where it has one."""
    L = info.lengths
    if info.kind == "four-bar":
        values = four_bar_transmission(L["ground"], L["input"], L["coupler"], L["output"], equal)
        phis = [0.0, math.pi]
    else:
        values = slider_crank_transmission(L["crank"], L["rod"], info.signed_offset, equal)
        ratio = info.signed_offset / L["crank"]
        phis = [math.pi / 2, -math.pi / 2]
        if abs(ratio) <= 1:
            phis += [math.asin(ratio), math.pi - math.asin(ratio)]
    low, high, turns, dead = (v.item() for v in values)
    offset = info.input_value - info.input_angle  # joint value = phi + offset
    if info.input_range is None or turns:  # (a change point's range is a turn less round-off)
        xs = [offset + phi for phi in phis]
        xs = [nearest_turn(x, info.input_value) for x in xs]
        ends = []
    else:
        lo_x, hi_x = info.input_range
        xs = []
        for phi in phis:
            k0 = math.ceil((lo_x - offset - phi) / (2 * math.pi))
            xs += [offset + phi + 2 * math.pi * k for k in range(k0, k0 + 2) if lo_x <= offset + phi + 2 * math.pi * k <= hi_x]
        ends = [lo_x, hi_x]
    mus = _mu_at(info, np.array(xs + ends) - offset)
    if ends:  # the limit positions: mu exactly 0 or 180 deg
        mus[len(xs):] = np.where(mus[len(xs):] < math.pi / 2, 0.0, math.pi)
    cand = xs + ends
    near = 1e-12 * math.pi  # candidates at the same extreme (round-off apart)
    low_at = tuple(sorted(float(x) for x, m in zip(cand, mus) if m <= mus.min() + near))
    high_at = tuple(sorted(float(x) for x, m in zip(cand, mus) if m >= mus.max() - near))
    dead_at = {float(x) for x in ends}
    if low == 0.0:  # a change point folding flat (mu = 0 within the tolerance of its class)
        dead_at |= set(low_at)
    if high == math.pi:
        dead_at |= set(high_at)
    return TransmissionRange(float(low), float(high), low_at, high_at, bool(turns), int(dead), tuple(sorted(dead_at)))
