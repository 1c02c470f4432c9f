"""screwkin view's meshcat server goes away with the command: SIGTERM, SIGHUP and SIGINT to
``screwkin view`` (and even SIGKILL) leave no process of its group and nothing on its port."""

import os
import select
import signal
import socket
import subprocess
import sys

import pytest

from conftest import ROBOTS
from test_view import listening

FILE = str(ROBOTS / "fourbar_crank_rocker.urdf")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def answers(port) -> bool:
    with socket.socket() as s:
        s.settimeout(1.0)
        return s.connect_ex(("127.0.0.1", port)) == 0


def port_is_free(port) -> bool:
    """Another program could listen on the port now (SO_REUSEADDR: the probe's own closed
    connection, in TIME_WAIT, does not count)."""
    with socket.socket() as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind(("127.0.0.1", port))
            s.listen()
        except OSError:
            return False
    return True


def group_alive(pgid) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    return True


def start_view(port, *extra, ready="meshcat: "):
    """``python -m screwkin view FILE --port P`` in a process group of its own, once it says it
    serves and the port answers (at most 600 waits of a second for its line)."""
    proc = subprocess.Popen([sys.executable, "-m", "screwkin", "view", FILE, "--port", str(port), *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    for _ in range(600):
        if proc.poll() is not None:
            pytest.fail(f"screwkin view ended before serving: {proc.stderr.read()[-500:]}")
        readable, _, _ = select.select([proc.stdout], [], [], 1.0)
        if readable:
            line = proc.stdout.readline()
            if line.startswith(ready):
                assert f":{port}" in line
                assert answers(port)
                return proc
    os.killpg(proc.pid, signal.SIGKILL)
    pytest.fail(f"screwkin view did not say it serves on port {port}")


def wait_free(port, pgid, tries=200) -> None:
    """Wait (a bounded number of short waits) until the group is gone and the port free."""
    for _ in range(tries):
        if not group_alive(pgid) and port_is_free(port):
            return
        select.select([], [], [], 0.05)


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT])
def test_a_signal_stops_the_server_and_frees_the_port(sig):
    port = free_port()
    proc = start_view(port)
    assert listening(port) == ["0100007F"]  # the web server: loopback only
    pgid = proc.pid  # its own group (start_new_session): the command and the server it started
    proc.send_signal(sig)  # to the command only, as `kill PID` does
    try:
        out, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(pgid, signal.SIGKILL)
        pytest.fail(f"screwkin view did not end after {sig.name}")
    assert proc.returncode == 0, err
    assert f"stopped by {sig.name}" in out and f"port {port} is closed" in out
    assert "Traceback" not in err
    assert not group_alive(pgid), "a process of screwkin view's group is left"
    assert listening(port) == []
    assert port_is_free(port)


@pytest.mark.slow
def test_the_server_ends_when_the_command_is_killed():
    """SIGKILL cannot be handled: the server sees its standard input close and ends by itself."""
    port = free_port()
    proc = start_view(port)
    pgid = proc.pid
    proc.kill()
    proc.communicate(timeout=60)
    wait_free(port, pgid)
    assert not group_alive(pgid), "the meshcat server outlived the killed command"
    assert port_is_free(port)


@pytest.mark.slow
def test_sigterm_stops_the_interactive_view_too():
    pytest.importorskip("viser")
    port = free_port()
    proc = start_view(port, "--interactive", ready="interactive view: ")
    assert listening(port) == ["0100007F"]
    proc.send_signal(signal.SIGTERM)
    try:
        out, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail("screwkin view --interactive did not end after SIGTERM")
    assert proc.returncode == 0, err
    assert f"stopped by SIGTERM: the server on port {port} is closed" in out
    assert not group_alive(proc.pid)
    assert listening(port) == [] and port_is_free(port)


def test_interactive_without_viser_says_how_to_install_it(capsys, monkeypatch):
    from screwkin.cli import main

    monkeypatch.setitem(sys.modules, "viser", None)
    assert main(["view", FILE, "--interactive"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pip install viser" in err[0]


def test_a_port_in_use_is_a_usage_error():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        p = subprocess.run([sys.executable, "-m", "screwkin", "view", FILE, "--port", str(port)],
                           capture_output=True, text=True, timeout=120)
    assert p.returncode == 2
    errors = [line for line in p.stderr.strip().splitlines() if not line.startswith("note: ")]  # notes: what it chose
    assert f"port {port} cannot be used" in p.stderr and len(errors) == 1
    assert "Traceback" not in p.stderr


@pytest.mark.parametrize("text", ["80", "70000", "abc"])
def test_a_bad_port_number_is_a_usage_error(text, capsys):
    from screwkin.cli import main

    assert main(["view", FILE, "--port", text]) == 2
    assert "--port" in capsys.readouterr().err


class _SignalAfterLine:
    """sys.stdout that sends ``sig`` to this process as soon as the serving line (``ready``) has been
    written: the signal arrives between saying where the page is and waiting, every time (issue 43 item 1:
    under load it exited 130 without its "stopped by" line)."""

    def __init__(self, sig, ready):
        self.sig, self.ready, self.text = sig, ready, ""

    def write(self, text):
        self.text += text
        if text.startswith(self.ready):
            os.kill(os.getpid(), self.sig)
        return len(text)

    def flush(self):
        pass


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT])
def test_a_signal_right_after_the_serving_line_stops_cleanly(sig, monkeypatch):
    from screwkin.cli import main

    previous = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT)}
    port = free_port()
    out = _SignalAfterLine(sig, "meshcat: ")
    monkeypatch.setattr(sys, "stdout", out)
    assert main(["view", FILE, "--port", str(port)]) == 0
    assert f"stopped by {sig.name}: the meshcat server on port {port} is closed" in out.text
    assert port_is_free(port)
    assert {s: signal.getsignal(s) for s in previous} == previous  # the handlers given back
    assert signal.set_wakeup_fd(-1) == -1  # and no wakeup descriptor left behind


def test_a_signal_right_after_the_interactive_line_stops_cleanly(monkeypatch):
    pytest.importorskip("viser")
    from screwkin.cli import main

    port = free_port()
    out = _SignalAfterLine(signal.SIGTERM, "interactive view: ")
    monkeypatch.setattr(sys, "stdout", out)
    assert main(["view", FILE, "--interactive", "--port", str(port)]) == 0
    assert f"stopped by SIGTERM: the server on port {port} is closed" in out.text
    assert port_is_free(port)


@pytest.mark.slow
def test_signals_right_after_the_line_under_load_stop_cleanly():
    """The README's test command on a loaded machine: `screwkin view` in a session of its own, signalled the
    moment its line is read, six times (each signal twice) beside a process that keeps a CPU busy."""
    hog = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        for sig in [signal.SIGTERM, signal.SIGHUP, signal.SIGINT] * 2:
            port = free_port()
            proc = subprocess.Popen([sys.executable, "-m", "screwkin", "view", FILE, "--port", str(port)],
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                    start_new_session=True)
            out = ""
            for line in proc.stdout:  # (bounded: the command ends, or is killed below after 120 s)
                out += line
                if line.startswith("meshcat: "):
                    proc.send_signal(sig)
                    break
            try:
                rest, err = proc.communicate(timeout=120)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                pytest.fail(f"screwkin view did not end after {sig.name}")
            assert proc.returncode == 0, (sig.name, out + rest, err)
            assert f"stopped by {sig.name}: the meshcat server on port {port} is closed" in out + rest
            assert "Traceback" not in err
            wait_free(port, proc.pid)
            assert not group_alive(proc.pid)
    finally:
        hog.kill()
        hog.wait()
