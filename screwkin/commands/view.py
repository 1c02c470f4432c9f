"""screwkin view: show the mechanism in meshcat (server on 127.0.0.1, or --html/--png)."""

from __future__ import annotations

import argparse
import contextlib
import os
import select
import signal
import sys
import tempfile

from ..analysis.position.interactive import Interactive
from ..analysis.position.position import PositionSolver
from ..analysis.singular import classify
from ..analysis.motion.singular_points import locate_singularities
from ..analysis.motion.sweep import sweep, sweep_inputs
from ..present.outfile import write_output
from ..present.view import build_scene, page, screenshot, show
from ..present.camera import PICTURE
from ..present.viewserver import ViewerServer
from ..errors import UsageError, quote
from ..present.interactive import InteractiveView, viser_module
from ..present.player import with_player
from ..units import unit_text
from ..present.viewplanar import colour_links, link_colours, planar_basis
from ._configuration import add_branch_option, add_configuration_options, configuration, mode_line, moved_not_set
from ._output_frame import add_point_option, named_points
from ._values import joint_assignments, joint_inputs, parse_range
from ..model.topology import open_joints
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any
    from screwkin.model.mechanism import Mechanism
    from collections.abc import Callable

__all__ = ["NAME", "NEEDS_MECHANISM", "add_parser", "run"]

NAME = "view"
NEEDS_MECHANISM = True


def add_parser(sub: argparse._SubParsersAction, common: Callable[..., None], scaled: Callable[..., None]) -> None:
    sp = sub.add_parser("view", help="show the mechanism in meshcat (server on 127.0.0.1, or --html/--png)")
    common(sp)
    add_configuration_options(sp)
    add_branch_option(sp, "--sweep's motion")
    sp.add_argument("--output", help="output link: its frame is drawn, singularities are marked on it")
    sp.add_argument("--sweep", metavar="NAME=A:B:N", help="animate the motion of one input (other inputs from --set)")
    sp.add_argument("--html", help="write a self-contained static HTML page of the scene and exit")
    sp.add_argument("--png", help="write a picture of the scene (headless Chromium) and exit")
    sp.add_argument("--interactive", action="store_true",
                    help="a page with a slider per input (viser: pip install viser): the loops re-solved as they "
                         "move, the assembly modes, singularity warnings, the output pose and --points")
    add_point_option(sp)
    sp.add_argument("--port", type=port_number, help="the web page's port on 127.0.0.1 (default: the first free one "
                                                     "from 7000); a port in use is an error")
    scaled(sp, point=False)


def port_number(text: str) -> int:
    """argparse type of a TCP port a person types: 1024 to 65535 (no privileged port)."""
    try:
        port = int(text.strip())
    except (ValueError, AttributeError):
        raise argparse.ArgumentTypeError(f"expected a port number, got {quote(text, 20)}") from None
    if not 1024 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"must be from 1024 to 65535, got {port}")
    return port


class _Stop:
    """SIGTERM, SIGHUP and SIGINT (Ctrl-C) stop ``view`` cleanly whenever they arrive: its handler
    records the first signal (``signum``; a second while stopping is ignored).  While the command
    gets ready (the server starting, pictures written) the handler also raises KeyboardInterrupt, so
    that a long start can be stopped (``run`` catches it as a stop); from ``_serve_until_stopped``
    on (before its line is printed) it only records, and the wait checks the record: a signal that
    arrives between saying where the page is and waiting is not lost (it exited 130 without its
    "stopped by" line), and ``signal.set_wakeup_fd`` wakes the wait at once.  The handlers and the
    wakeup descriptor are installed before the server starts; the previous ones come back after."""

    def __init__(self) -> None:
        self.signum = None
        self.interrupting = True
        self.wake = None

    def _handle(self, signum, frame) -> None:
        if self.signum is None:
            self.signum = signum
            if self.interrupting:
                raise KeyboardInterrupt

    def __enter__(self):
        self.wake, self._wake_w = os.pipe()
        for fd in (self.wake, self._wake_w):
            os.set_blocking(fd, False)
        self._previous_fd = signal.set_wakeup_fd(self._wake_w, warn_on_full_buffer=False)
        self._previous = {s: signal.signal(s, self._handle) for s in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT)}
        return self

    def __exit__(self, *exc: Any) -> None:
        for s, handler in self._previous.items():
            signal.signal(s, handler)
        signal.set_wakeup_fd(self._previous_fd)
        os.close(self.wake)
        os.close(self._wake_w)

    def wait(self) -> None:
        """Until a signal has been recorded (the handler only records from now on)."""
        self.interrupting = False
        while self.signum is None:
            select.select([self.wake], [], [], 60.0)  # the wakeup byte: at once, even if it came before
            with contextlib.suppress(BlockingIOError):
                while os.read(self.wake, 64):
                    pass

    def said(self, where: str) -> str:
        return f"stopped by {signal.Signals(self.signum).name}: {where}"


