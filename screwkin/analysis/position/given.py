"""Every joint given: nothing is unknown, so nothing is solved or searched.

When the input values name every coordinate the loops could move (the usual way to ask about one
pose: every joint of the tree given), the configuration is the one those values set.  The closure is
evaluated there (the solver's rows, as model.kernel.newton judges convergence):
- the loops close -- within the geometry tolerance, scaled by the mechanism's size where it is over
  a metre (values typed to nine digits close to about 1e-9) -- and that configuration is the one
  answer, said with its residual;
- they do not: an error that names each loop joint left open and by how much (its position gap in
  metres, its misalignment in radians), and how to let the loops solve for a joint instead.

Where something is unknown and solve's default answers only the mode asked for (Newton from the file's
configuration, analysis.position.position), ``first_count`` says so in the counts every solve carries.
"""

from __future__ import annotations

import numpy as np

from ...errors import AssemblyError
from ...model.cuts import Assembly
from .certified import ModeCount
from .solution import NEWTON_FROM_FILE
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["unknowns", "given_configuration", "gaps", "first_count"]


def unknowns(solver) -> np.ndarray:
    """The velocity indices the closure would solve for: the passive ones, less the coordinates of
    the multi-coordinate joints no loop passes through (which keep the file's values)."""
    mech = solver.mech
    kept = [np.arange(c.idx_v, c.idx_v + c.nv) for c in (mech.coordinate(j) for j in solver.kept)]
    return np.setdiff1d(solver.passive, np.concatenate(kept).astype(int) if kept else np.zeros(0, int))


def gaps(mech: Mechanism, q: np.ndarray) -> list:
    """[(loop joint or higher pair, position gap [m], misalignment [rad])] of the rows of q's closure that
    are open, the largest first: the minimal rows grouped by the joint they close (model.kernel.closure's
    row labels: ``pos`` rows are distances, the others angles)."""
    r = mech.closure.evaluate(q, jacobian=False)[0]
    out = {}
    for label, value in zip(mech.closure.row_labels(), r):
        name, _, kind = label.rpartition(":")
        pos, ang = out.get(name, (0.0, 0.0))
        if kind.startswith("pos"):
            pos = float(np.hypot(pos, value))
        else:
            ang = float(np.hypot(ang, value))
        out[name] = (pos, ang)
    return sorted(((n, p, a) for n, (p, a) in out.items()), key=lambda g: -max(g[1] / mech.length, g[2]))


def given_configuration(solver, q: np.ndarray) -> tuple:
    """(q wrapped, model.cuts.Assembly, note) of a configuration whose every unknown is given (``q``: the
    values set on the reference configuration): the loops close there; AssemblyError naming the gap
    when they do not."""
    mech, tol = solver.mech, solver.mech.tolerances
    norm = float(np.linalg.norm(mech.closure.evaluate(q, jacobian=False, solver=True)[0]))
    limit = tol.geometry * max(mech.length, 1.0)
    if norm <= limit and not mech.closure.wrong_branch(q):
        q = solver._wrap(q)
        return q, Assembly(q, norm, 0, "every joint given"), \
            f"every joint given: the loops close (residual {norm:.2g}), no search"
    shown = []
    for name, pos, ang in gaps(mech, q)[:3]:
        parts = ([f"{pos:.3g} m apart"] if pos > limit else []) + ([f"misaligned by {ang:.3g} rad"] if ang > limit else [])
        if parts:
            shown.append(f"{name} {' and '.join(parts)}")
    flipped = mech.closure.wrong_branch(q)
    if flipped:
        shown.append(f"{', '.join(flipped)} assembled with a reversed axis")
    raise AssemblyError(mech.path, norm, 0, message=(
        "cannot assemble the mechanism: every joint is given, so nothing is solved, and the loops do not close "
        f"there: {'; '.join(shown) or f'residual {norm:.3g}'}; the loop-closure residual there is {norm:.3g} "
        "(leave out the --set of a joint the loops should solve for, or give the values of a closed configuration)"))


def first_count(first: str, assembly: Assembly) -> ModeCount:
    """The certified.ModeCount of an answer reached without a search: ``first`` says how -- "every joint
    given" (the one configuration: complete) or Newton from the file's configuration (the mode asked
    for; how many others there are is not known: ``--all`` searches)."""
    if first == NEWTON_FROM_FILE:
        return ModeCount(1, False, first, 1, None, None, "only the mode asked for was solved, by Newton from the "
                         "file's configuration (no search); --all searches every mode",
                         {"iterations": int(assembly.iterations)})
    return ModeCount(1, True, first, 1, 0, f"every joint given: the loops close (residual {assembly.residual:.2g}), "
                     "no search", "", {"residual": float(assembly.residual)})

