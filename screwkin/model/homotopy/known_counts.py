"""Published bounds on the number of isolated solutions of classes of mechanism problems, and how a
mechanism is recognized as one: a second certificate for a homotopy's result, where the trace test
would cost too much (analysis.position.certified).  A result that reaches the bound has found them all.

- Stewart-Gough platforms: two rigid bodies joined by six distances (legs whose passive joints are
  revolutes meeting at a point at each end, written as universal and spherical joints, their length
  an input): at most 40 isolated complex assembly modes (Raghavan, ASME J. Mech. Des. 115, 1993,
  found 40 for a general geometry by continuation; Wampler, Mech. Mach. Theory 31, 1996, proved the
  bound of 40 with Study's soma coordinates; Ronga and Vust 1995; Lazard 1993).
- The inverse kinematics of a serial chain of six revolutes with the end's pose given: at most 16
  isolated solutions (Lee and Liang, Mech. Mach. Theory 23, 1988; Raghavan and Roth, ASME J. Mech.
  Des. 115, 1993; Tsai and Morgan 1985 found 16 numerically).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..legs import chain_distance

if TYPE_CHECKING:
    from ..kernel.algebraic import PolynomialClosure

__all__ = ["KnownCount", "known_count"]


@dataclass(frozen=True)
class KnownCount:
    """bound: the most isolated solutions; of: what is counted ("poses": distinct placements of the
    links, "angle sets": joint solutions); what: the class in words; source: where the bound is from."""

    bound: int
    of: str
    what: str
    source: str


STEWART = KnownCount(40, "poses", "a Stewart-Gough platform (two bodies joined by six distances)",
                     "Raghavan 1993; Wampler 1996: at most 40")
SIX_R = KnownCount(16, "angle sets", "the inverse kinematics of a six-revolute serial chain",
                   "Lee and Liang 1988; Raghavan and Roth 1993: at most 16")


def known_count(closure: PolynomialClosure, frozen: np.ndarray, target: bool = False) -> KnownCount | None:
    """The published bound that applies to this polynomial closure (model.kernel.algebraic.PolynomialClosure,
    its legs eliminated), or None.  ``target``: the last cut joint is an inverse-kinematics target."""
    model = closure.model
    kinds = [closure.kind[j] for j in closure.slices]
    if target and len(closure.cuts) == 1 and closure.cuts[0].type == "fixed" and kinds == ["R"] * 6:
        return SIX_R
    rows = [row for row in closure.plan]
    if not closure.legs or any(r[0] != "dist" for r in rows):
        return None
    ground = all(leg.parent == 0 for leg in closure.legs)
    platforms = {model.frames[leg.other].parentJoint for leg in closure.legs}
    if not ground or len(platforms) != 1:
        return None
    joint = platforms.pop()
    if len(closure.legs) == 6 and closure.kind[joint] == "F":
        return STEWART
    if len(closure.legs) == 5 and chain_distance(model, frozen, joint, closure.L) is not None:
        return STEWART
    return None
