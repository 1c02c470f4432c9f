"""Long work shows its progress on a terminal, a line redrawn every few seconds, and nothing elsewhere
(issue 33): present/progress.Progress, the callable the analyses are given."""

from __future__ import annotations

import io

import pytest

import screwkin.present.progress as progress_module
from screwkin.present.progress import Progress


class Tty(io.StringIO):
    def isatty(self):
        return True


def test_redrawn_at_most_every_few_seconds_on_a_terminal(monkeypatch):
    clock = [100.0]
    monkeypatch.setattr(progress_module.time, "perf_counter", lambda: clock[0])
    tty = Tty()
    p = Progress(tty, label="sweep", unit="steps", every=2.0)
    p(10, 1000)  # at once: not yet (short work shows nothing)
    assert tty.getvalue() == ""
    clock[0] += 2.5
    p(250, 1000)
    # 2.5 s for 250 steps: 7.5 s for the 750 left
    assert tty.getvalue() == "\rsweep [#######.......................] 250/1,000 steps, 2 s, 8 s left "
    clock[0] += 1.0
    p(300, 1000)  # 1 s after the last line: not redrawn
    assert tty.getvalue().count("\r") == 1
    clock[0] += 2.0
    p(500, 1000)
    assert tty.getvalue().count("\r") == 2 and "500/1,000 steps" in tty.getvalue()
    p.clear()
    assert tty.getvalue().endswith("\r\x1b[K")


def test_nothing_but_the_final_line_when_not_a_terminal():
    plain = io.StringIO()
    p = Progress(plain, label="dynamics", unit="configurations")
    p(5, 10)
    p.clear()
    assert plain.getvalue() == ""
    p.finish("done")
    assert plain.getvalue() == "done\n"


@pytest.mark.slow  # seconds of work are needed for a line to be drawn
def test_a_long_streamed_sweep_shows_its_progress_on_a_terminal_only(tmp_path):
    """A 300,000-step streamed sweep of the MJCF four-bar (batched: several seconds) with stderr a
    pseudo-terminal draws 'sweep [###...] N/300,000 steps' lines; with stderr a pipe, none."""
    import os
    import subprocess
    import sys

    from conftest import ROOT

    argv = [sys.executable, "-m", "screwkin", "sweep", str(ROOT / "tests" / "data" / "mjcf" / "fourbar.xml"),
            "--input", "crank_joint", "--from", "0", "--to", "360deg", "--steps", "300000", "--csv",
            str(tmp_path / "s.csv")]
    master, slave = os.openpty()
    p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    seen = b""
    while True:
        try:
            chunk = os.read(master, 4096)
        except OSError:  # the terminal's other end closed
            break
        if not chunk:
            break
        seen += chunk
    out = p.communicate(timeout=600)[0].decode()
    os.close(master)
    assert p.returncode == 0 and "300,001 rows written" in out
    text = seen.decode()
    assert "\rsweep [" in text and "/300,000 steps" in text and text.endswith("\r\x1b[K"), text[-300:]
    plain = subprocess.run(argv, capture_output=True, text=True, timeout=600)
    # the one line naming the assembly mode taken is said on a pipe too; no progress is
    assert plain.returncode == 0 and plain.stderr == ("note: the assembly mode Newton reaches from the file's configuration "
                                                "(no search: --mode K lists every mode and takes the K-th)\n")
