"""screwkin scan: singularity scan of a serial chain over random configurations."""

from __future__ import annotations

import time

from ..analysis.singularities.scan import scan
from ..present.jsonout import json_of
from ..present.outfile import write_output
from ..present.report import scan_csv, scan_dict
from ._output_frame import output_frame
from ._options import count
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "scan"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable[..., None], scaled: Callable[..., None]) -> None:
    sp = sub.add_parser("scan", help="singularity scan of a serial chain over random configurations")
    common(sp)
    sp.add_argument("--output", help="the chain's last link (e.g. the flange; or give a named --point)")
    sp.add_argument("--samples", type=count("samples"), default=100000, help="random configurations (default 100000)")
    sp.add_argument("--seed", type=count("seed"), default=0, help="random seed (default 0)")
    sp.add_argument("--measure", choices=["sigma_ratio", "det"], default="sigma_ratio",
                    help="smallest / largest singular value (default) or the determinant (6 joints)")
    scaled(sp)
    sp.add_argument("--threads", type=count("threads"), help="threads (default: the machine's cores)")
    sp.add_argument("--csv", help="write every sample (joint values and the measure) to this CSV file")


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    t = time.perf_counter()
    output, point = output_frame(mech, args, required=True)  # a named --point is the output
    res = scan(mech, output, args.samples, args.seed, args.measure, None, args.threads, point=point)
    elapsed = time.perf_counter() - t
    if args.csv:
        write_output(args.csv, scan_csv(res))
    d = scan_dict(res)
    if args.json:
        print(json_of({"file": mech.path, **d, "seconds": elapsed}))
        return 0
    what = (("smallest / largest singular value of the output origin's velocity Jacobian (a point)"
             if res.point else "smallest / largest singular value of the output Jacobian (v / L, w)")
            + f", L = {res.length:.4g} m" if res.measure == "sigma_ratio" else "determinant of the output Jacobian (v, w)")
    worst = ", ".join(f"{n}={v:.6g}" for n, v in d["min_configuration"].items())
    p = d["percentiles"]
    print(f"scan of {mech.path}, chain to '{res.output}' ({len(res.joints)} joints): {res.samples} random "
          f"configurations within the joint limits (seed {res.seed}), {elapsed:.2f} s")
    print(f"measure: {what}")
    print(f"  nearest a singularity: {d['min']:.3g} at {worst}")
    print(f"  |measure| percentiles: 1% {p['1']:.3g}, 5% {p['5']:.3g}, median {p['50']:.3g}; largest {d['max']:.3g}")
    if d["singular_fraction"] is not None:
        print(f"  singular (below {res.threshold:g}): {100 * d['singular_fraction']:.3g}% of the configurations")
    return 0
