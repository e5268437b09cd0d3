"""The real-time plant's links: UDP datagrams (stdlib socket) or ZeroMQ messages.

An endpoint is a URL: ``udp://HOST:PORT`` (the default transport, no dependency),
``tcp://HOST:PORT`` or ``ipc://PATH`` (ZeroMQ, the optional extra ``realtime``).
Two endpoints make a link: the sensor endpoint (the plant sends there, the client
listens) and the command endpoint (the plant listens, the client sends there).
Over ZeroMQ the plant binds both (PUSH for sensors, PULL for commands) and the
client connects; over UDP each side binds the endpoint it listens on.
"""

from __future__ import annotations

import errno
import select
import socket
from typing import Protocol
from urllib.parse import urlsplit

from flexsat.errors import ConfigError

__all__ = [
    "DEFAULT_COMMAND_ENDPOINT",
    "DEFAULT_SENSOR_ENDPOINT",
    "Link",
    "check_seconds",
    "client_link",
    "parse_endpoint",
    "plant_link",
]

DEFAULT_SENSOR_ENDPOINT = "udp://127.0.0.1:47101"
"""Where the plant sends its sensor packets by default."""
DEFAULT_COMMAND_ENDPOINT = "udp://127.0.0.1:47102"
"""Where the plant listens for commands by default."""
_MAX_DATAGRAM = 2048  # [bytes] longer than any packet: a longer datagram is cut, then refused


class Link(Protocol):
    """One side of a link: send a packet, receive the ones that arrived."""

    def send(self, data: bytes) -> None:
        """Send one packet (never blocks: a packet that cannot go is dropped)."""

    def receive(self, timeout_s: float) -> bytes | None:
        """The next packet, waiting at most ``timeout_s`` [s] (0: do not wait), or None."""

    def close(self) -> None:
        """Release the sockets."""


def check_seconds(option: str, value: float, limit_s: float = 3600.0) -> float:
    """``value`` [s] if it is in (0, ``limit_s``], else a :class:`ConfigError` naming ``option``.

    Parameters
    ----------
    option : str
        The option, for the message.
    value : float
        A duration [s].
    limit_s : float
        Largest allowed [s].

    Returns
    -------
    float
        ``value`` [s].
    """
    if not 0.0 < value <= limit_s:
        raise ConfigError(f"{option}: must be in (0, {limit_s:g}] s, got {value:g}")
    return value


def parse_endpoint(text: str, option: str) -> tuple[str, str, int | None]:
    """(scheme, host or path, port) of an endpoint URL.

    Parameters
    ----------
    text : str
        ``udp://HOST:PORT``, ``tcp://HOST:PORT`` or ``ipc://PATH``.
    option : str
        The option it came from, for the message.

    Returns
    -------
    tuple
        Scheme, host (or the ipc path) and port (None for ipc).

    Raises
    ------
    ConfigError
        Naming ``option``: an unknown scheme, no host or a port outside 1-65535.
    """
    parts = urlsplit(text)
    if parts.scheme == "ipc" and (parts.netloc or parts.path):
        return "ipc", parts.netloc + parts.path, None
    if parts.scheme not in ("udp", "tcp"):
        raise ConfigError(f"{option}: expected udp://HOST:PORT, tcp://HOST:PORT (ZeroMQ) or "
                          f"ipc://PATH (ZeroMQ), got {text!r}")  # fmt: skip
    try:
        port = parts.port
    except ValueError:
        port = None
    if not parts.hostname or port is None or not 1 <= port <= 65535:
        raise ConfigError(f"{option}: expected a host and a port in 1-65535, got {text!r}")
    return parts.scheme, parts.hostname, port


def _zmq():
    try:
        import zmq
    except ImportError:
        raise ConfigError("tcp:// and ipc:// endpoints need ZeroMQ: pip install "
                          "'flexsat[realtime]' (or use udp://HOST:PORT)") from None  # fmt: skip
    return zmq


