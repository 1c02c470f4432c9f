"""A Dask scheduler's address, and a check that a Dask scheduler answers there before the Dask client
reads from it (a hostile peer decided how much memory the client reserved: 8 bytes of 0xff are 16 EiB)."""

from __future__ import annotations

import re
import socket
import struct

from ..errors import UsageError, quote

__all__ = ["MAX_HANDSHAKE", "scheduler_address", "probe_scheduler"]


#: Most bytes the first message of a Dask scheduler (its handshake, a few hundred bytes) may announce
#: before screwkin lets the Dask client read it: a peer that is no scheduler decides the size otherwise
#: (8 bytes of 0xff announce 16 EiB, and the client tried to allocate them).
MAX_HANDSHAKE = 1 << 20


def _host_port(address: str) -> tuple:
    """(host, port) of tcp://HOST:PORT or tls://HOST:PORT ([IPv6]:PORT too), or a UsageError."""
    scheme, sep, rest = address.partition("://") if isinstance(address, str) else ("", "", "")
    if not sep or scheme not in ("tcp", "tls"):
        raise UsageError(f"--scheduler expects tcp://HOST:PORT (or tls://), got {quote(address)}")
    if rest.startswith("["):
        host, _, port = rest[1:].partition("]")
        port = port[1:] if port.startswith(":") else ""
    else:
        host, _, port = rest.rpartition(":") if ":" in rest else (rest, "", "")
    if not host or not re.fullmatch(r"[A-Za-z0-9.\-:]+", host):
        raise UsageError(f"--scheduler {quote(address)}: {quote(host)} is not a host name or address")
    if not port.isdigit() or not 0 < int(port) < 65536:
        raise UsageError(f"--scheduler {quote(address)}: the port must be a number from 1 to 65535, "
                         f"got {quote(port)}")
    return host, int(port)


def scheduler_address(address: str) -> str:
    """The address, checked (tcp:// or tls://, a host, a port number)."""
    _host_port(address)
    return address


def probe_scheduler(address: str, timeout: float) -> None:
    """Check that a Dask scheduler answers at a tcp:// address before the Dask client reads from it:
    a scheduler sends its handshake first, 8 bytes announcing the length of a small message whose
    prelude announces its frames; anything else (no answer, a banner, an absurd length) is "not a Dask
    scheduler", a UsageError in at most ``timeout`` seconds."""
    host, port = _host_port(address)
    if not address.startswith("tcp://"):
        return  # tls: the handshake is encrypted; the client's own checks apply
    where = quote(address)
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            head = _recv_exactly(sock, 8)
            (n,) = struct.unpack("Q", head)
            if not 0 < n <= MAX_HANDSHAKE:
                raise UsageError(f"not a Dask scheduler at {where}: its first message announces {n} bytes")
            body = _recv_exactly(sock, n)
    except TimeoutError:
        raise UsageError(f"not a Dask scheduler at {where}: no handshake within {timeout:g} s") from None
    except ConnectionError as exc:
        raise UsageError(f"the dask scheduler at {where} cannot be reached ({exc.strerror or exc})") from None
    except OSError as exc:
        raise UsageError(f"the dask scheduler at {where} cannot be reached ({exc.strerror or exc})") from None
    # the prelude: the number of frames, then each frame's length (distributed.protocol.utils.pack_frames)
    if len(body) < 8:
        raise UsageError(f"not a Dask scheduler at {where}: a handshake of {len(body)} bytes")
    (count,) = struct.unpack("Q", body[:8])
    if not 0 < count <= 64 or len(body) < 8 * (count + 1):
        raise UsageError(f"not a Dask scheduler at {where}: its handshake announces {count} frames")
    lengths = struct.unpack(f"{count}Q", body[8:8 * (count + 1)])
    if sum(lengths) > MAX_HANDSHAKE:
        raise UsageError(f"not a Dask scheduler at {where}: its handshake announces {sum(lengths)} bytes of frames")


def _recv_exactly(sock, n: int) -> bytes:
    out = bytearray()
    while len(out) < n:
        chunk = sock.recv(min(n - len(out), 65536))
        if not chunk:
            raise ConnectionError("the peer closed the connection")
        out += chunk
    return bytes(out)
