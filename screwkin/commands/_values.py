"""Joint values as people type them (--set, --set-length, --set-angle, --rate, --accel, NAME=A:B:N):
each parsed once into a units.Quantity (SI value, kind, the unit typed) and checked against its joint's
kind (an angle or a length) and the kinds of unit it takes; the Quantity goes on to the table that
answers in the unit typed."""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import replace

import numpy as np

from ..analysis.motion.planar import LinkAngles
from ..errors import UsageError, quote, shorten
from ..model.state import value_for_leg_length
from ..units import MAGNITUDES, Quantity, check_magnitude, parse_quantity, parse_typed_assignments
from ._options import count
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["value_kind", "MAX_ANGLE", "joint_quantities", "joint_assignments", "joint_value", "inputs", "split_inputs",
           "joint_inputs", "link_rates", "names_list", "parse_range", "rate_items", "check_rate_names"]


def value_kind(mech: Mechanism, joint: str) -> str | None:
    """'angle' or 'length': what a value of this one-coordinate joint is; None when it is no such
    joint (a multi-coordinate joint's ``j[q0]``, an unknown name: the analysis names the problem)."""
    c = next((c for c in mech.coordinates if c.joint == joint), None)
    if c is None or c.nv != 1:
        return None
    return "length" if mech.translational[c.idx_v] else "angle"


#: The kinds of unit a joint's value, rate (order 1) and acceleration (order 2) take: an angle or a length
#: given for a rate or an acceleration keeps its old meaning (--rate crank=90deg is 90 deg/s).
_KINDS = {("angle", 0): ("angle",), ("angle", 1): ("angle", "angular rate"),
          ("angle", 2): ("angle", "angular acceleration"), ("length", 0): ("length",),
          ("length", 1): ("length", "linear rate"), ("length", 2): ("length", "linear acceleration")}
_WHAT = {0: "value", 1: "rate", 2: "acceleration"}


#: The largest angle a joint value may have [rad] (15,915 turns): a double's rounding error there is
#: 1.5e-11 rad, below the closure tolerance; at 1e308 rad nothing of the fraction of a turn is left.
MAX_ANGLE = MAGNITUDES["angle"]
#: The kind (units.MAGNITUDES) of a joint's value (order 0), rate (1) and acceleration (2).
_MAGNITUDE_KIND = {("angle", 0): "angle", ("angle", 1): "angular rate", ("angle", 2): "angular acceleration",
                   ("length", 0): "length", ("length", 1): "linear rate", ("length", 2): "linear acceleration"}


def _checked(mech: Mechanism, name: str, typed: Quantity, option: str, text: str, order: int = 0, links: tuple=()) -> Quantity:
    """``typed`` (parsed without a kind: its unit's) as the value (order 0), rate (1) or acceleration (2)
    of joint ``name``: the Quantity of that kind, or a usage error."""
    value, unit, found = typed.value, typed.unit, typed.kind
    kind = value_kind(mech, name)
    what = f"{'an' if kind == 'angle' else 'a'} {kind} joint"
    if kind is None and name in links:
        kind, what = "angle", "a link given by its angle"
    if kind and found and found not in _KINDS[kind, order]:
        raise UsageError(f"{option} {text}: {quote(name)} is {what}, "
                         f"{unit} is a unit of {found} (its {_WHAT[order]} takes {' or '.join(_KINDS[kind, order])})")
    if kind and (kind != "angle" or order):  # a length, or a rate or acceleration: bounded by its kind
        check_magnitude(value, _MAGNITUDE_KIND[kind, order], f"{option} {text}")
    if kind == "angle" and not order and abs(value) > MAX_ANGLE:
        raise UsageError(f"{option} {text}: {value:g} rad is {abs(value) / (2 * math.pi):.4g} turns; beyond "
                         f"{MAX_ANGLE:g} rad an angle's place in its turn is lost to rounding (1e-10 rad)")
    if kind == "angle" and not unit and not order and abs(value) > 2 * math.pi:
        print(f"warning: {option} {shorten(name, 60)}={value:g} is read as {value:g} rad = "
              f"{math.degrees(value):.6g} deg (more than a turn); write {value:g}deg for degrees", file=sys.stderr)
    return replace(typed, kind=_MAGNITUDE_KIND[kind, order]) if kind else typed


