"""screwkin mobility: degrees of freedom, the counts and the screw-theory mobility."""

from __future__ import annotations

from ..analysis.mobility import analyze_mobility
from ..errors import UsageError
from ..present.mobility import mobility_dict, mobility_text
from ._common import emit
from ._configuration import add_configuration_options, configuration, with_mode

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "mobility"
NEEDS_MECHANISM = True


def add_parser(sub, common, scaled):
    sp = sub.add_parser(NAME, help="degrees of freedom: counts and screw-theory mobility")
    common(sp)
    sp.add_argument("--output", help="link whose motion to characterize (e.g. the platform)")
    sp.add_argument("--point", action="store_true", help="the output link's origin as a point (3 translations)")
    add_configuration_options(sp)  # where the local analysis decides the mobility (default: the file's)


def run(mech, args) -> int:
    if args.point and not args.output:
        raise UsageError("--point needs --output LINK")
    given = any(getattr(args, k, None) for k in ("set", "set_angle", "set_length", "near", "mode"))
    at = configuration(mech, args) if given else None
    result = analyze_mobility(mech, output=args.output, point=args.point, at=at, suggest=True)
    return emit(args, lambda: with_mode(args, mobility_dict(result)), lambda: mobility_text(result, args.explain))
