"""Whether a mass and an inertia tensor can be a rigid body's: the one check, for every reader.

A rigid body's inertia about its centre of mass is positive semi-definite, and its principal
moments A, B, C satisfy the triangle inequality A + B >= C (each is an integral of a sum of two
squared coordinates: A + B = integral of (x^2 + z^2) + (y^2 + z^2) dm >= integral of (x^2 + y^2) dm
= C).  MuJoCo refuses a file whose inertia breaks either ("inertia must satisfy A + B >= C", "inertia
must have positive eigenvalues"); a negative mass is refused by every reader.  Pinocchio takes
any matrix, and the dynamics computed with it are not a body's (a kinetic energy of -29.9 J).

Real robot files break it too (measured over example-robot-data 6.0's 117 files: 56 of their 2,722
inertias, PR2's, Romeo's, ANYmal's, TIAGo's among them), so a URDF reader records the problem on
the link (LinkSpec.inertia_problem) and warns once, and what computes with inertias (dynamics)
refuses such a link when it moves; an MJCF reader refuses it, as MuJoCo does.

Numbers written to a few digits round: a principal moment may fall below zero, or A + B below C,
by ``ROUNDING`` of the largest moment plus ``FLOOR`` (an inertia of 1e-12 kg m^2 is a gram at a
thirtieth of a millimetre, noise of a CAD export), and still be taken as written.
"""

from __future__ import annotations

import numpy as np

from ..errors import quote
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any

__all__ = ["inertia_problem", "inertia_warnings", "ROUNDING", "FLOOR"]

#: Relative slack of the checks (of the largest principal moment): rounding of numbers written to 7 digits.
ROUNDING = 1e-6
#: Absolute slack [kg m^2]: below it an inertia is zero for any body a mechanism file describes.
FLOOR = 1e-12


def inertia_problem(mass: float, *inertia: Any) -> str | None:
    """Why ``mass`` [kg] and the inertia tensor about the centre of mass [kg m^2] cannot be a rigid body's
    (one phrase, naming the numbers), or None when they can.  A mass of None (not given) is not checked.

    Any description's inertial: ``inertia`` is the six numbers a URDF ``<inertia>`` or an MJCF
    ``fullinertia`` writes, ``ixx, iyy, izz[, ixy, ixz, iyz]`` (products 0 when left out), as arguments or
    as one sequence, or the 3 x 3 tensor (in any axes: the checks do not depend on them).  The phrase
    names no file or element (the caller says where: ``link 'x' has ...``)."""
    if mass is not None and mass < 0:
        return f"a negative mass ({mass:g} kg)"
    values = np.asarray(inertia[0] if len(inertia) == 1 else inertia, float)
    if values.shape == (3, 3):
        tensor = values
    elif values.shape in ((3,), (6,)):
        ixx, iyy, izz, ixy, ixz, iyz = (*values, 0.0, 0.0, 0.0)[:6]
        tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], float)
    else:
        raise ValueError(f"inertia_problem: expected 3 or 6 numbers or a (3, 3) tensor, got shape {values.shape}")
    if not np.all(np.isfinite(tensor)):
        return "an inertia that is not finite"
    scale = float(np.abs(tensor).max())
    if np.abs(tensor - tensor.T).max() > ROUNDING * scale + FLOOR:
        return "an inertia tensor that is not symmetric"
    a, b, c = np.linalg.eigvalsh(tensor)  # ascending
    slack = ROUNDING * max(abs(a), abs(c)) + FLOOR
    moments = f"principal moments {a:.4g}, {b:.4g}, {c:.4g} kg m^2"
    if a < -slack:
        return f"an inertia tensor that is not positive (a negative principal moment: {moments})"
    if a + b < c - slack:
        return f"an inertia whose {moments} break the triangle inequality A + B >= C ({a + b:.4g} < {c:.4g})"
    return None


def inertia_warnings(links: dict) -> list:
    """One warning for the links (name -> LinkSpec) whose inertia_problem is set: the first named with
    its problem, the others counted; none when there is none."""
    bad = [(name, link.inertia_problem) for name, link in links.items() if link.inertia_problem]
    if not bad:
        return []
    (name, why), more = bad[0], len(bad) - 1
    others = f" (and {more} more link{'s' if more > 1 else ''})" if more else ""
    return [f"link {quote(name)} has {why}{others}, which no rigid body has: dynamics refuses it where it moves"]
