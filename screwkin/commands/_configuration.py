"""The configuration a command analyses: its options (--set, --set-angle, --set-length, --near,
--mode), solved for the inputs on the assembly mode chosen, and the words that say which mode it is."""

from __future__ import annotations

import math
import sys

from ..analysis.motion.link_inputs import holding_angles
from ..analysis.position.modes import choose_mode
from ..analysis.position.position import PositionSolver
from ..analysis.position.solution import NEWTON_FROM_FILE
from ..analysis.motion.sweep import BRANCHES
from ..errors import UsageError, quote
from ..model.topology import open_joints
from ._options import count
from ._values import joint_assignments, split_inputs
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    import numpy as np

__all__ = ["add_angle_option", "add_length_option", "add_configuration_options", "add_mode_option", "add_branch_option",
           "input_solver",
           "configuration", "mode_line", "file_configuration_line", "near_values", "with_mode", "moved_not_set"]


def add_angle_option(sp: argparse.ArgumentParser) -> None:
    """--set-angle: an input as a link's absolute angle (planar mechanisms)."""
    sp.add_argument("--set-angle", action="append", metavar="LINK=ANGLE",
                    help="planar mechanisms: an input given as the absolute angle of a link, from the ground's "
                         "x axis (e.g. crank=45deg): a link pinned to the ground sets its joint, any other "
                         "link's angle is held by one more loop equation; its rate is --rate LINK=...")


def add_length_option(sp: argparse.ArgumentParser) -> None:
    """--set-length: an input given as the length of a prismatic leg."""
    sp.add_argument("--set-length", action="append", metavar="JOINT=LENGTH",
                    help="a prismatic input given as its leg's length, the distance between the joint centres it "
                         "connects (e.g. leg1=0.418 or 418mm)")


def add_configuration_options(sp: argparse.ArgumentParser) -> None:
    """--set, --set-angle, --set-length and --near: the configuration a command analyses (see configuration)."""
    sp.add_argument("--set", action="append", metavar="NAME=VALUE", help="input values of the configuration")
    add_angle_option(sp)
    add_length_option(sp)
    sp.add_argument("--near", metavar="NAME=VALUE,...", help="assembly mode nearest this configuration")
    add_mode_option(sp)


def add_mode_option(sp: argparse.ArgumentParser, at: str = "the --set inputs") -> None:
    """--mode K: the K-th assembly mode (configuration() chooses it and says which, of how many)."""
    sp.add_argument("--mode", type=count("mode"), metavar="K",
                    help=f"the K-th assembly mode of {at} (as solve lists them; default 1, the one nearest the "
                         "file's configuration)")


def add_branch_option(sp: argparse.ArgumentParser, what: str = "the motion") -> None:
    """--branch continue|other: what a motion does at a change point (analysis.motion.sweep's branch)."""
    sp.add_argument("--branch", choices=BRANCHES, default=BRANCHES[0],
                    help=f"at a change point of {what} (branches of the motion cross: a parallelogram four-bar "
                         "folding flat), go on along the branch whose tangent continues the motion (continue, the "
                         "default: the parallelogram stays a parallelogram) or along the other one (other)")


def input_solver(mech: Mechanism, inputs: dict | list, held: dict | None = None, output: str | None=None) -> PositionSolver:
    """The PositionSolver of these input joints (names, or split_inputs' values: their keys), with the
    ``held`` links' angles held by their loop equations (a copy of the mechanism:
    analysis.motion.link_inputs.holding_angles); none held, the plain solver of ``mech``."""
    inputs = list(inputs)
    if held:
        return PositionSolver(holding_angles(mech, inputs, held), inputs, output=output)
    return PositionSolver(mech, inputs, output=output)


