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

from ..errors import OutputError, UsageError, quote
from .draw import draw_mechanism
from .outfile import write_output
from .plots import pyplot
from typing import TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Callable
    from matplotlib.figure import Figure
    from collections.abc import Sequence
    from screwkin.analysis.course.skeleton import Skeleton

__all__ = ["FORMATS", "animation_format", "write_animation"]

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
                    angles: bool = False, subtitle: str | None = None, progress: Callable[[int, int], object] | None=None) -> int:
    """Write the animation of ``skeletons`` (one per frame, each with its title) to ``path`` (.gif or
    .mp4) at ``fps`` frames per second; ``traces``: name -> (len(skeletons), 2) path of a point in
    the drawing plane [m], drawn up to the current frame (backwards: the point is marked where it is
    now); ``progress(done, total)`` is told of the frames framed, then drawn.  Returns the number of
    frames written."""
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
                                     size=size, limits=limits, angles=angles, subtitle=subtitle)
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
