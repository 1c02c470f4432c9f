"""``screwkin synthesize KIND ... -o OUT.urdf``: linkage synthesis (issue 14).

KIND is ``motion`` (rigid-body guidance through 3-5 poses), ``function`` (Freudenstein),
``path`` (a coupler point through points) or ``chains`` (type and number synthesis).  Each
writes URDF that every other command loads, and checks it with screwkin's own analyses
before reporting it (screwkin.analysis.design.synthesis.check): a result with a defect is reported
with the defect; ``--reject-defects`` leaves such results out and fails (exit 1) when
nothing is left.  A file is checked under a temporary name beside OUT and then renamed to
OUT, so OUT is the checked file and a rejected result leaves no file.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import tempfile
from dataclasses import replace
from pathlib import Path

from ..analysis.design.synthesis.chains import chain_linkage, enumerate_chains
from ..analysis.design.synthesis.check import check_chain_file, check_design
from ..analysis.design.synthesis.constraints import GRASHOF_TYPES, Constraints
from ..analysis.design.synthesis.search import GENERATIONS, Search
from ..analysis.design.synthesis.designs import SynthesisError
from ..analysis.design.synthesis.function import synthesize_function
from ..analysis.design.synthesis.motion import motion_design, synthesize_motion
from ..analysis.design.synthesis.optimal import optimal_path
from ..analysis.design.synthesis.optimal_function import optimal_function
from ..analysis.design.synthesis.optimal_motion import optimal_motion
from ..analysis.design.synthesis.path import synthesize_path
from ..errors import OutputError, UsageError, quote
from ..files.description import LIMITS
from ..files.writer import write_urdf
from ..parallel.pool import dask_client, dask_map, process_pool
from ..model.loader import load
from ..present.draw import draw_design
from ..present.jsonout import json_of
from ..present.outfile import os_reason, output_failed, remove_partial, write_output
from ..present.synthesis import chains_dict, chains_text, synthesis_dict, synthesis_text
from ..present.synthesis_plots import burmester_png
from ..units import parse_value
from ._options import count, seconds, whole
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.design.synthesis.designs import Design
    from collections.abc import Callable

NAME = "synthesize"
NEEDS_MECHANISM = False
KINDS = ("motion", "function", "path", "chains")
#: Ranked pairs of Burmester dyads checked with screwkin before giving up on a defect-free one.
PAIRS_CHECKED = 6

#: The options of the constrained global search (motion, function, path).
#: What the processes of --workers import once, before they fork (the search's runs are in them).
SEARCH_MODULES = ("screwkin.analysis.design.synthesis.optimal", "screwkin.analysis.design.synthesis.optimal_motion",
                  "screwkin.analysis.design.synthesis.optimal_function")
SEARCH = {"bounds", "lengths", "grashof", "min_transmission", "best", "generations", "workers", "scheduler", "seed"}
_OPTIONS = {  # which options each kind takes (dest names)
    "motion": {"poses", "pivots", "moving", "pick", "candidates", "png", "draw"} | SEARCH,
    "function": {"function", "x_range", "input_range", "output_range", "points", "spacing", "ground", "draw"} | SEARCH,
    "path": {"points", "timing", "starts", "seed", "tolerance", "draw"} | SEARCH,
    "chains": {"links", "dof", "prismatic", "planar"},
}


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser("synthesize", help="synthesize a planar linkage (motion, function, path) or enumerate "
                                           "kinematic chains; writes URDF checked with screwkin")
    sp.add_argument("kind", choices=KINDS, help="what to synthesize")
    common(sp, mechanism=False)
    sp.add_argument("-o", "--output", dest="out", metavar="OUT",
                    help="the URDF to write (chains: a folder, one file per mechanism)")
    sp.add_argument("--reject-defects", action="store_true",
                    help="leave out results with a defect (branch, order, limit position, a missed position); "
                         "exit 1 when none is left")
    sp.add_argument("--draw", metavar="F.png|F.svg",
                    help="motion, function, path: draw the linkage written with its targets, as 'screwkin draw OUT "
                         "--png F' does (the linkage at each precision position, a path's coupler curve)")
    m = sp.add_argument_group("motion")
    m.add_argument("--poses", metavar='"x,y,th; ..."',
                   help="3 to 5 poses of the coupler frame (m; th in rad, or with deg)")
    m.add_argument("--pivots", metavar='"x,y; x,y"', help="three poses: the two fixed pivots (crank's first)")
    m.add_argument("--moving", metavar='"x,y; x,y"',
                   help="three poses: the two moving pivots in the coupler frame (crank's first)")
    m.add_argument("--pick", metavar="I,J", help="four or five poses: the candidates for crank and rocker")
    m.add_argument("--candidates", type=count("candidates"), default=24,
                   help="four poses: lines through a pole that trace the candidates (default 24)")
    m.add_argument("--png", help="draw the centre-point and circle-point curves (needs matplotlib)")
    f = sp.add_argument_group("function")
    f.add_argument("--function", help='y = f(x), e.g. "log(x)" (x, numbers, + - * / **, sin cos tan exp log '
                                      'sqrt abs, pi, e)')
    f.add_argument("--x-range", metavar="X0:X1", help="the range of x")
    f.add_argument("--input-range", metavar="A:B", help="the crank's angle range (rad, or with deg)")
    f.add_argument("--output-range", metavar="C:D", help="the rocker's angle range (rad, or with deg)")
    f.add_argument("--spacing", choices=("chebyshev", "even"), default="chebyshev",
                   help="precision points (default chebyshev)")
    f.add_argument("--ground", default="0.1", help="ground length, crank_joint to rocker_joint (default 0.1 m)")
    p = sp.add_argument_group("path (and function)")
    p.add_argument("--points", help='path: the points "x,y; x,y; ..."; function: the number of precision points '
                                    "(default 3; more: least squares)")
    p.add_argument("--timing", metavar='"a, b, ..."', help="path: the crank angle at each point (from any zero)")
    p.add_argument("--starts", type=count("starts"), default=24, help="path: least-squares starts (default 24)")
    p.add_argument("--seed", type=count("seed"), default=0,
                   help="path: seed of the starts; the global search's seed (default 0)")
    p.add_argument("--tolerance", default="1e-6",
                   help="path: a point is reached within this distance (default 1e-6 m)")
    g = sp.add_argument_group("constraints and the global search (motion, function, path)")
    g.add_argument("--bounds", metavar='"X0,Y0; X1,Y1"', help="the fixed pivots inside this box (m, or with units)")
    g.add_argument("--lengths", metavar="MIN..MAX", help="every link, the ground's too, this long (m, or with units)")
    g.add_argument("--grashof", choices=GRASHOF_TYPES, help="the Grashof type (as study prints it; grashof: any)")
    g.add_argument("--min-transmission", metavar="ANGLE",
                   help="the transmission angle within ANGLE .. 180 deg - ANGLE over the motion (rad, or with deg)")
    g.add_argument("--best", type=count("best"), help="designs listed (default 5)")
    g.add_argument("--generations", type=count("generations"),
                   help=f"generations of each differential-evolution run at most (default {GENERATIONS})")
    g.add_argument("--workers", type=count("workers"), metavar="N",
                   help="spread the search's runs over N local processes (0: in this process, the default); "
                        "it helps only with N idle cores: the search is 4 to 8 runs of seconds each, so at best "
                        "about 1.8x on 2 idle cores, and nothing on cores busy with other work (README, synthesize)")
    g.add_argument("--scheduler", metavar="ADDRESS", help="spread them over a running dask cluster, tcp://HOST:PORT")
    g.add_argument("--timeout", type=seconds("timeout"), default=10.0,
                   help="seconds to reach the scheduler and a worker (default 10)")
    c = sp.add_argument_group("chains")
    c.add_argument("--links", type=whole, help="number of links (the ground included)")
    c.add_argument("--dof", type=whole, help="degrees of freedom")
    c.add_argument("--prismatic", type=whole, default=0, help="how many joints are prismatic (default 0)")
    c.add_argument("--planar", action="store_true", help="planar chains (the only kind enumerated)")


def _given(args: argparse.Namespace, dest: str) -> bool:
    defaults = {"candidates": 24, "spacing": "chebyshev", "ground": "0.1", "starts": 24, "seed": 0,
                "tolerance": "1e-6", "prismatic": 0, "planar": False, "timeout": 10.0}
    return getattr(args, dest) not in (None, defaults.get(dest))


def _option(dest):
    return "--" + dest.replace("_", "-")


def _number_groups(text: str, option: str, count: int | None = None, kind: str | None = None) -> list:
    """'x,y; x,y' -> [[x, y], [x, y]] (each number with an optional unit, of ``kind`` when given)."""
    groups = [g for g in text.split(";") if g.strip()]
    if not groups:
        raise UsageError(f"{option}: no values in {quote(text)}")
    out = []
    for g in groups:
        parts = [x for x in g.replace(",", " ").split()]
        if count is not None and len(parts) != count:
            raise UsageError(f"{option}: {quote(g.strip())} has {len(parts)} numbers, expected {count} "
                             f"(write {'x,y,theta' if count == 3 else 'x,y'}; separated by ;)")
        out.append([parse_value(x, kind, option) if kind else parse_value(x) for x in parts])
    return out


def _range(text: str, option: str) -> tuple:
    parts = text.split(":") if text else []
    if len(parts) != 2:
        raise UsageError(f"{option} expects A:B, got {quote(text or '')}")
    return parse_value(parts[0]), parse_value(parts[1])


def _plausible(design: Design, kind: str) -> None:
    """A linkage whose numbers a file can hold: finite, and within the 10 km the reader accepts."""
    fb = design.fourbar
    values = [*fb.A0, *fb.A, *fb.B, *fb.B0, *(fb.tool or ())]
    if not all(math.isfinite(v) for v in values):
        raise SynthesisError(f"synthesize {kind}", "the linkage found has no finite dimensions (the positions are "
                                                   "degenerate or too far apart)")
    big = max(abs(v) for v in values)
    if big > LIMITS.length:
        raise SynthesisError(f"synthesize {kind}", f"the linkage found reaches {big:.3g} m from the origin, beyond "
                                                   f"the {LIMITS.length:g} m a mechanism file may hold")


def _realize(design: Design, out: str, tolerance=None) -> tuple:
    """Write design's URDF under a temporary name beside ``out``, check it there; returns
    (check, temporary path)."""
    _plausible(design, design.kind)
    folder = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(folder):
        raise UsageError(f"-o {quote(str(out))}: the folder {quote(folder)} does not exist")
    try:
        fd, tmp = tempfile.mkstemp(prefix=".screwkin-", suffix=".urdf", dir=folder)
    except OSError as exc:
        raise output_failed(out, exc) from None
    os.close(fd)
    try:
        write_output(tmp, write_urdf(design.linkage))  # (a partial file removed when it fails)
        return check_design(design, tmp, tolerance=tolerance), tmp
    except BaseException:  # a failed check or Ctrl-C: the temporary file removed, the error goes on
        remove_partial(tmp)
        raise


def _keep(tmp: str, out: str) -> None:
    """The checked design at ``out``: the temporary file renamed there, or written through a link, a
    device or a pipe that ``out`` names (a rename would replace it)."""
    try:
        if os.path.islink(out) or (os.path.exists(out) and not os.path.isfile(out)):
            with open(tmp, encoding="utf-8") as f:
                write_output(out, f.read())
            os.remove(tmp)
            return
        os.replace(tmp, out)
    except OSError as exc:
        raise OutputError(out, os_reason(exc)) from None
    finally:
        remove_partial(tmp)


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    kind = args.kind
    for dest in sorted(set().union(*_OPTIONS.values()) - _OPTIONS[kind]):
        if _given(args, dest):
            takers = " and ".join(f"'synthesize {k}'" for k, dests in _OPTIONS.items() if dest in dests)
            raise UsageError(f"{_option(dest)} applies to {takers}, not to 'synthesize {kind}'")
    if kind == "chains":
        return _chains(args)
    if not args.out:
        raise UsageError(f"synthesize {kind} needs -o OUT.urdf (the file to write)")
    if args.draw and not (args.draw.lower().endswith((".png", ".svg")) and len(args.draw) > 4):
        raise UsageError(f"--draw expects a file name ending in .png or .svg, got {quote(args.draw)}")
    if kind == "motion":
        result, check, tmp = _motion(args)
    elif kind == "function":
        result, check, tmp = _function(args)
    else:
        result, check, tmp = _path(args)
    if args.reject_defects and not check.valid:
        os.unlink(tmp)
        raise SynthesisError(f"synthesize {kind}", "every result has a defect (--reject-defects): "
                                                   + "; ".join(check.defects))
    _keep(tmp, args.out)
    check = replace(check, file=str(args.out))
    lines, marks = [], None
    if args.draw:
        marks = draw_design(load(args.out), [args.draw], say=lines.append)
    constraints = _constraints(args).describe() if getattr(result, "search", None) is not None else ()
    if args.json:
        out = synthesis_dict(result, check, args.out, constraints)
        if args.draw:
            out["drawing"] = {"file": args.draw, "targets": marks}
        print(json_of(out))
    else:
        print(synthesis_text(result, check, args.out, constraints))
        if args.draw:
            print("\n".join([*lines, f"wrote {args.draw}"]))
        else:
            print(f"to see it with its targets: screwkin draw {args.out} --png "
                  f"{os.path.splitext(str(args.out))[0]}-design.png (or --draw F.png here)")
    return 0


def _constraints(args: argparse.Namespace) -> Constraints:
    """--bounds, --lengths, --grashof, --min-transmission, checked."""
    bounds = lengths = angle = None
    if args.bounds:
        corners = _number_groups(args.bounds, "--bounds", 2, kind="length")
        if len(corners) != 2:
            raise UsageError(f"--bounds expects two corners \"X0,Y0; X1,Y1\", got {len(corners)}")
        (x0, y0), (x1, y1) = corners
        bounds = ((x0, y0), (x1, y1))
    if args.lengths:
        low, sep, high = args.lengths.partition("..")
        if not sep or not low.strip() or not high.strip():
            raise UsageError(f"--lengths expects MIN..MAX, got {quote(args.lengths)}")
        lengths = (parse_value(low, "length", "--lengths"), parse_value(high, "length", "--lengths"))
    if args.min_transmission:
        angle = parse_value(args.min_transmission, "angle", "--min-transmission")
        if not 0 <= angle < math.pi / 2:
            raise UsageError(f"--min-transmission must lie from 0 to below 90 deg, got {quote(args.min_transmission)}")
    return Constraints(bounds, lengths, args.grashof, angle).check()


def _searching(args: argparse.Namespace, count: int, beyond: int) -> bool:
    """Whether the constrained global search runs: a constraint or a search option given, or more
    precision positions than the classic methods take (``beyond``)."""
    return count > beyond or any(_given(args, d) for d in SEARCH - {"seed"})


@contextlib.contextmanager
def _search(args: argparse.Namespace):
    """The Search of the command line: in this process, over N local processes (--workers N: forked from a
    fork server, parallel.pool.process_pool), or over a running Dask cluster (--scheduler, study's grammar)."""
    kw = {"seed": args.seed, "best": args.best or 5, "generations": args.generations or GENERATIONS}
    if args.scheduler is not None and args.workers is not None:
        raise UsageError("--workers is for the local cluster; a scheduler's cluster has its own workers")
    if args.scheduler is None and not args.workers:
        yield Search(**kw)
        return
    if args.scheduler is None:  # a few runs of seconds each: local processes, not a Dask LocalCluster
        with process_pool(args.workers, SEARCH_MODULES) as (mapper, how):
            yield Search(**kw, mapper=mapper, where=f"{how}, {args.workers} worker{'s' if args.workers != 1 else ''}")
        return
    with dask_client(args.scheduler, args.workers, args.timeout) as (client, used, where):
        yield Search(**kw, mapper=dask_map(client, "screwkin-synthesis"),
                     where=f"{where}, {used} worker{'s' if used != 1 else ''}")


def _motion(args: argparse.Namespace):
    if not args.poses:
        raise UsageError('synthesize motion needs --poses "x,y,theta; x,y,theta; x,y,theta"')
    poses = _number_groups(args.poses, "--poses", 3)
    if _searching(args, len(poses), 5):
        for opt, given in (("--pivots", args.pivots), ("--moving", args.moving), ("--pick", args.pick)):
            if given:
                raise UsageError(f"{opt} chooses the dyads; the constrained search ({len(poses)} poses or "
                                 "--bounds, --lengths, --grashof, --min-transmission ...) chooses them itself")
        with _search(args) as search:
            result = optimal_motion(poses, _constraints(args), search)
        check, tmp = _realize(result.design, args.out)
        return result, check, tmp
    pivots = _number_groups(args.pivots, "--pivots", 2) if args.pivots else None
    moving = _number_groups(args.moving, "--moving", 2) if args.moving else None
    pick = None
    if args.pick:
        try:
            pick = tuple(whole(x) for x in args.pick.split(","))
        except argparse.ArgumentTypeError:
            raise UsageError(f"--pick expects I,J (two candidate numbers), got {quote(args.pick)}") from None
        if len(pick) != 2:
            raise UsageError(f"--pick expects I,J (two candidate numbers), got {quote(args.pick)}")
    if args.candidates < 4:
        raise UsageError("--candidates must be at least 4")
    result = synthesize_motion(poses, pivots, moving, pick, args.candidates)
    if args.png:
        burmester_png(result, args.png)
    if not result.ranked:
        check, tmp = _realize(result.design, args.out)
        return result, check, tmp
    first = None
    for i, j, _, _ in result.ranked[:PAIRS_CHECKED]:
        design = result.design if (i, j) == tuple(result.pick) else \
            motion_design(result.poses, result.candidates[i], result.candidates[j])
        check, tmp = _realize(design, args.out)
        if check.valid:
            if first is not None:
                os.unlink(first[2])
            return replace(result, pick=(i, j), design=design), check, tmp
        if first is None:
            first = (replace(result, pick=(i, j), design=design), check, tmp)
        else:
            os.unlink(tmp)
    return first


def _function(args: argparse.Namespace) -> tuple:
    missing = [o for o, v in (("--function", args.function), ("--x-range", args.x_range),
                              ("--input-range", args.input_range), ("--output-range", args.output_range)) if not v]
    if missing:
        raise UsageError(f"synthesize function needs {', '.join(missing)}")
    points = 3
    if args.points:
        try:
            points = whole(args.points)
        except argparse.ArgumentTypeError:
            raise UsageError(f"--points: for function generation, the number of precision points, got "
                             f"{quote(args.points)}") from None
        if points > 200:
            raise UsageError("--points: at most 200 precision points")
    if _searching(args, 0, 0):
        with _search(args) as search:
            result = optimal_function(args.function, _range(args.x_range, "--x-range"),
                                      _range(args.input_range, "--input-range"),
                                      _range(args.output_range, "--output-range"), points, args.spacing,
                                      parse_value(args.ground, "length", "--ground"), _constraints(args), search)
        check, tmp = _realize(result.design, args.out)
        return result, check, tmp
    result = synthesize_function(args.function, _range(args.x_range, "--x-range"),
                                 _range(args.input_range, "--input-range"), _range(args.output_range, "--output-range"),
                                 points, args.spacing, parse_value(args.ground, "length", "--ground"))
    check, tmp = _realize(result.design, args.out)
    if result.defects and not check.defects:  # the closed form saw a defect that screwkin's check did not
        check = replace(check, defects=tuple(f"closed form: {d}" for d in result.defects))
    return result, check, tmp


def _path(args: argparse.Namespace) -> tuple:
    if not args.points:
        raise UsageError('synthesize path needs --points "x,y; x,y; x,y; ..."')
    points = _number_groups(args.points, "--points", 2)
    timing = None
    if args.timing:
        timing = [parse_value(x) for x in args.timing.replace(";", ",").split(",") if x.strip()]
    tolerance = parse_value(args.tolerance, "length", "--tolerance")
    if not tolerance > 0:
        raise UsageError("--tolerance must be a positive length")
    if _searching(args, len(points), 24):
        with _search(args) as search:
            result = optimal_path(points, timing, _constraints(args), search, tolerance)
    else:
        result = synthesize_path(points, timing, args.starts, args.seed, tolerance)
    check, tmp = _realize(result.design, args.out, tolerance=tolerance)
    return result, check, tmp


def _chains(args: argparse.Namespace) -> int:
    if args.links is None or args.dof is None:
        raise UsageError("synthesize chains needs --links N and --dof F")
    result = enumerate_chains(args.links, args.dof, args.prismatic)
    directory = None
    if args.out:
        directory = Path(args.out)
        if directory.exists() and not directory.is_dir():
            raise UsageError(f"-o {quote(str(directory))}: chains are written to a folder, and this is a file")
        try:
            directory.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputError(directory, os_reason(exc)) from None
        files = []
        for c in result.chains:
            for g in c.inversions:
                path = directory / f"chain{c.index:02d}_ground{g}.urdf"
                checked = None
                for seed in range(4):  # generic proportions: another seed when the first is special
                    write_output(path, write_urdf(chain_linkage(c, g, seed=seed, dof=args.dof)))
                    checked = check_chain_file(path, c.index, g, args.dof)
                    if not checked.problem:
                        break
                if checked.problem and args.reject_defects:
                    path.unlink()
                    continue
                files.append(checked)
        result = replace(result, files=tuple(files))
        if args.reject_defects and not files and result.chains:
            raise SynthesisError("synthesize chains", "every written mechanism had a problem (--reject-defects)")
    if not result.chains:
        raise SynthesisError("synthesize chains", f"no planar chain of {args.links} links and {args.dof} DOF "
                                                  f"with {args.prismatic} prismatic joints (every candidate has a "
                                                  "separable part, a degenerate sub-chain or a locked loop)")
    if args.json:
        print(json_of(chains_dict(result, directory)))
    else:
        print(chains_text(result, directory))
    return 0


__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]