def configuration(mech: Mechanism, args: argparse.Namespace, moved: dict | None = None, inputs: list | None=None) -> np.ndarray:
    """The configuration a command analyses: solved for --set values (the assembly mode --mode K, else the
    first: the one nearest the file's or --near's), else the assembled file one.  When there are several
    modes, a line on stderr says which one is analysed and how to get the others, and ``args.mode_chosen``
    holds {"index": K, "of": N} for the JSON (commands add it as "mode": with_mode).

    A command that moves inputs (sweep, dynamics, map, workspace) gives their first values as ``moved``
    (they take the place of a --set of the same joint) and its solver's ``inputs`` (default: the joints
    given): the configuration returned is the mode its motion starts from."""
    values, held, _ = split_inputs(mech, args)
    values.update(moved or {})
    near = near_values(mech, args)
    wanted = getattr(args, "mode", None)
    args.mode_chosen = args.continuum = None
    if not values and not held:
        if wanted not in (None, 1):
            raise UsageError(f"--mode {wanted}: the file's own configuration is one mode; give --set values to "
                             "choose among the modes of those inputs")
        if near:
            raise UsageError("--near: the file's own configuration is one mode; give --set values to choose the "
                             "mode of those inputs nearest --near")
        q = mech.generic_configurations()[0].q
        print(f"note: {file_configuration_line(mech, q)}", file=sys.stderr)
        return q
    inputs = list(values if inputs is None else inputs)
    missing = [n for n in inputs if n not in values]
    if missing:
        raise UsageError(f"{mech.path}: give values for the other inputs with --set: {', '.join(missing)}")
    if wanted is not None and wanted > 1 and near:
        raise UsageError(f"--near and --mode {wanted}: give one of them (--near picks the mode nearest a "
                         "configuration, --mode K the K-th of the list of every mode)")
    q, k, n, res = choose_mode(input_solver(mech, inputs, held), values, wanted, near, method="nearest")
    for note in res.notes:  # a --near value the mode found lies far from; a continuum's sample; every joint given
        print(f"note: {note}", file=sys.stderr)
    if res.free_dofs:
        args.continuum = {"free_dofs": res.free_dofs}
    if wanted is not None and wanted > 1 and res.method == "homotopy search":
        print(f"note: --mode {wanted} needs the list of every assembly mode: it was searched (homotopy "
              "continuation; without --mode, Newton answers the mode nearest the file's configuration at once)",
              file=sys.stderr)
    if res.method == NEWTON_FROM_FILE and not res.free_dofs:  # one mode, at once: how many others is not known
        args.mode_chosen = {"index": 1, "of": None, "method": res.method}
        if not getattr(args, "json", False):
            print("note: the assembly mode Newton reaches from the file's configuration (no search: --mode K "
                  "lists every mode and takes the K-th)", file=sys.stderr)
    elif n > 1:
        args.mode_chosen = {"index": k, "of": n}
        if not getattr(args, "json", False):
            print(f"note: {mode_line(k, n, hasattr(args, 'near'))}", file=sys.stderr)
    return q


def mode_line(k: int, n: int, near: bool = True) -> str:
    """The words every command says the assembly mode in: ``assembly mode 1 of 2 (others: --mode 2, or --near)``."""
    others = ", ".join(f"--mode {j}" for j in range(1, n + 1) if j != k)
    return f"assembly mode {k} of {n} (others: {others}{', or --near' if near else ''})"


def file_configuration_line(mech: Mechanism, q: np.ndarray) -> str:
    """What a command analyses when no --set is given, in one line: the file's configuration (assembled,
    when it has loops), with the values it gives the inputs (actuated joints and joints no loop
    passes through; deg or m)."""
    names = list(dict.fromkeys([*mech.actuated, *open_joints(mech)]))
    values = mech.joint_values(q)
    shown = [f"{n} = " + (f"{values[n]:.6g} m" if mech.translational[mech.coordinate(n).idx_v]
                          else f"{math.degrees(values[n]) + 0.0:.6g} deg") for n in names[:8] if n in values]
    more = f", ... ({len(names) - 8} more)" if len(names) > 8 else ""
    what = "the configuration assembled from the file's" if mech.cuts else "the file's configuration"
    return (f"no --set given: {what}" + (f" ({', '.join(shown)}{more})" if shown else "")
            + "; --set NAME=VALUE to choose another")


def near_values(mech: Mechanism, args: argparse.Namespace) -> dict | None:
    """--near NAME=VALUE,...: the configuration whose nearest assembly mode is wanted, as joint values
    (checked as --set's), every name a moving joint of the mechanism (or a multi-coordinate joint's
    ``j[qk]``): the one check of every command that takes --near (an unknown name was ignored by draw,
    export and view).  None when not given."""
    if not getattr(args, "near", None):
        return None
    near = joint_assignments(mech, [args.near], "--near")
    for name in near:
        joint, _, k = name[:-1].rpartition("[q") if name.endswith("]") and "[q" in name else (name, "", "")
        c = mech.coordinate(joint)  # a clear error naming the joints there are
        if k and not (k.isdigit() and int(k) < c.nq):
            raise UsageError(f"--near {quote(name, 60)}: joint {quote(joint)} has no coordinate q{k}")
    return near


def with_mode(args: argparse.Namespace, d: dict) -> dict:
    """``d`` with "mode": {"index", "of"} when the configuration was one of several assembly modes, with
    "continuum": {"free_dofs"} when it was a sample of a continuum the inputs leave (no modes then)."""
    if getattr(args, "mode_chosen", None):
        d["mode"] = args.mode_chosen
    if getattr(args, "continuum", None):
        d["continuum"] = args.continuum
    return d


def moved_not_set(values: dict, moved: str, how: str) -> None:
    """A --set (or --set-angle) value of the input the command moves would be ignored: a usage error
    naming it (sweep --input X --set X=..., dynamics, draw --animate, view --sweep).  ``how``: what moves
    it ("sweep moves it from --from to --to")."""
    if moved in values:
        raise UsageError(f"--set {quote(moved, 60)} (or --set-angle of its link): {how}, so a value of its own "
                         "would be ignored; leave it out")
