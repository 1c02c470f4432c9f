"""``screwkin study SPEC.yaml``: a family of mechanisms (a xacro file) over its parameters,
the metrics of every design, on Dask (a local cluster, or ``--scheduler tcp://...``)."""

from __future__ import annotations

from dataclasses import replace

from ..parallel.study import run_study
from ..errors import UsageError, quote
from ..files.study import read_study_spec
from ..present.jsonout import json_of
from ..present.study import (
    check_table_path,
    metrics_png,
    pareto_png,
    study_dict,
    study_text,
    write_table,
)
from ..present.progress import Progress
from ._configuration import add_mode_option
from ._options import count, seconds
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

NAME = "study"
NEEDS_MECHANISM = False


def add_parser(sub: argparse._SubParsersAction, common: Callable[..., None], scaled: Callable[..., None]) -> None:
    sp = sub.add_parser(NAME, help="design-space study of a family of mechanisms (a xacro file) on Dask")
    sp.add_argument("spec", metavar="SPEC.yaml", help="the study: file, parameters, sampling, metrics (docs/format.md)")
    common(sp, mechanism=False)
    sp.add_argument("--scheduler", metavar="ADDRESS",
                    help="a running dask.distributed scheduler, tcp://HOST:PORT (default: a local cluster)")
    sp.add_argument("--workers", type=count("workers"), metavar="N",
                    help="processes of the local cluster (default: the cores, at most 4; 0: in this process; "
                         "at most 64)")
    sp.add_argument("-o", "--output", dest="table", metavar="FILE",
                    help="write the table: results.csv, or results.parquet (needs pyarrow)")
    sp.add_argument("--plot", metavar="PREFIX",
                    help="PREFIX-metrics.png (each metric against each parameter) and, with pareto columns, "
                         "PREFIX-pareto.png (needs matplotlib)")
    sp.add_argument("--pareto", metavar="max:COL,min:COL",
                    help="the two columns of the Pareto front and their goals (overrides the spec's pareto)")
    sp.add_argument("--timeout", type=seconds("timeout"), default=10.0,
                    help="seconds to reach the scheduler and a worker (default 10)")
    add_mode_option(sp, "each design's inputs at their values in its assembled configuration, for the metrics "
                        "that follow one (transmission_angle, the workspace metrics); overrides the spec's mode")
    sp.add_argument("--design-timeout", type=seconds("design_timeout"), metavar="S",
                    help="seconds one design may take before its row is a failure (overrides the spec's timeout; "
                         "default 120)")


def _pareto(text: str) -> tuple:
    goals = []
    for part in text.split(","):
        goal, sep, column = part.strip().partition(":")
        if not sep or goal not in ("max", "min") or not column:
            raise UsageError(f"--pareto expects max:COLUMN,min:COLUMN (two columns), got {quote(text)}")
        goals.append((column, goal))
    if len(goals) != 2 or goals[0][0] == goals[1][0]:
        raise UsageError(f"--pareto expects two different columns, got {quote(text)}")
    return tuple(goals)


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    if args.workers is not None and args.workers < 0:
        raise UsageError("--workers must be 0 or more (0: in this process)")
    if args.table:
        check_table_path(args.table)
    spec = read_study_spec(args.spec)
    if args.pareto:
        spec = replace(spec, pareto=_pareto(args.pareto))
    if args.mode is not None:
        spec = replace(spec, mode=args.mode)
    if args.design_timeout is not None:
        if not 0 < args.design_timeout <= 86400:
            raise UsageError(f"--design-timeout must be more than 0 s and at most 86400, got {args.design_timeout:g}")
        spec = replace(spec, timeout=float(args.design_timeout))
    progress = Progress()
    result = run_study(spec, scheduler=args.scheduler, workers=args.workers, progress=progress,
                       timeout=args.timeout)
    n, ok = len(result.rows), len(result.succeeded)
    progress.finish(f"study: {n} designs in {result.seconds:.1f} s ({n / max(result.seconds, 1e-9):.1f} designs/s, "
                    f"{result.workers} worker{'s' if result.workers != 1 else ''}): {ok} analysed, "
                    f"{n - ok} failed")
    if args.table:
        write_table(result, args.table)
    if args.plot:
        metrics_png(result, f"{args.plot}-metrics.png")
        if spec.pareto and result.succeeded:
            pareto_png(result, f"{args.plot}-pareto.png")
    if args.json:
        print(json_of(study_dict(result)))
    else:
        print(study_text(result, args.table))
    return 0 if ok or not n else 1