def joint_quantities(mech: Mechanism, items: list | None, option: str, order: int = 0, links: tuple=()) -> dict:
    """``NAME=VALUE,...`` of joints (order 0), their rates (1) or accelerations (2): joint -> units.Quantity
    (the SI value, the kind -- 'angle', 'angular rate', 'linear acceleration' ... -- and the unit typed);
    a unit of a kind the joint does not take (``crank=30mm``, ``crank=10rpm`` as a value) is a usage error,
    a bare angle of more than a turn is read as radians with a warning.  ``links``: names that are links
    given by their angle (--set-angle), checked as angles."""
    out = {}
    for name, typed in parse_typed_assignments(items, option):
        t = mech.input_alias(name)
        if t is None:
            out[name] = _checked(mech, name, typed, option, f"{quote(name, 60)}=...{typed.unit}", order, links)
            continue
        # an input the file names by a tendon or a coupled joint: scale * joint + offset (files.description.Transmission)
        v = _checked(mech, t.joint, typed, option, f"{quote(name, 60)}=...{typed.unit}", order, links)
        if t.joint in out:
            raise UsageError(f"{option}: joint {quote(t.joint)} is given twice ({quote(name)} moves it)")
        out[t.joint] = replace(v, value=(v.value - (t.offset if order == 0 else 0.0)) / t.scale)
        print(f"note: {option} {shorten(name, 60)} is {t.joint} = {out[t.joint].value:.9g} ({t.text()})",
              file=sys.stderr)
    return out


def joint_assignments(mech: Mechanism, items: list | None, option: str, order: int = 0, links: tuple=()) -> dict:
    """joint_quantities' SI values: joint -> value [rad, m, rad/s ...]."""
    return {name: q.value for name, q in joint_quantities(mech, items, option, order, links).items()}


def joint_value(mech: Mechanism, joint: str, text: str, option: str, order: int = 0) -> Quantity:
    """One value (rate: order 1) of ``joint`` typed after ``option`` (``--from -90deg``), checked like
    joint_quantities: its units.Quantity."""
    return _checked(mech, joint, parse_quantity(text), option, quote(text, 60), order)


def inputs(mech: Mechanism, args: argparse.Namespace) -> dict:
    """Input joint values from --set, --set-length and --set-angle of links pinned to the ground
    (split_inputs; the links held at an angle are left out)."""
    return split_inputs(mech, args)[0]


def split_inputs(mech: Mechanism, args: argparse.Namespace) -> tuple:
    """(joint values, held angles, pivots) from the options: --set and --set-length as joint values
    [rad or m]; --set-angle LINK=ANGLE of a link pinned to the ground by a revolute as that joint's
    value (``pivots``: link -> (joint, sign), its angular velocity sign * the joint's rate), of any
    other moving link of a planar mechanism as ``held``: link -> angle [rad], held by one more loop
    equation (analysis.motion.link_inputs; input_solver builds the solver)."""
    values = joint_assignments(mech, getattr(args, "set", None), "--set")
    for name, typed in parse_typed_assignments(getattr(args, "set_length", None), "--set-length"):
        if typed.kind not in (None, "length"):
            raise UsageError(f"--set-length {quote(name)}: {typed.unit} is a unit of {typed.kind}, a leg length is a length")
        if name in values:
            raise UsageError(f"joint {quote(name)} is given twice (--set and --set-length)")
        values[name] = value_for_leg_length(mech, name, typed.value)
    angles, held, pivots = {}, {}, {}
    for name, typed in parse_typed_assignments(getattr(args, "set_angle", None), "--set-angle"):
        if typed.kind not in (None, "angle"):
            raise UsageError(f"--set-angle {quote(name)}: {typed.unit} is a unit of {typed.kind}, --set-angle takes an "
                             "angle")
        # a bare angle over a turn warned of, one beyond MAX_ANGLE refused, as a joint's
        angles[name] = _checked(mech, name, typed, "--set-angle", f"{quote(name, 60)}=...{typed.unit}",
                                links=(name,)).value
    if angles:
        q = mech.generic_configurations()[1][0]
        link_angles = LinkAngles(mech, mech.topology(q))
        for link, angle in angles.items():
            if not link_angles.pivoted(link):
                held[link] = angle
                continue
            joint, value = link_angles.joint_value(link, angle)
            if joint in values:
                raise UsageError(f"joint '{joint}' is given twice (--set and --set-angle {link})")
            values[joint] = value
            pivots[link] = link_angles.pivot(link)
    return values, held, pivots


