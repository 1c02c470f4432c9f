"""screwkin view: show the mechanism in meshcat (server on 127.0.0.1, or --html/--png)."""

from __future__ import annotations

import os
import tempfile
import time

from ..analysis.position import PositionSolver
from ..analysis.singular import classify
from ..analysis.sweep import locate_singularities, sweep
from ..present.view import PICTURE, ViewerServer, build_scene, page, screenshot, show
from ._common import (
    add_configuration_options,
    configuration,
    joint_assignments,
    parse_range,
)

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "view"
NEEDS_MECHANISM = True


def add_parser(sub, common, scaled):
    sp = sub.add_parser("view", help="show the mechanism in meshcat (server on 127.0.0.1, or --html/--png)")
    common(sp)
    add_configuration_options(sp)
    sp.add_argument("--output", help="output link: its frame is drawn, singularities are marked on it")
    sp.add_argument("--sweep", metavar="NAME=A:B:N", help="animate the motion of one input (other inputs from --set)")
    sp.add_argument("--html", help="write a self-contained static HTML page of the scene and exit")
    sp.add_argument("--png", help="write a picture of the scene (headless Chromium) and exit")
    scaled(sp, point=False)


def run(mech, args) -> int:
    q = configuration(mech, args)
    motion, singular = None, []
    if args.sweep:
        name, values = parse_range(args.sweep, "--sweep")
        fixed = {k: v for k, v in joint_assignments(mech, args.set, "--set").items() if k != name}
        inputs = list(mech.actuated) if name in mech.actuated else [name, *fixed]
        solver = PositionSolver(mech, inputs)
        res = sweep(solver, name, values[0], values[-1], len(values) - 1, fixed=fixed)
        motion = res.q
        q = res.q[0]
        for s in locate_singularities(solver, res, output=args.output):
            rep = classify(mech, s.q, output=args.output)
            twist = next((t for t in rep.singular_twists if t.kind == s.kind), None)
            singular.append((s.q, twist))
            print(f"singular ({s.kind}) at {name} = {s.input:.9g}")
    scene = build_scene(mech, q, output=args.output, singular=singular)
    with ViewerServer() as server:
        show(mech, scene, server.viewer, q, motion=motion)
        if args.html or args.png:
            html = server.viewer.static_html()
            title = os.path.basename(mech.path) + (f", {args.sweep.split('=')[0].strip()} swept" if args.sweep else "")
            if args.html:
                with open(args.html, "w") as f:
                    f.write(page(html, scene, title))
                print(f"wrote {args.html}")
            if args.png:
                with tempfile.TemporaryDirectory() as d:
                    path = os.path.join(d, "scene.html")
                    with open(path, "w") as f:
                        f.write(page(html, scene, title, controls=False, size=PICTURE))
                    screenshot(path, args.png)
                print(f"wrote {args.png}")
            return 0
        print(f"meshcat: {server.web_url}  (Ctrl-C to stop)", flush=True)
        try:
            while True:
                time.sleep(1)
        except KeyboardInterrupt:
            return 0
