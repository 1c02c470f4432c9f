"""A meshcat server bound to the loopback interface only.

meshcat's own server listens on every interface (it passes no address to
tornado); this one binds its web server and its ZMQ socket to 127.0.0.1.
Run as ``python -m screwkin.present.viewserver``: it prints ``zmq_url=...`` and
``web_url=...`` and serves until terminated.
"""

from __future__ import annotations

import sys

__all__ = ["main"]


def _bridge_class():
    from meshcat.servers.zmqserver import ZMQWebSocketBridge

    class LoopbackBridge(ZMQWebSocketBridge):
        def make_app(self):
            app = super().make_app()
            listen = app.listen

            def loopback_listen(port, **kwargs):
                kwargs["address"] = "127.0.0.1"
                return listen(port, **kwargs)

            app.listen = loopback_listen
            return app

    return LoopbackBridge


def main():
    bridge = _bridge_class()(host="127.0.0.1")
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)
    try:
        bridge.run()
    except KeyboardInterrupt:  # pragma: no cover
        pass
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
