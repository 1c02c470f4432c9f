"""A play/scrub control for the static HTML page of ``view --sweep ... --html``.

meshcat's static export carries the animation, and its Animator has play, pause and a time
scrubber -- but inside dat.gui's panel (Open Controls > Animations > default), where a reader of a
report does not look.  This adds a bar at the bottom right of the page (the legend is bottom left): a play/pause button, a slider over
the frames and a readout of the frame and the input's value; it drives meshcat's own Animator
(``viewer.animator``: ``play``, ``pause``, ``seek``), so the two controls agree.  No file is
fetched: the page stays offline.
"""

from __future__ import annotations

from html import escape

from .jsonout import json_of

__all__ = ["player_html", "with_player", "PLAYER_ID"]

PLAYER_ID = "screwkin-player"


def player_html(labels, fps: float) -> str:
    """The bar's style, markup and script: ``labels`` says what each frame shows (the input's value
    as text, one per animation frame, frame k at time k / fps [s])."""
    labels = [str(x) for x in labels]
    n = len(labels)
    style = f"""<style>
#{PLAYER_ID} {{position: absolute; right: 12px; bottom: 12px; z-index: 11;
  display: flex; align-items: center; gap: 10px; padding: 6px 12px; background: rgba(255,255,255,0.9);
  border: 1px solid #bbb; border-radius: 4px; font: 13px/1.4 'DejaVu Sans', Arial, sans-serif; color: #222;}}
#{PLAYER_ID} button {{width: 34px; height: 26px; font-size: 14px; cursor: pointer;}}
#{PLAYER_ID} input[type=range] {{width: 200px;}}
#{PLAYER_ID} .sk-readout {{min-width: 170px; white-space: nowrap; font-variant-numeric: tabular-nums;}}
</style>"""
    markup = (f'<div id="{PLAYER_ID}" data-frames="{n}" data-fps="{fps:g}">'
              f'<button type="button" class="sk-play" title="play / pause" aria-label="play">&#9654;</button>'
              f'<input type="range" class="sk-scrub" min="0" max="{max(n - 1, 0)}" step="1" value="0" '
              f'aria-label="frame">'
              f'<span class="sk-readout">frame 1 / {n}: {escape(labels[0]) if labels else ""}</span></div>')
    script = f"""<script>
(function () {{
  var labels = {json_of(labels, indent=None)}, fps = {float(fps)!r}, n = labels.length;
  var bar = document.getElementById("{PLAYER_ID}");
  var button = bar.querySelector(".sk-play"), scrub = bar.querySelector(".sk-scrub");
  var readout = bar.querySelector(".sk-readout");
  function animator() {{
    var a = window.viewer && window.viewer.animator;
    return a && a.actions && a.actions.length ? a : null;
  }}
  function frameOf(t) {{ return Math.max(0, Math.min(n - 1, Math.round(t * fps))); }}
  function show(k) {{
    scrub.value = k;
    readout.textContent = "frame " + (k + 1) + " / " + n + ": " + labels[k];
  }}
  window.screwkinPlayer = {{
    seek: function (k) {{
      var a = animator(); if (!a) return false;
      a.pause(); var t = k / fps; a.seek(t); a.display_progress(t); show(k); return true;
    }},
    play: function () {{
      var a = animator(); if (!a) return false;
      if (frameOf(a.time) >= n - 1) a.reset();
      a.play(); return true;
    }},
    pause: function () {{ var a = animator(); if (a) a.pause(); return !!a; }},
    frame: function () {{ return Number(scrub.value); }},
    ready: function () {{ return !!animator(); }}
  }};
  button.addEventListener("click", function () {{
    var a = animator(); if (!a) return;
    if (a.playing) window.screwkinPlayer.pause(); else window.screwkinPlayer.play();
  }});
  scrub.addEventListener("input", function () {{ window.screwkinPlayer.seek(Number(scrub.value)); }});
  function tick() {{
    var a = animator();
    if (a) {{
      button.innerHTML = a.playing ? "&#10074;&#10074;" : "&#9654;";
      button.setAttribute("aria-label", a.playing ? "pause" : "play");
      if (a.playing) show(frameOf(a.time));
    }}
    requestAnimationFrame(tick);
  }}
  requestAnimationFrame(tick);
}})();
</script>"""
    return style + markup + script


def with_player(page: str, labels, fps: float) -> str:
    """``page`` (a static meshcat page) with the play/scrub bar before its ``</body>``."""
    at = page.rfind("</body>")
    at = len(page) if at < 0 else at
    return page[:at] + player_html(labels, fps) + page[at:]
