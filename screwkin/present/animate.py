"""Animations of skeleton diagrams (``draw --animate``): one frame per configuration drawn by
:func:`screwkin.present.draw.draw_mechanism`, every frame with the same framing (the union of
the drawings of the whole motion) and the same symbol scale, named points' paths growing frame
by frame; written as a GIF with Pillow or an MP4 with imageio-ffmpeg (an optional package:
``pip install imageio-ffmpeg``)."""

from __future__ import annotations

import io
import os
import tempfile

import numpy as np

from ..analysis.course.skeleton import skeleton
from ..analysis.motion.links import motion_along
from ..errors import OutputError, UsageError, quote
from ..units import unit_text
from .draw import draw_mechanism, drawing_title
from .outfile import write_output
from .plots import pyplot
from typing import TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Callable
    from matplotlib.figure import Figure
    from collections.abc import Sequence
    from screwkin.analysis.course.skeleton import Skeleton
    from screwkin.analysis.singularities.mode_connect import Connection
    from screwkin.model.mechanism import Mechanism

__all__ = ["FORMATS", "animate_configurations", "animate_connection", "animation_format", "connection_frames",
           "write_animation"]

FORMATS = (".gif", ".mp4")
DPI = 80  # the figures are 10 x 6.4 in: 800 x 512 pixels (both multiples of 16, as video encoders like)


def _ffmpeg():
    try:
        import imageio_ffmpeg
    except ImportError:
        return None
    return imageio_ffmpeg


def animation_format(path: str) -> str:
    """'.gif' or '.mp4', by the suffix of ``path``; an MP4 needs imageio-ffmpeg (a usage error naming
    the package when it is not installed, before any work is done)."""
    ext = os.path.splitext(str(path))[1].lower()
    if ext not in FORMATS or len(os.path.basename(str(path))) <= len(ext):
        raise UsageError(f"--animate expects a file name ending in .gif or .mp4, got {quote(str(path), 80)}")
    if ext == ".mp4" and _ffmpeg() is None:
        raise UsageError("--animate OUT.mp4 needs imageio-ffmpeg (pip install imageio-ffmpeg); "
                         "or write a GIF (OUT.gif, Pillow)")
    return ext


def _limits(skeletons: Sequence[Skeleton], titles: Sequence[str], traces: dict | None, size, angles: bool, progress: Callable[[int, int], object] | None=None) -> tuple[tuple, tuple]:
    """The framing of the whole motion: the union of the limits each frame would take alone
    (whole paths drawn), so that every frame is drawn in the same window."""
    plt = pyplot("--animate")
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for k, (skel, title) in enumerate(zip(skeletons, titles)):
        if progress is not None:
            progress(k, 2 * len(skeletons))
        fig = draw_mechanism(skel, title=title, traces=traces, size=size, angles=angles)
        ax = fig.axes[0]
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        lo, hi = np.minimum(lo, [x0, y0]), np.maximum(hi, [x1, y1])
        plt.close(fig)
    return (lo[0], hi[0]), (lo[1], hi[1])


def _pixels(fig: Figure) -> np.ndarray:
    fig.set_dpi(DPI)
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()


def write_animation(path: str, skeletons: Sequence[Skeleton], titles: Sequence[str], traces: dict | None = None, fps: float = 20.0,
                    angles: bool = False, subtitle: str | Sequence[str] | None = None,
                    progress: Callable[[int, int], object] | None=None) -> int:
    """Write the animation of ``skeletons`` (one per frame, each with its title) to ``path`` (.gif or
    .mp4) at ``fps`` frames per second; ``traces``: name -> (len(skeletons), 2) path of a point in
    the drawing plane [m], drawn up to the current frame (backwards: the point is marked where it is
    now); ``subtitle``: one line under every title, or one per frame; ``progress(done, total)`` is told
    of the frames framed, then drawn.  Returns the number of frames written."""
    ext = animation_format(path)
    traces = {n: np.asarray(xy, float) for n, xy in (traces or {}).items()}
    size = max(s.size for s in skeletons)
    limits = _limits(skeletons, titles, traces, size, angles, progress)
    plt = pyplot("--animate")
    from PIL import Image  # (with matplotlib)

    frames = []
    writer = None
    with tempfile.TemporaryDirectory() as folder:  # ffmpeg's MP4 is made here, then written to ``path``
        video = os.path.join(folder, "animation.mp4")
        try:
            for k, (skel, title) in enumerate(zip(skeletons, titles)):
                if progress is not None:
                    progress(len(skeletons) + k, 2 * len(skeletons))
                fig = draw_mechanism(skel, title=title, traces={n: xy[k::-1] for n, xy in traces.items()},
                                     size=size, limits=limits, angles=angles,
                                     subtitle=subtitle if subtitle is None or isinstance(subtitle, str) else subtitle[k])
                image = _pixels(fig)
                plt.close(fig)
                if ext == ".gif":  # a palette of its own (fast octree: a third of the default's time and memory)
                    frames.append(Image.fromarray(image).quantize(method=Image.Quantize.FASTOCTREE))
                    continue
                if writer is None:
                    writer = _ffmpeg().write_frames(video, (image.shape[1], image.shape[0]), fps=float(fps),
                                                    macro_block_size=1, quality=7)
                    writer.send(None)
                writer.send(np.ascontiguousarray(image).tobytes())
        except OSError as exc:  # the temporary folder is full: the output itself was not touched
            raise OutputError(video, f"{exc.strerror or exc} (the video is made there first)") from None
        finally:
            if writer is not None:
                writer.close()
        if ext == ".gif":
            buf = io.BytesIO()
            frames[0].save(buf, format="GIF", save_all=True, append_images=frames[1:],
                           duration=int(round(1000 / fps)), loop=0, optimize=False)
            write_output(path, buf.getvalue())
        else:
            with open(video, "rb") as f:
                write_output(path, f.read())
    return len(skeletons)


