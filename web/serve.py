"""Serving a page until Ctrl-C: address checks, the printed URL, a clean stop.

Shared by ``rsg demo`` and ``rsg replay``: the host must resolve and the port be
free (a clear message and exit code 2 otherwise); a host that is not loopback gets
a warning that anyone who reaches the port can use the page; the URL printed is
the address the server was bound to; Ctrl-C or SIGTERM stop the page and release
the port.
"""

from __future__ import annotations

import contextlib
import io
import ipaddress
import signal
import socket
import sys
import threading
from collections.abc import Callable
from types import FrameType

GIL_SWITCH_INTERVAL = 0.001  # [s]


def resolve_host(host: str, port: int) -> list[str] | str:
    """The addresses ``host`` stands for, or the reason it is not a usable host."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError, ValueError) as exc:
        return f"not an IP address or a host name this machine resolves ({exc})"
    return sorted({str(info[4][0]) for info in infos})


def is_loopback(addresses: list[str]) -> bool:
    """All ``addresses`` are loopback (only this machine can connect)."""
    try:
        return all(ipaddress.ip_address(a.split("%")[0]).is_loopback for a in addresses)
    except ValueError:
        return False


def port_is_free(host: str, port: int) -> bool:
    """Whether a server could listen on ``host``:``port`` now."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((host, port))
        except OSError:
            return False
    return True


def url_of(host: str, port: int) -> str:
    """``http://host:port`` (IPv6 addresses in brackets)."""
    shown = f"[{host}]" if ":" in host else host
    return f"http://{shown}:{port}"


def check_address(command: str, host: str, port: int) -> int | None:
    """Check ``host`` and ``port`` before serving; print what is wrong.

    Returns:
        None when the server can start, else the exit code (2).
    """
    addresses = resolve_host(host, port)
    if isinstance(addresses, str):
        print(f"rsg {command}: error: --host {host!r}: {addresses}", file=sys.stderr)
        return 2
    if not port_is_free(host, port):
        print(
            f"rsg {command}: error: port {port} on {host} is in use "
            "(another demo?); choose another one with --port",
            file=sys.stderr,
        )
        return 2
    if not is_loopback(addresses):
        print(
            f"rsg {command}: warning: serving on {host} (not loopback): anyone who can reach "
            f"port {port} of this machine can open the page"
            + (" and push the robot" if command == "demo" else ""),
            flush=True,
        )
    return None


def _interrupt(signum: int, frame: FrameType | None) -> None:
    raise KeyboardInterrupt


def serve(
    command: str,
    host: str,
    port: int,
    start: Callable[..., Callable[[], None]],
    label: str,
    checked: bool = False,
) -> int:
    """Serve a page on ``host``:``port`` until Ctrl-C or SIGTERM.

    Args:
        command: ``demo`` or ``replay`` (for the messages).
        host, port: Where to serve (checked first, :func:`check_address`).
        start: Builds the page on the server and starts it; returns its stop function.
        label: The page's title.
        checked: :func:`check_address` already passed (it is not repeated).

    Returns:
        0 after Ctrl-C, 2 when the host or the port cannot be used.
    """
    refused = None if checked else check_address(command, host, port)
    if refused is not None:
        return refused
    import viser

    # The simulation and the page threads hold the GIL in long calls: hand it over
    # more often so the page keeps its frame rate (measured: +10-20 % page updates).
    sys.setswitchinterval(GIL_SWITCH_INTERVAL)
    with contextlib.redirect_stdout(io.StringIO()):  # viser's own box prints "localhost"
        server = viser.ViserServer(host=host, port=port, label=label, verbose=False)
    stop_page: Callable[[], None] | None = None
    if threading.current_thread() is threading.main_thread():
        # SIGINT explicitly too: a process started as a background job of a
        # non-interactive shell inherits SIGINT ignored, and Python then raises no
        # KeyboardInterrupt (measured: CI started that way killed the demos after 30 s).
        signal.signal(signal.SIGINT, _interrupt)
        signal.signal(signal.SIGTERM, _interrupt)
    try:
        if server.get_port() != port:
            print(
                f"rsg {command}: error: port {port} on {host} was taken while starting; "
                "choose another one with --port",
                file=sys.stderr,
            )
            return 2
        stop_page = start(server)
        bound = url_of(server.get_host(), server.get_port())
        local = (
            f" (all interfaces; on this machine {url_of('127.0.0.1', port)})"
            if host in ("0.0.0.0", "::")
            else ""
        )
        print(f"rsg {command}: open {bound}{local} (Ctrl-C to stop)", flush=True)
        forever = threading.Event()
        while not forever.wait(0.5):
            pass
    except KeyboardInterrupt:
        print(f"rsg {command}: stopping ...", flush=True)
    finally:
        if stop_page is not None:
            stop_page()
        with contextlib.redirect_stdout(io.StringIO()):
            server.stop()
    print(f"rsg {command}: stopped", flush=True)
    return 0