def run(mech: Mechanism, args: argparse.Namespace) -> int:
    if args.interactive:
        return _interactive(mech, args)
    if getattr(args, "points", None):
        raise UsageError(f"{mech.path}: --point goes with --interactive (its position is read out there)")
    motion, singular, frames = None, [], None
    if not args.sweep:
        q = configuration(mech, args)
    else:  # (the range and the --set values checked before the configuration is solved)
        name, values, unit = parse_range(args.sweep, "--sweep", mech)
        fixed = joint_assignments(mech, args.set, "--set")
        moved_not_set(fixed, name, "view --sweep moves it over its range")
        inputs = sweep_inputs(mech, name, fixed)
        solver = PositionSolver(mech, inputs)
        # the mode followed (--mode K, --near), chosen and said as sweep's
        res = sweep(solver, name, values[0], values[-1], len(values) - 1, fixed=fixed, branch=args.branch,
                    q_start=lambda: configuration(mech, args, moved={name: float(values[0])}, inputs=inputs))
        for line in res.change_point_notes:  # the change points passed, and the branch taken at each
            print(f"note: {line}")
        motion = res.q
        q = res.q[0]
        frames = [f"{name} = {unit_text(v, unit, 4)}" for v in res.values]
        for s in locate_singularities(solver, res, output=args.output):
            rep = classify(mech, s.q, output=args.output)
            twist = next((t for t in rep.singular_twists if t.kind == s.kind), None)
            singular.append((s.q, twist))
            print(f"singular ({s.kind}) at {name} = {s.input:.9g}")
    scene = build_scene(mech, q, output=args.output, singular=singular)
    server = None
    with _Stop() as stop:
        try:
            with ViewerServer(port=args.port) as server:
                show(mech, scene, server.viewer, q, motion=motion, fps=FPS)
                if args.html or args.png:
                    _pictures(mech, args, server, scene, frames)
                    stop.interrupting = False
                    return 0
                _serve_until_stopped(f"meshcat: {server.web_url}", stop)
        except KeyboardInterrupt:  # a signal while getting ready (the handler raised it): a stop as any other
            if stop.signum is None:
                raise
    closed = f"the meshcat server on port {server.port} is closed" if server else "before the meshcat server served"
    print(stop.said(closed), flush=True)
    return 0


#: Frames per second of a sweep's animation
FPS = 30


def _pictures(mech: Mechanism, args: argparse.Namespace, server, scene, frames=None) -> None:
    """--html (with a play/scrub bar when ``frames``, the text of each animation frame) and --png."""
    html = server.viewer.static_html()
    title = os.path.basename(mech.path) + (f", {args.sweep.split('=')[0].strip()} swept" if args.sweep else "")
    if args.html:
        write_output(args.html, with_player(page(html, scene, title), frames, FPS) if frames else page(html, scene, title))
        print(f"wrote {args.html}")
    if args.png:
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "scene.html")
            with open(path, "w") as f:
                f.write(page(html, scene, title, controls=False, size=PICTURE))
            screenshot(path, args.png)
        print(f"wrote {args.png}")


def _interactive(mech: Mechanism, args: argparse.Namespace) -> int:
    """view --interactive: the viser page, served until a signal stops it."""
    if args.sweep or args.html or args.png:
        raise UsageError(f"{mech.path}: --interactive is a live page: leave out --sweep, --html and --png")
    viser_module()  # a clear message before any work when viser is missing
    given = joint_inputs(mech, args, "view --interactive")
    # a slider per input: the actuated joints and the joints no loop passes through (a serial arm's)
    names = list(dict.fromkeys([*mech.actuated, *open_joints(mech)])) or list(given)
    extra = [n for n in given if n not in names]
    if extra:
        raise UsageError(f"{mech.path}: --set {', '.join(extra)}: not an input (inputs: {', '.join(names) or 'none'})")
    # the inputs not given start at the file's values (the documented default), said in the line below
    live = Interactive(mech, names, values=given, mode=args.mode or 1, output=args.output,
                       points=named_points(mech, args))
    print(live.opened, flush=True)
    if live.mode_index[1] > 1:  # the mode it opened in, said as every command says it
        print(f"note: {mode_line(*live.mode_index, near=False)}", file=sys.stderr)
    for note in live.notes:
        print(f"note: {note}", file=sys.stderr)
    q = live.state.q
    scene = build_scene(mech, q, output=args.output)
    if planar_basis(mech, q) is not None:
        colour_links(scene, link_colours(mech, q))
    view = None
    with _Stop() as stop:
        try:
            view = InteractiveView(mech, live, scene, port=args.port, title=os.path.basename(mech.path))
            try:
                _serve_until_stopped(f"interactive view: {view.url}", stop)
            finally:
                stop.interrupting = False
                view.close()
        except KeyboardInterrupt:  # a signal while getting ready: a stop as any other
            if stop.signum is None:
                raise
    print(stop.said(f"the server on port {view.port} is closed" if view else "before the server served"), flush=True)
    return 0


def _serve_until_stopped(where: str, stop: _Stop) -> None:
    """Say where the page is served and wait until SIGINT (Ctrl-C), SIGTERM or SIGHUP: from here on the
    handler only records the signal (it raises nothing), so one that arrives while or just after the line
    is printed ends the wait as one that arrives later does."""
    stop.interrupting = False
    print(f"{where}  (Ctrl-C to stop)", flush=True)
    stop.wait()
