"""screwkin mobility: degrees of freedom, the counts and the screw-theory mobility."""

from __future__ import annotations

from dataclasses import replace

from ..analysis.mobility import analyze_mobility
from ..errors import UsageError
from ..present.mobility import mobility_dict, mobility_text
from ..present.progress import EVERY, Progress
from ._common import emit
from ._configuration import add_configuration_options, configuration, with_mode
from ._options import count
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    import argparse
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "mobility"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable, scaled: Callable) -> None:
    sp = sub.add_parser(NAME, help="degrees of freedom: counts and screw-theory mobility")
    common(sp)
    sp.add_argument("--output", help="link whose motion to characterize (e.g. the platform)")
    sp.add_argument("--point", action="store_true", help="the output link's origin as a point (3 translations)")
    add_configuration_options(sp)  # where the local analysis decides the mobility (default: the file's)
    sp.add_argument("--local-samples", type=count("local_samples"), metavar="N",
                    help="at a singular point, continue the local series along at most N directions sampled on "
                         "one tangent space (default 400; the answer says when some were left out)")


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    if args.point and not args.output:
        raise UsageError("--point needs --output LINK")
    given = any(getattr(args, k, None) for k in ("set", "set_angle", "set_length", "near", "mode"))
    if args.local_samples:
        mech.tolerances = replace(mech.tolerances, local_samples=args.local_samples)
    at = configuration(mech, args) if given else None
    with Progress(label="mobility", unit="tangent directions continued", every=EVERY) as progress:  # a terminal only
        result = analyze_mobility(mech, output=args.output, point=args.point, at=at, suggest=True, progress=progress)
    return emit(args, lambda: with_mode(args, mobility_dict(result)), lambda: mobility_text(result, args.explain))