def animate_configurations(path: str, mech: Mechanism, qs: Sequence[np.ndarray], inputs: list[str] | None,
                           titles: Sequence[str], points=(), fps: float = 20.0, angles: bool = False,
                           subtitles: Sequence[str] | None = None,
                           progress: Callable[[int, int], object] | None = None) -> tuple[int, dict]:
    """The animation of ``mech`` through the configurations ``qs``, one frame each (``draw --animate``'s
    drawing, written by write_animation): the skeletons in the drawing plane of the first (``inputs``
    marked), each named point of ``points`` (motion.Point) traced.  Returns (frames written, the points'
    paths in the drawing plane: name -> (len(qs), 2) [m])."""
    first = skeleton(mech, qs[0], inputs)
    skels = [first, *(skeleton(mech, q, inputs, basis=first.basis) for q in qs[1:])]
    traces = {}
    if points:
        motion = motion_along(mech, np.asarray(qs), np.zeros((len(qs), mech.nv)), np.zeros((len(qs), mech.nv)), points)
        e1, e2, _ = (np.asarray(v) for v in first.basis)
        for p in points:
            P = np.asarray(motion.points[p.name]["position"])
            traces[p.name] = np.stack([P @ e1, P @ e2], axis=1)
    space = None if first.planar else f"schematic projection of a {first.motion_space} mechanism"
    if subtitles is not None:
        subtitle = [f"{space}; {line}" if space else line for line in subtitles]
    else:
        subtitle = space
    n = write_animation(path, skels, titles, traces, fps=fps, angles=angles, subtitle=subtitle, progress=progress)
    return n, traces


def connection_frames(mech: Mechanism, conn: Connection, inputs: list[str], units: dict | None = None) -> tuple:
    """(titles, subtitles) of the frames along a connection's path (``solve --connect --animate``, ``draw
    --connect I:J --animate``): the title the inputs' values at the frame (each in ``units``[name], the unit
    typed; rad or m when not given), the subtitle the two modes (numbered from 1), the smallest actuator
    measure from the start to the frame (conn.sigma_so_far: over every point followed, not only the frames)
    and the frame's number."""
    units = units or {}
    i, j = conn.modes[0] + 1, conn.modes[1] + 1
    n = len(conn.path)
    titles, subtitles = [], []
    for k, q in enumerate(conn.path):
        values = mech.joint_values(q)
        said = ", ".join(f"{name} = " + unit_text(values[name], units.get(name) or (
            "m" if mech.translational[mech.coordinate(name).idx_v] else "rad"), 5) for name in inputs)
        titles.append(drawing_title(mech, said))
        smallest = "" if conn.sigma_so_far is None else f": smallest actuator measure so far {conn.sigma_so_far[k]:.3g}"
        subtitles.append(f"mode {i} to mode {j} without a singularity{smallest} (frame {k + 1} of {n})")
    return titles, subtitles


def animate_connection(path: str, mech: Mechanism, conn: Connection, inputs: list[str], units: dict | None = None,
                       points=(), fps: float = 10.0, angles: bool = False,
                       progress: Callable[[int, int], object] | None = None) -> int:
    """Write the animation of a joined connection's path (conn.path: thinned as mode_connect.THIN says, its
    first and last points the two modes), one frame per point, titled by connection_frames.  Returns the
    number of frames written."""
    titles, subtitles = connection_frames(mech, conn, inputs, units)
    n, _ = animate_configurations(path, mech, list(conn.path), inputs, titles, points, fps=fps, angles=angles,
                                  subtitles=subtitles, progress=progress)
    return n
