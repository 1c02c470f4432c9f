"""What several commands share: the configuration they analyse, from the options typed."""

from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np
import pinocchio as pin

from ..analysis.motion.link_inputs import holding_angles
from ..analysis.motion.links import Point
from ..analysis.motion.modes import choose_mode
from ..analysis.motion.planar import LinkAngles
from ..analysis.motion.position import PositionSolver
from ..errors import UsageError, quote, shorten
from ..model.state import KinematicState, place_tool, value_for_leg_length
from ..model.topology import open_joints
from ..present.tables import RateUnits
from ..units import MAGNITUDES, check_magnitude, parse_typed_assignments, parse_typed_value, parse_value, unit_kind
from ._options import count

__all__ = ["with_mode", "mode_line", "file_configuration_line", "check_rate_names", "rate_items", "names_list", "parse_range", "add_common", "add_scaled", "emit", "add_length_option", "PointOption", "add_point_option", "named_points", "inputs", "split_inputs", "joint_inputs", "input_solver", "link_rates", "configuration", "add_configuration_options", "add_mode_option", "add_angle_option", "joint_assignments",
           "joint_value", "value_kind", "add_tool_option", "parse_tool", "output_frame", "output_frame_dict", "output_frame_line",
           "typed_unit", "rate_units", "MAX_ANGLE", "near_values", "moved_not_set"]


class PointOption(argparse.Action):
    """``--point`` alone: the output link's origin analysed as a point (``args.point = True``, as
    before); ``--point NAME=LINK:x,y,z``: a named point on a link (``args.points``), repeatable."""

    def __call__(self, parser, namespace, value, option_string=None):
        if value is None:
            namespace.point = True
        else:
            namespace.points = [*(getattr(namespace, "points", None) or []), value]


def add_point_option(sp, origin_help: str | None = None):
    """--point: named points NAME=LINK:x,y,z (and, with ``origin_help``, --point alone as before)."""
    sp.set_defaults(point=False, points=None)
    help = ("a point on a link, NAME=LINK:x,y,z in the link's frame (units allowed: P=coupler:60mm,20mm,0); "
            "its position, velocity and acceleration are reported; repeatable")
    if origin_help:
        help = f"{origin_help}; or {help}"
    sp.add_argument("--point", nargs="?", action=PointOption, metavar="NAME=LINK:x,y,z", help=help)


def named_points(mech, args) -> tuple:
    """The analysis.motion.links.Point objects of --point NAME=LINK:x,y,z (links checked, names unique)."""
    out, seen = [], set()
    for text in getattr(args, "points", None) or []:
        name, sep, rest = text.rpartition("=")
        link, sep2, coords = rest.partition(":")
        parts = [c for c in coords.replace(" ", ",").split(",") if c.strip()]
        if not sep or not sep2 or not name.strip() or not link.strip() or len(parts) not in (2, 3):
            raise UsageError(f"--point expects NAME=LINK:x,y,z (or x,y in the plane z = 0), got {quote(text, 80)}")
        name, link = name.strip(), link.strip()
        if name in seen:
            raise UsageError(f"--point: the name {quote(name)} is given twice")
        seen.add(name)
        mech.link_frame(link)  # a clear error for an unknown link
        # each coordinate a length within units.MAGNITUDES (10 km, a file's positions: 1e308 m gave inf answers)
        local = tuple(parse_value(c, "length", f"--point {name}") for c in parts) + ((0.0,) if len(parts) == 2 else ())
        out.append(Point(name, link, local))
    return tuple(out)


def add_tool_option(sp):
    """--tool x,y,z[,roll,pitch,yaw]: the output frame moved on the output link."""
    sp.add_argument("--tool", metavar="x,y,z[,roll,pitch,yaw]",
                    help="a tool frame on the --output link, placed in the link's frame (units allowed: "
                         "0,0,60mm or 0.1,0,0,0,0,90deg): its pose, twist and Jacobian replace the link frame's")


