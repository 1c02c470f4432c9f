"""study --scheduler at an address where no Dask scheduler answers (issue 22 item 3): the client read the
peer's first 8 bytes as a frame length and tried to allocate 3 EiB (exit 3, MemoryError).  Each hostile
peer here runs on 127.0.0.1 in a thread of the test, bounded in time; the answer must be one line, exit 2,
within the guard."""

from __future__ import annotations

import socket
import threading

import pytest

from conftest import ROOT, no_hang
from screwkin.cli import main

SPEC = str(ROOT / "examples" / "fourbar_study.yaml")


class Peer:
    """A loopback server that answers every connection with ``reply`` (None: accepts and says nothing)."""

    def __init__(self, reply):
        self.reply = reply
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.sock.settimeout(0.2)
        self.port = self.sock.getsockname()[1]
        self.rounds = 150  # accept() waits 0.2 s a round: the server ends by itself after at most 30 s
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self):
        held = []
        while self.rounds > 0:
            self.rounds -= 1
            try:
                conn, _ = self.sock.accept()
            except (socket.timeout, OSError):
                continue
            if self.reply is not None:
                try:
                    conn.sendall(self.reply)
                except OSError:
                    pass
            held.append(conn)
        for c in held:
            c.close()

    def close(self):
        self.rounds = 0
        self.thread.join(timeout=5)
        self.sock.close()


@pytest.mark.parametrize("reply,words", [
    (b"\xff" * 8, "announces 18446744073709551615 bytes"),
    (b"HTTP/1.1 400 Bad Request\r\n\r\n", "not a Dask scheduler"),
    (b"\x10\x00\x00\x00\x00\x00\x00\x00" + b"\x01\x00\x00\x00\x00\x00\x00\x00" + b"\xff" * 8,
     "announces 18446744073709551615 bytes of frames"),
    (None, "no handshake within 2 s"),
])
def test_a_peer_that_is_no_scheduler_is_named_so(reply, words, capsys):
    peer = Peer(reply)
    try:
        with no_hang(30):
            code = main(["study", SPEC, "--scheduler", f"tcp://127.0.0.1:{peer.port}", "--timeout", "2"])
    finally:
        peer.close()
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert words in err


@pytest.mark.parametrize("address,words", [
    ("tcp://127.0.0.1:1;touch X", "the port must be a number"),
    ("tcp://127.0.0.1", "the port must be a number"),
    ("tcp://127.0.0.1:99999", "the port must be a number"),
    ("http://127.0.0.1:8786", "expects tcp://HOST:PORT"),
    ("tcp://a b:1", "not a host name"),
])
def test_malformed_addresses_are_usage_errors(address, words, capsys):
    assert main(["study", SPEC, "--scheduler", address]) == 2
    assert words in capsys.readouterr().err


@pytest.mark.parametrize("argv,words", [
    (["--workers", "1000000"], "between 0 and 64"),
    (["--timeout", "nan"], "between 0.1 and 3600 s"),
    (["--design-timeout", "-1"], "between 0.1 and 86400 s"),
])
def test_study_counts_and_durations_are_bounded(argv, words, capsys):
    with no_hang(10):
        assert main(["study", SPEC, *argv]) == 2
    assert words in capsys.readouterr().err


# ---- workspace: what a typed number asks for is estimated before the work (issue 22 items 6, 10, 11)
from conftest import CORPUS, ROBOTS  # noqa: E402


@pytest.mark.parametrize("argv,words", [
    (["workspace", str(ROBOTS / "delta_parallelogram.urdf"), "--output", "platform", "--point", "--resolution", "1mm"],
     "would solve about"),
    (["workspace", str(ROBOTS / "five_bar.urdf"), "--output", "tip", "--point", "--resolution", "1um"],
     "use --resolution"),
    (["workspace", str(ROBOTS / "arm_6r.urdf"), "--output", "flange", "--point", "--method", "sampling",
      "--samples", "100000000"], "between 1 and 2,000,000"),
    (["workspace", str(ROBOTS / "quick_return_slot.urdf"), "--output", "slotted", "--point"],
     "batched solver does not take these yet"),
    (["workspace", str(ROBOTS / "five_bar.urdf"), "--output", "tip", "--resolution", "0"], "from 1e-09 m"),
    (["workspace", str(ROBOTS / "five_bar.urdf"), "--output", "tip", "--orientation", "30mm 0 0"],
     "unit of length"),
])
def test_workspace_refuses_what_it_cannot_do_before_the_work(argv, words, capsys):
    with no_hang(30):
        code = main(argv)
    err = capsys.readouterr().err
    errors = [line for line in err.strip().splitlines() if not line.startswith("note: ")]  # the mode chosen: said
    assert code == 2 and words in err and len(errors) == 1, err


@pytest.mark.slow
def test_workspace_honours_its_time_limit_and_says_the_result_is_cut(capsys):
    """wl16_like at 100 mm ran past 60 s: with --timeout 3 it stops and marks the result truncated."""
    import json

    path = CORPUS / "wl16_like" / "robot.urdf"
    with no_hang(60):
        code = main(["workspace", str(path), "--output", "foot_part", "--resolution", "100mm", "--timeout", "3",
                     "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["truncated"] is True
    assert any("time limit" in n for n in out["notes"])