class _UdpLink:
    def __init__(self, listen: tuple[str, int, str], send_to: tuple[str, int]) -> None:
        host, port, option = listen
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self._socket.bind((host, port))
        except OSError as error:
            self._socket.close()
            why = "is in use" if error.errno == errno.EADDRINUSE else f"cannot be bound ({error})"
            raise ConfigError(f"{option}: udp://{host}:{port} {why}; give another port") from None
        self._socket.setblocking(False)
        self._to = send_to

    def send(self, data: bytes) -> None:
        try:
            self._socket.sendto(data, self._to)
        except (BlockingIOError, ConnectionRefusedError):
            pass  # nobody listens (yet): a datagram is lost, as on a wire

    def receive(self, timeout_s: float) -> bytes | None:
        while True:
            try:
                return self._socket.recv(_MAX_DATAGRAM)
            except BlockingIOError:
                if timeout_s <= 0.0 or not select.select([self._socket], [], [], timeout_s)[0]:
                    return None
                timeout_s = 0.0
            except ConnectionRefusedError:  # a previous send found no listener
                continue

    def close(self) -> None:
        self._socket.close()


class _ZmqLink:
    def __init__(self, push: str, pull: str, bind: bool, options: tuple[str, str]) -> None:
        zmq = _zmq()
        self._zmq = zmq
        self._context = zmq.Context.instance()
        self._push = self._context.socket(zmq.PUSH)
        self._pull = self._context.socket(zmq.PULL)
        for sock in (self._push, self._pull):
            sock.setsockopt(zmq.LINGER, 0)
        self._push.setsockopt(zmq.SNDHWM, 16)
        for sock, address, option in ((self._push, push, options[0]),
                                      (self._pull, pull, options[1])):  # fmt: skip
            try:
                sock.bind(address) if bind else sock.connect(address)
            except zmq.ZMQError as error:
                self.close()
                raise ConfigError(f"{option}: {address} {error}; give another endpoint") from None
        self._poller = zmq.Poller()
        self._poller.register(self._pull, zmq.POLLIN)

    def send(self, data: bytes) -> None:
        try:
            self._push.send(data, self._zmq.NOBLOCK)
        except self._zmq.Again:
            pass  # no peer, or its queue is full: dropped

    def receive(self, timeout_s: float) -> bytes | None:
        if self._poller.poll(max(timeout_s, 0.0) * 1e3):
            return self._pull.recv(self._zmq.NOBLOCK)
        return None

    def close(self) -> None:
        self._push.close(0)
        self._pull.close(0)


def _link(sensor: str, command: str, plant: bool) -> Link:
    options = ("--sensor-endpoint", "--command-endpoint")
    s_scheme, s_host, s_port = parse_endpoint(sensor, options[0])
    c_scheme, c_host, c_port = parse_endpoint(command, options[1])
    if (s_scheme == "udp") != (c_scheme == "udp"):
        raise ConfigError(f"{options[0]} and {options[1]}: both udp://, or both ZeroMQ "
                          f"(tcp://, ipc://), got {sensor!r} and {command!r}")  # fmt: skip
    if s_scheme == "udp":
        if plant:
            return _UdpLink((c_host, c_port, options[1]), (s_host, s_port))
        return _UdpLink((s_host, s_port, options[0]), (c_host, c_port))
    if plant:
        return _ZmqLink(sensor, command, bind=True, options=options)
    return _ZmqLink(command, sensor, bind=False, options=options[::-1])


def plant_link(sensor_endpoint: str, command_endpoint: str) -> Link:
    """The plant's side: sends to ``sensor_endpoint``, listens on ``command_endpoint``.

    Parameters
    ----------
    sensor_endpoint, command_endpoint : str
        Endpoint URLs (:func:`parse_endpoint`).

    Returns
    -------
    Link

    Raises
    ------
    ConfigError
        A bad endpoint, a port in use, or ZeroMQ missing.
    """
    return _link(sensor_endpoint, command_endpoint, plant=True)


def client_link(sensor_endpoint: str, command_endpoint: str) -> Link:
    """The client's side: listens on ``sensor_endpoint``, sends to ``command_endpoint``.

    Parameters
    ----------
    sensor_endpoint, command_endpoint : str
        Endpoint URLs (:func:`parse_endpoint`), the plant's.

    Returns
    -------
    Link

    Raises
    ------
    ConfigError
        A bad endpoint, a port in use, or ZeroMQ missing.
    """
    return _link(sensor_endpoint, command_endpoint, plant=False)