def parse_tool(text: str):
    """``x,y,z[,roll,pitch,yaw]`` (m and rad, units allowed) -> a pinocchio.SE3 in the link's frame."""
    parts = [c for c in text.replace(" ", ",").split(",") if c.strip()]
    if len(parts) not in (3, 6):
        raise UsageError(f"--tool expects x,y,z or x,y,z,roll,pitch,yaw, got {len(parts)} numbers in {quote(text, 80)}")
    v = [parse_value(c, "length" if k < 3 else "angle", "--tool") for k, c in enumerate(parts)]  # (bounded by kind)
    rpy = np.array(v[3:] if len(v) == 6 else [0.0, 0.0, 0.0])
    return pin.SE3(pin.rpy.rpyToMatrix(rpy), np.array(v[:3]))


def output_frame(mech, args, required: bool = False):
    """The output a command analyses, from --output, --tool and a named --point: ``(name, point)``.

    ``--tool`` moves the output frame onto the --output link (named ``LINK@tool``); a named
    ``--point NAME=LINK:x,y,z`` makes that point the output (its link's orientation, analysed as a
    point: ``point`` is True); ``--point`` alone keeps its meaning (the output link's origin as a point).
    ``name`` is what mech.link_frame takes (None when no output is given and none is ``required``)."""
    output, tool = getattr(args, "output", None), getattr(args, "tool", None)
    named = named_points(mech, args)
    if len(named) > 1:
        raise UsageError(f"--point: this command takes one named point as its output, got {len(named)}")
    if named:
        p = named[0]
        if tool is not None:
            raise UsageError("--tool and a named --point both move the output frame: give one of them")
        if output is not None and output != p.link:
            raise UsageError(f"--point {p.name} is on {quote(p.link)}, not on the --output link {quote(output)}")
        return place_tool(mech, p.name, p.link, pin.SE3(np.eye(3), np.asarray(p.local, float))), True
    if output is None:
        if tool is not None:
            raise UsageError("--tool needs --output LINK (the link the tool is on)")
        if required:
            raise UsageError("give --output LINK (or a named --point NAME=LINK:x,y,z)")
        return None, bool(getattr(args, "point", False))
    if tool is not None:
        return place_tool(mech, f"{output}@tool", output, parse_tool(tool)), bool(getattr(args, "point", False))
    return output, bool(getattr(args, "point", False))