def joint_inputs(mech: Mechanism, args: argparse.Namespace, what: str) -> dict:
    """inputs() for a command that moves its inputs as joints (an animation, a live page): a usage error
    naming the links that --set-angle would hold by their angle (not pinned to the ground)."""
    values, held, _ = split_inputs(mech, args)
    if held:
        raise UsageError(f"{mech.path}: {what} moves joint inputs; --set-angle {', '.join(held)} is held by its "
                         "angle (not pinned to the ground): set joints with --set, or use solve, draw --png, "
                         "statics or singularities at that configuration")
    return values


def link_rates(rates: dict | None, pivots: dict, option: str) -> dict | None:
    """--rate/--accel values with the links pinned to the ground (split_inputs' pivots) given as their
    joints' (sign * the link's); the held links keep their names (the solver reads them)."""
    if rates is None:
        return None
    out = dict(rates)
    for link, (joint, sign) in pivots.items():
        if link in out:
            if joint in out:
                raise UsageError(f"{option}: '{joint}' is given twice ({joint} and the link {link} on it)")
            out[joint] = sign * out.pop(link)
    return out


def names_list(text: str) -> list | None:
    """``"a, b,c"`` -> ``["a", "b", "c"]``; None for no text."""
    return [n.strip() for n in text.split(",") if n.strip()] if text else None


def parse_range(text: str, option: str, mech: Mechanism) -> tuple:
    """``NAME=A:B:N`` -> (name, N values from A to B, the unit to answer in), N bounded
    (commands/_options.BOUNDS["grid"]), A and B checked as the joint's values (a unit of the other kind,
    ``crank=0:30mm:5``, is a usage error, as with --set); the unit the one typed with A
    (``crank=0deg:360deg:61`` -> 'deg'), else with B, else the SI unit of the joint's kind (rad or m)."""
    name, sep, rest = text.partition("=")
    parts = rest.split(":")
    if not sep or len(parts) != 3:
        raise UsageError(f"{option} expects NAME=A:B:N, got {quote(text, 80)}")
    try:
        n = count("grid")(parts[2])
    except argparse.ArgumentTypeError as exc:
        raise UsageError(f"{option}: N {exc}") from None
    name = name.strip()
    a, b = (joint_value(mech, name, p, f"{option} {quote(name, 60)}") for p in parts[:2])
    return name, np.linspace(a.value, b.value, n), (a if a.unit else b).shown_unit or "rad"


def rate_items(items: list | None, inputs: list, option: str) -> list:
    """--rate, --accel (and dynamics' --speed) as typed, each made NAME=VALUE: the one grammar of every
    command (``--rate O2=120rpm``, repeatable, ``a,b=1``); a bare VALUE (``--rate 120rpm``) is the input's
    where there is exactly one input, a usage error naming the inputs otherwise."""
    out = []
    for item in [items] if isinstance(items, str) else items or []:
        if "=" not in item:
            if len(inputs) != 1:
                raise UsageError(f"{option} {quote(item, 60)}: give NAME=VALUE (a bare value is the input's where there "
                                 f"is one input; inputs: {', '.join(inputs) or 'none'})")
            item = f"{inputs[0]}={item}"
        out.append(item)
    return out


def check_rate_names(given: dict | None, inputs: list, option: str) -> None:
    """A --rate/--accel name that is not an input would be dropped without a word: exit 2 naming it."""
    stray = [n for n in (given or {}) if n not in inputs]
    if stray:
        raise UsageError(f"{option} {', '.join(shorten(s, 40) for s in stray)}: not an input (inputs: "
                         f"{', '.join(shorten(i, 40) for i in inputs) or 'none'})")
