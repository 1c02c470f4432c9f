"""Text and JSON of velocity and force ellipsoids (``singularities --ellipsoids``)."""

from __future__ import annotations

import numpy as np

from ..analysis.singularities.ellipsoids import Ellipsoids
from .tables import table

__all__ = ["ellipsoids_dict", "ellipsoids_text"]


#: Display: an axis component below this rounds to 0.000 in the .3f format and is left out.
SHOWN_COMPONENT = 5e-4


def _axis_words(v, rows) -> str:
    parts = [f"{x:+.3f} {name}" for x, name in zip(v, rows) if abs(x) >= SHOWN_COMPONENT]
    return ", ".join(parts) or "0"


def _ratio(s) -> float:
    finite = s[np.isfinite(s)]
    return float(finite.min() / finite.max()) if finite.size and finite.max() > 0 else 0.0


def ellipsoids_dict(e: Ellipsoids) -> dict:
    """JSON: each principal axis (unit vector over ``rows``) with its velocity and force semi-axes
    (dimensionless; a force semi-axis is infinite, "inf" in JSON, along a wrench that loads no input), the
    rank, and the isotropy (smallest over largest velocity semi-axis)."""
    return {
        "output": e.output, "point": e.point, "inputs": list(e.inputs), "characteristic_length": e.length,
        "rows": list(e.rows), "force_rows": list(e.force_rows), "rank": e.rank,
        "velocity_semi_axes": [float(x) for x in e.velocity.semi_axes],
        "force_semi_axes": [float(x) for x in e.force.semi_axes],
        "axes": e.velocity.axes.T.tolist(),
        "isotropy": _ratio(e.velocity.semi_axes),
    }


def ellipsoids_text(e: Ellipsoids) -> str:
    what = f"the origin of '{e.output}'" if e.point else f"'{e.output}'"
    lines = [f"velocity and force ellipsoids of {what}, inputs {', '.join(e.inputs)} "
             f"(dimensionless: linear velocities / L, forces x L, L = {e.length:.6g} m)"]
    rows = []
    for k, (s, f) in enumerate(zip(e.velocity.semi_axes, e.force.semi_axes)):
        rows.append([str(k + 1), f"{s:.6g}", "inf" if not np.isfinite(f) else f"{f:.6g}",
                     _axis_words(e.velocity.axes[:, k], e.rows)])
    lines.append(table(["axis", "velocity semi-axis", "force semi-axis", "direction"], rows))
    lines.append(f"rank {e.rank} of {len(e.rows)}; isotropy (smallest / largest velocity semi-axis) "
                 f"{_ratio(e.velocity.semi_axes):.4g}; a unit input rate vector moves the output along the "
                 "velocity axes by their semi-axes, a unit input effort vector balances output wrenches up to the "
                 "force semi-axes (inf: an output wrench that loads no input)")
    return "\n".join(lines)