def output_frame_dict(mech, q, jacobian: bool = False, point: bool = False) -> dict | None:
    """JSON of the placed output frame (model.state.place_tool) at q: its name, link, placement on the
    link (x, y, z, roll, pitch, yaw) and world pose (position, rotation); with ``jacobian`` its frame
    Jacobian (world axes, rows (v, w) of its origin; only v for a ``point``: J_p = J_v - [r]x J_w, one
    column a velocity coordinate); None when none is placed."""
    if mech.tool is None:
        return None
    name, link, X = mech.tool
    state = KinematicState(mech, q)
    M = state.frame_placement(mech.tool_frame)
    out = {"name": name, "link": link, "local": [*X.translation.tolist(), *pin.rpy.matrixToRpy(X.rotation).tolist()],
           "position": M.translation.tolist(), "rotation": M.rotation.tolist()}
    if jacobian:
        J = state.frame_jacobian(mech.tool_frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        out["jacobian"] = (J[:3] if point else J).tolist()
        out["jacobian_columns"] = list(mech.coordinate_names)
    return out


def output_frame_line(frame: dict, point: bool) -> str:
    """One line saying which frame is the output (output_frame_dict), where it is on its link and in the world."""
    x = ", ".join(f"{v:.6g}" for v in frame["local"][:3])
    w = ", ".join(f"{v:.6g}" for v in frame["position"])
    if point:
        return f"output: the point {quote(frame['name'])} at ({x}) m on {quote(frame['link'])}, in the world at ({w}) m"
    rpy = ", ".join(f"{math.degrees(v):.6g}" for v in frame["local"][3:])
    return (f"output: the tool frame {quote(frame['name'])} at ({x}) m, roll pitch yaw ({rpy}) deg on "
            f"{quote(frame['link'])}, in the world at ({w}) m")


def value_kind(mech, joint: str):
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


def _checked(mech, name, value, unit, option, text, order=0, links=()):
    kind = value_kind(mech, name)
    what = f"{'an' if kind == 'angle' else 'a'} {kind} joint"
    if kind is None and name in links:
        kind, what = "angle", "a link given by its angle"
    found = unit_kind(unit)
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
    return value


def joint_assignments(mech, items, option: str, order: int = 0, links=()) -> dict:
    """``NAME=VALUE,...`` of joints (order 0), their rates (1) or accelerations (2): SI values; a unit
    of a kind the joint does not take (``crank=30mm``, ``crank=10rpm`` as a value) is a usage error, a
    bare angle of more than a turn is read as radians with a warning.  ``links``: names that are links
    given by their angle (--set-angle), checked as angles."""
    out = {}
    for name, value, unit in parse_typed_assignments(items, option):
        t = mech.input_alias(name)
        if t is None:
            out[name] = _checked(mech, name, value, unit, option, f"{quote(name, 60)}=...{unit}", order, links)
            continue
        # an input the file names by a tendon or a coupled joint: scale * joint + offset (files.description.Transmission)
        v = _checked(mech, t.joint, value, unit, option, f"{quote(name, 60)}=...{unit}", order, links)
        if t.joint in out:
            raise UsageError(f"{option}: joint {quote(t.joint)} is given twice ({quote(name)} moves it)")
        out[t.joint] = (v - (t.offset if order == 0 else 0.0)) / t.scale
        print(f"note: {option} {shorten(name, 60)} is {t.joint} = {out[t.joint]:.9g} ({t.text()})", file=sys.stderr)
    return out


def joint_value(mech, joint: str, text: str, option: str, order: int = 0) -> float:
    """One value (rate: order 1) of ``joint`` typed after ``option`` (``--from -90deg``), checked like
    joint_assignments."""
    value, unit = parse_typed_value(text)
    return _checked(mech, joint, value, unit, option, quote(text, 60), order)


def add_angle_option(sp):
    """--set-angle: an input as a link's absolute angle (planar mechanisms)."""
    sp.add_argument("--set-angle", action="append", metavar="LINK=ANGLE",
                    help="planar mechanisms: an input given as the absolute angle of a link, from the ground's "
                         "x axis (e.g. crank=45deg): a link pinned to the ground sets its joint, any other "
                         "link's angle is held by one more loop equation; its rate is --rate LINK=...")


def add_length_option(sp):
    """--set-length: an input given as the length of a prismatic leg."""
    sp.add_argument("--set-length", action="append", metavar="JOINT=LENGTH",
                    help="a prismatic input given as its leg's length, the distance between the joint centres it "
                         "connects (e.g. leg1=0.418 or 418mm)")


def add_configuration_options(sp):
    """--set, --set-angle, --set-length and --near: the configuration a command analyses (see configuration)."""
    sp.add_argument("--set", action="append", metavar="NAME=VALUE", help="input values of the configuration")
    add_angle_option(sp)
    add_length_option(sp)
    sp.add_argument("--near", metavar="NAME=VALUE,...", help="assembly mode nearest this configuration")
    add_mode_option(sp)


def add_mode_option(sp, at: str = "the --set inputs"):
    """--mode K: the K-th assembly mode (configuration() chooses it and says which, of how many)."""
    sp.add_argument("--mode", type=count("mode"), metavar="K",
                    help=f"the K-th assembly mode of {at} (as solve lists them; default 1, the one nearest the "
                         "file's configuration)")


def inputs(mech, args) -> dict:
    """Input joint values from --set, --set-length and --set-angle of links pinned to the ground
    (split_inputs; the links held at an angle are left out)."""
    return split_inputs(mech, args)[0]


def split_inputs(mech, args) -> tuple:
    """(joint values, held angles, pivots) from the options: --set and --set-length as joint values
    [rad or m]; --set-angle LINK=ANGLE of a link pinned to the ground by a revolute as that joint's
    value (``pivots``: link -> (joint, sign), its angular velocity sign * the joint's rate), of any
    other moving link of a planar mechanism as ``held``: link -> angle [rad], held by one more loop
    equation (analysis.motion.link_inputs; input_solver builds the solver)."""
    values = joint_assignments(mech, getattr(args, "set", None), "--set")
    for name, value, unit in parse_typed_assignments(getattr(args, "set_length", None), "--set-length"):
        if unit_kind(unit) not in (None, "length"):
            raise UsageError(f"--set-length {quote(name)}: {unit} is a unit of {unit_kind(unit)}, a leg length is a length")
        if name in values:
            raise UsageError(f"joint {quote(name)} is given twice (--set and --set-length)")
        values[name] = value_for_leg_length(mech, name, value)
    angles, held, pivots = {}, {}, {}
    for name, value, unit in parse_typed_assignments(getattr(args, "set_angle", None), "--set-angle"):
        if unit_kind(unit) not in (None, "angle"):
            raise UsageError(f"--set-angle {quote(name)}: {unit} is a unit of {unit_kind(unit)}, --set-angle takes an angle")
        # a bare angle over a turn warned of, one beyond MAX_ANGLE refused, as a joint's
        angles[name] = _checked(mech, name, value, unit, "--set-angle", f"{quote(name, 60)}=...{unit}", links=(name,))
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


def joint_inputs(mech, args, what: str) -> dict:
    """inputs() for a command that moves its inputs as joints (an animation, a live page): a usage error
    naming the links that --set-angle would hold by their angle (not pinned to the ground)."""
    values, held, _ = split_inputs(mech, args)
    if held:
        raise UsageError(f"{mech.path}: {what} moves joint inputs; --set-angle {', '.join(held)} is held by its "
                         "angle (not pinned to the ground): set joints with --set, or use solve, draw --png, "
                         "statics or singularities at that configuration")
    return values


def input_solver(mech, inputs, held: dict | None = None, output=None) -> PositionSolver:
    """The PositionSolver of these input joints (names, or split_inputs' values: their keys), with the
    ``held`` links' angles held by their loop equations (a copy of the mechanism:
    analysis.motion.link_inputs.holding_angles); none held, the plain solver of ``mech``."""
    inputs = list(inputs)
    if held:
        return PositionSolver(holding_angles(mech, inputs, held), inputs, output=output)
    return PositionSolver(mech, inputs, output=output)


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


def configuration(mech, args, moved: dict | None = None, inputs=None):
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
    args.mode_chosen = None
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
    q, k, n, res = choose_mode(input_solver(mech, inputs, held), values, wanted, near)
    for note in res.notes:  # a --near value the mode found lies far from
        print(f"note: {note}", file=sys.stderr)
    if n > 1:
        args.mode_chosen = {"index": k, "of": n}
        if not getattr(args, "json", False):
            print(f"note: {mode_line(k, n, hasattr(args, 'near'))}", file=sys.stderr)
    return q


def mode_line(k: int, n: int, near: bool = True) -> str:
    """The words every command says the assembly mode in: ``assembly mode 1 of 2 (others: --mode 2, or --near)``."""
    others = ", ".join(f"--mode {j}" for j in range(1, n + 1) if j != k)
    return f"assembly mode {k} of {n} (others: {others}{', or --near' if near else ''})"


def file_configuration_line(mech, q) -> str:
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


def near_values(mech, args) -> dict | None:
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


def with_mode(args, d: dict) -> dict:
    """``d`` with "mode": {"index", "of"} when the configuration was one of several assembly modes."""
    if getattr(args, "mode_chosen", None):
        d["mode"] = args.mode_chosen
    return d


def names_list(text):
    """``"a, b,c"`` -> ``["a", "b", "c"]``; None for no text."""
    return [n.strip() for n in text.split(",") if n.strip()] if text else None


def typed_unit(mech, name: str, text: str) -> str:
    """The unit to answer a ``NAME=A:B:N`` range in: the one typed with A (``crank=0deg:360deg:61`` ->
    'deg'), else with B, else the SI unit of the joint's kind (rad or m)."""
    for part in text.partition("=")[2].split(":")[:2]:
        unit = parse_typed_value(part)[1]
        if unit:
            return unit
    return "m" if value_kind(mech, name) == "length" else "rad"


def rate_units(args) -> RateUnits:
    """The units solve's and report's tables write rates and accelerations in: those typed with --rate
    and --accel (``10rpm``: omega in rpm; ``90deg``: deg/s and deg/s^2; ``5mm/s``: mm/s), SI otherwise."""
    return RateUnits.typed([u for _, _, u in parse_typed_assignments(getattr(args, "rate", None), "--rate")],
                           [u for _, _, u in parse_typed_assignments(getattr(args, "accel", None), "--accel")])


def parse_range(text, option, mech):
    """``NAME=A:B:N`` -> (name, N values from A to B), N bounded (commands/_options.BOUNDS["grid"]), A and B
    checked as the joint's values (a unit of the other kind, ``crank=0:30mm:5``, is a usage error, as
    with --set)."""
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
    return name, np.linspace(a, b, n)


def moved_not_set(values: dict, moved: str, how: str) -> None:
    """A --set (or --set-angle) value of the input the command moves would be ignored: a usage error
    naming it (sweep --input X --set X=..., dynamics, draw --animate, view --sweep).  ``how``: what moves
    it ("sweep moves it from --from to --to")."""
    if moved in values:
        raise UsageError(f"--set {quote(moved, 60)} (or --set-angle of its link): {how}, so a value of its own "
                         "would be ignored; leave it out")


def add_common(sp, mechanism: bool = True, optional_file: bool = False):
    """The options every command takes (with mechanism=False: no FILE and no mechanism options)."""
    if not mechanism:
        sp.add_argument("--json", action="store_true", help="print one JSON object")
        sp.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show tracebacks of errors")
        return
    sp.add_argument("file", help="URDF (with <loop_joint> or a YAML sidecar), SDF, MJCF, or xacro file",
                    **({"nargs": "?"} if optional_file else {}))
    sp.add_argument("--arg", action="append", dest="xacro_args", metavar="NAME=VALUE",
                    help="xacro argument of a .xacro file (units allowed, e.g. crank=30mm: given in SI); repeatable")
    sp.add_argument("--yaml", help="Extended-URDF sidecar (default: FILE with .yaml suffix, if present)")
    sp.add_argument("--json", action="store_true", help="print one JSON object")
    # SUPPRESS: when absent after the command, the top-level --debug (before the command) is kept
    sp.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show tracebacks of errors")
    sp.add_argument("--actuated", help="actuated joints, comma separated (overrides the file)")
    sp.add_argument("--package-dir", action="append", dest="package_dirs", metavar="DIR",
                    help="folder holding ROS packages (or a package) for package:// meshes, searched before "
                         "ROS_PACKAGE_PATH; repeatable")


def add_scaled(sp, point=True):
    """--length (the characteristic length of the dimensionless measures) and --point."""
    sp.add_argument("--length", help="characteristic length that makes the measures dimensionless "
                                     "(default: the mean link length; printed with every measure)")
    if point:
        add_point_option(sp, "--point alone: analyse the output link's origin as a point (3 translations) "
                             "instead of its full motion")


def emit(args, data, text) -> int:
    """Print ``data`` as one JSON object (--json; to_jsonable applied by the caller's data) or ``text``
    (a string, or a callable making it, so that text-only work is skipped for --json); exit code 0."""
    if getattr(args, "json", False):
        print(json.dumps(data() if callable(data) else data, indent=2))
    else:
        print(text() if callable(text) else text)
    return 0


def rate_items(items, inputs, option: str) -> list:
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


def check_rate_names(given: dict | None, inputs, option: str) -> None:
    """A --rate/--accel name that is not an input would be dropped without a word: exit 2 naming it."""
    stray = [n for n in (given or {}) if n not in inputs]
    if stray:
        raise UsageError(f"{option} {', '.join(shorten(s, 40) for s in stray)}: not an input (inputs: "
                         f"{', '.join(shorten(i, 40) for i in inputs) or 'none'})")
