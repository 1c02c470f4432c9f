"""A meshcat server bound to the loopback interface only, that goes away with its parent.

meshcat's own server listens on every interface (it passes no address to
tornado); this one binds its web server and its ZMQ socket to 127.0.0.1.
Run as ``python -m screwkin.present.viewserver [--port P]``: it prints
``zmq_url=...`` and ``web_url=...`` and serves until terminated, or until its
standard input closes: :class:`ViewerServer` holds the other end of that pipe, so
the server ends with the process that started it however that process ends
(SIGTERM, SIGKILL, a closed notebook kernel).  With ``--port`` the web server takes
exactly that port (a port in use is an error); without, the first free one from 7000.
"""

from __future__ import annotations

import contextlib
import io
import os
import signal
import subprocess
import sys
import tempfile
import threading

from ..errors import UsageError
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any

__all__ = ["ViewerServer", "main"]


def _bridge_class():
    from meshcat.servers.zmqserver import ZMQWebSocketBridge

    class LoopbackBridge(ZMQWebSocketBridge):
        def make_app(self):
            app = super().make_app()
            listen = app.listen

            def loopback_listen(port, **kwargs: Any):
                kwargs["address"] = "127.0.0.1"
                return listen(port, **kwargs)

            app.listen = loopback_listen
            return app

    return LoopbackBridge


def _exit_when_stdin_closes() -> None:
    """End this process (at once, sockets closed by the kernel) when the parent's end of stdin closes."""
    try:
        while sys.stdin.buffer.read(4096):
            pass
    except (OSError, ValueError):  # pragma: no cover
        pass
    os._exit(0)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    port = int(argv[argv.index("--port") + 1]) if "--port" in argv else None
    # the parent stops this server: Ctrl-C in a terminal reaches the whole process group, and the
    # parent's own handler ends it; SIGTERM and SIGHUP keep their default (the process ends)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_exit_when_stdin_closes, daemon=True).start()
    try:
        bridge = _bridge_class()(host="127.0.0.1", port=port)
    except OSError as exc:
        print(f"error=port {port} cannot be used on 127.0.0.1: {exc.strerror or exc}", flush=True)
        return 1
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)
    bridge.run()
    return 0


class ViewerServer:
    """A meshcat server on 127.0.0.1 in a subprocess (this module run as a script), in the caller's
    process group; ``port``: the web server's port (default: the first free one from 7000).
    The server ends when :meth:`close` is called, or when this process ends in any way."""

    def __init__(self, port: int | None = None) -> None:
        cmd = [sys.executable, "-u", "-m", "screwkin.present.viewserver"]
        if port is not None:
            cmd += ["--port", str(int(port))]
        self._stderr = tempfile.TemporaryFile()  # a file, not a pipe: the server's log can never block it
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._stderr,
                                     env=dict(os.environ), text=True)
        info = {}
        while len(info) < 2:
            line = self.proc.stdout.readline()
            key, _, value = line.strip().partition("=")
            if not line or key == "error":
                self._stderr.seek(0)
                why = value or self._stderr.read().decode(errors="replace").strip()[-300:] or "it ended"
                self.close()
                raise UsageError(f"the meshcat server did not start: {why}")
            info[key] = value
        self.zmq_url, self.web_url = info["zmq_url"], info["web_url"]
        self.port = int(self.web_url.split(":")[2].split("/")[0])

        import meshcat

        with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints its URL; the CLI says it itself
            self.viewer = meshcat.Visualizer(zmq_url=self.zmq_url)

    def close(self) -> None:
        """Stop the server and wait for it (killed if it has not ended after 5 s)."""
        if self.proc.poll() is None:
            self.proc.terminate()
        try:
            self.proc.wait(timeout=5)
        except subprocess.TimeoutExpired:  # pragma: no cover
            self.proc.kill()
            self.proc.wait(timeout=5)
        for stream in (self.proc.stdin, self.proc.stdout, self._stderr):
            with contextlib.suppress(OSError):
                stream.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
