"""Before a Dask client is made for ``--scheduler ADDRESS``: is a Dask scheduler answering there?

A Dask scheduler speaks first on a new TCP connection (distributed's handshake): an 8-byte
little-endian count, then the frames.  A port that accepts and never answers would hang the client
(issue 35: 809 s with no output), and another service's greeting read as that count asked for
3.07 EiB.  The probe connects and waits for the first 8 bytes, each with a timeout
(``CRANEFMU_SCHEDULER_TIMEOUT`` seconds, default 10), and refuses in one line what is not a plausible
answer.  Addresses of other transports (``tls://``, ``ucx://``, ``inproc://``) are left to Dask.
"""
from __future__ import annotations

import os
import socket
import struct

from ..errors import SettingsError

DEFAULT_TIMEOUT = 10.0     # [s] to connect, and again for the first answer
MAX_FIRST_COUNT = 1 << 20  # a handshake's frame count is small; a greeting's text read as one is not


def timeout() -> float:
    """The probe's and the client's timeout [s] (``CRANEFMU_SCHEDULER_TIMEOUT``, default 10)."""
    text = os.environ.get("CRANEFMU_SCHEDULER_TIMEOUT", "")
    try:
        value = float(text) if text else DEFAULT_TIMEOUT
    except ValueError:
        value = -1.0
    if not value > 0 or value == float("inf"):
        raise SettingsError(f"CRANEFMU_SCHEDULER_TIMEOUT = {text!r} is not allowed: a number of seconds > 0")
    return value


def host_port(address: str) -> tuple[str, int] | None:
    """(host, port) of a TCP address (``tcp://host:port`` or ``host:port``), else None."""
    text = address[len("tcp://"):] if address.startswith("tcp://") else address
    if "://" in text:
        return None
    host, sep, port = text.rpartition(":")
    if not sep or not port.isdigit():
        raise SettingsError(f"--scheduler {address!r} is not allowed: give tcp://HOST:PORT (e.g. tcp://10.0.0.5:8786)")
    return host.strip("[]") or "127.0.0.1", int(port)


def probe(address: str, seconds: float | None = None) -> None:
    """Raise :class:`SettingsError` (one line) unless something at ``address`` answers like a Dask
    scheduler within ``seconds`` (default :func:`timeout`) to connect and again to answer."""
    where = host_port(address)
    if where is None:
        return
    seconds = timeout() if seconds is None else seconds
    try:
        sock = socket.create_connection(where, timeout=seconds)
    except OSError as err:
        why = "no answer" if isinstance(err, TimeoutError) else (err.strerror or str(err))
        raise SettingsError(f"--scheduler {address!r}: cannot reach a Dask scheduler there ({why} within "
                            f"{seconds:g} s)") from None
    with sock:
        first = b""
        try:
            while len(first) < 8:
                got = sock.recv(8 - len(first))
                if not got:
                    break
                first += got
        except TimeoutError:
            raise SettingsError(f"--scheduler {address!r}: the port accepts but nothing answered within {seconds:g} s "
                                "(not a Dask scheduler, or a hung one)") from None
        except OSError as err:
            raise SettingsError(f"--scheduler {address!r}: the connection failed ({err.strerror or err})") from None
    if len(first) < 8:
        raise SettingsError(f"--scheduler {address!r}: the port closed the connection without a Dask handshake")
    (count,) = struct.unpack("<Q", first)
    if count > MAX_FIRST_COUNT:
        raise SettingsError(f"--scheduler {address!r}: another service answers there ({first!r} is not a Dask "
                            "handshake)")
