"""The real-time plant's packets: a versioned, little-endian fixed layout (struct).

Every packet starts with the same 24-byte header; its ``type`` says which body
follows and the packet's length is fixed by the type. ``docs/realtime.md`` ('The
packets') is the reference, and ``examples/realtime/flexsat_packets.h`` the same
layout for C (a test checks its sizes and offsets against the structs here).
"""

from __future__ import annotations

import struct
from typing import NamedTuple

import numpy as np

__all__ = [
    "COMMAND",
    "COMMAND_FORMAT",
    "END",
    "HEADER_FORMAT",
    "HELLO",
    "MAGIC",
    "SENSOR",
    "SENSOR_FORMAT",
    "SIZES",
    "VERSION",
    "Command",
    "Header",
    "PacketError",
    "Sensor",
    "decode",
    "encode_command",
    "encode_end",
    "encode_hello",
    "encode_sensor",
]

MAGIC = 0x54535846
"""``b"FXST"`` read as a little-endian uint32: the first four bytes of every packet."""
VERSION = 1
"""The layout's version; a packet of another version is dropped."""

HELLO, SENSOR, COMMAND, END = 1, 2, 3, 4
"""Packet types: client ready, plant sensor sample, client torque command, end of run."""

HEADER_FORMAT = "<IHHIIQ"
"""magic u32, version u16, type u16, sequence u32, size u32 (the whole packet [bytes]),
sim_time_ns u64 (simulated time of the sample [ns])."""
SENSOR_FORMAT = HEADER_FORMAT + "Q4d3d"
"""header, plant_stamp_ns u64 (plant's monotonic clock at sending [ns]), q[4] (scalar
first, frame B relative to N [-]), omega[3] (body rate, frame B [rad/s])."""
COMMAND_FORMAT = HEADER_FORMAT + "QQ3d"
"""header (sequence and sim time of the sensor packet answered), echo_stamp_ns u64
(that packet's plant_stamp_ns, returned), compute_ns u64 (client's time from receipt
to sending [ns]), torque[3] (commanded body torque, frame B [N m])."""

SIZES = {
    HELLO: struct.calcsize(HEADER_FORMAT),
    SENSOR: struct.calcsize(SENSOR_FORMAT),
    COMMAND: struct.calcsize(COMMAND_FORMAT),
    END: struct.calcsize(HEADER_FORMAT),
}
"""Length of each packet type [bytes]."""

_HEADER = struct.Struct(HEADER_FORMAT)
_SENSOR = struct.Struct(SENSOR_FORMAT)
_COMMAND = struct.Struct(COMMAND_FORMAT)


class PacketError(ValueError):
    """A datagram that is not a valid packet: wrong magic, version, type or length."""


class Header(NamedTuple):
    """A packet's header: its type, sequence number and simulated time.

    Attributes
    ----------
    type : int
        Packet type: :data:`HELLO`, :data:`SENSOR`, :data:`COMMAND` or :data:`END` [-].
    sequence : int
        Control instant index k (a command: the k it answers) [-].
    sim_time_ns : int
        Simulated time of the sample [ns].
    """

    type: int
    sequence: int
    sim_time_ns: int


class Sensor(NamedTuple):
    """A sensor packet: the sample ``sequence`` at ``sim_time_ns`` [ns].

    Attributes
    ----------
    sequence : int
        Control instant index k [-].
    sim_time_ns : int
        Simulated time of the sample [ns].
    plant_stamp_ns : int
        The plant's monotonic clock when it sent the packet [ns].
    q : ndarray, shape (4,)
        Measured attitude quaternion, scalar first, B relative to N [-].
    omega : ndarray, shape (3,)
        Measured body rate, frame B [rad/s].
    """

    sequence: int
    sim_time_ns: int
    plant_stamp_ns: int
    q: np.ndarray
    omega: np.ndarray


class Command(NamedTuple):
    """A command packet, the answer to the sensor packet ``sequence``.

    Attributes
    ----------
    sequence : int
        The answered sensor packet's sequence [-].
    sim_time_ns : int
        Its simulated time [ns].
    echo_stamp_ns : int
        Its ``plant_stamp_ns``, returned [ns].
    compute_ns : int
        The client's time from receipt to sending [ns].
    torque : ndarray, shape (3,)
        Commanded body torque, frame B [N m].
    """

    sequence: int
    sim_time_ns: int
    echo_stamp_ns: int
    compute_ns: int
    torque: np.ndarray


def _header(kind: int, sequence: int, sim_time_ns: int) -> tuple:
    return MAGIC, VERSION, kind, sequence & 0xFFFFFFFF, SIZES[kind], sim_time_ns


def encode_sensor(sequence: int, sim_time_ns: int, plant_stamp_ns: int, q: np.ndarray,
                  omega: np.ndarray) -> bytes:  # fmt: skip
    """A sensor packet's bytes (``SENSOR_FORMAT``).

    Parameters
    ----------
    sequence : int
        Control instant index [-].
    sim_time_ns : int
        Simulated time [ns].
    plant_stamp_ns : int
        The plant's monotonic clock now [ns].
    q : ndarray, shape (4,)
        Measured attitude quaternion, scalar first [-].
    omega : ndarray, shape (3,)
        Measured body rate, frame B [rad/s].

    Returns
    -------
    bytes
    """
    return _SENSOR.pack(*_header(SENSOR, sequence, sim_time_ns), plant_stamp_ns, *q, *omega)


def encode_command(sequence: int, sim_time_ns: int, echo_stamp_ns: int, compute_ns: int,
                   torque: np.ndarray) -> bytes:  # fmt: skip
    """A command packet's bytes (``COMMAND_FORMAT``).

    Parameters
    ----------
    sequence : int
        The answered sensor packet's sequence [-].
    sim_time_ns : int
        Its simulated time [ns].
    echo_stamp_ns : int
        Its ``plant_stamp_ns`` [ns].
    compute_ns : int
        Time from its receipt to now [ns].
    torque : ndarray, shape (3,)
        Commanded body torque, frame B [N m].

    Returns
    -------
    bytes
    """
    return _COMMAND.pack(*_header(COMMAND, sequence, sim_time_ns), echo_stamp_ns,
                         max(compute_ns, 0), *torque)  # fmt: skip


def encode_hello() -> bytes:
    """The client's HELLO packet (a header alone): it is ready, the plant may start."""
    return _HEADER.pack(*_header(HELLO, 0, 0))


def encode_end(sequence: int, sim_time_ns: int) -> bytes:
    """The plant's END packet (a header alone): the run is over.

    Parameters
    ----------
    sequence : int
        The last control instant index [-].
    sim_time_ns : int
        Simulated time the run ended at [ns].

    Returns
    -------
    bytes
    """
    return _HEADER.pack(*_header(END, sequence, sim_time_ns))


def decode(data: bytes) -> Header | Sensor | Command:
    """Parse one packet.

    Parameters
    ----------
    data : bytes
        One datagram or message.

    Returns
    -------
    Header, Sensor or Command
        A HELLO or END packet as its :class:`Header`.

    Raises
    ------
    PacketError
        Naming what is wrong: too short, magic, version, unknown type, or a length
        that is not the type's.
    """
    if len(data) < _HEADER.size:
        raise PacketError(f"{len(data)} bytes, shorter than the {_HEADER.size}-byte header")
    magic, version, kind, sequence, size, sim_time_ns = _HEADER.unpack_from(data)
    if magic != MAGIC:
        raise PacketError(f"magic 0x{magic:08x}, expected 0x{MAGIC:08x}")
    if version != VERSION:
        raise PacketError(f"version {version}, expected {VERSION}")
    if kind not in SIZES:
        raise PacketError(f"type {kind}, expected one of {sorted(SIZES)}")
    if len(data) != SIZES[kind] or size != SIZES[kind]:
        raise PacketError(
            f"type {kind} of {len(data)} bytes (header says {size}), expected {SIZES[kind]}"
        )
    if kind == SENSOR:
        values = _SENSOR.unpack(data)
        return Sensor(sequence, sim_time_ns, values[6], np.array(values[7:11]),
                      np.array(values[11:14]))  # fmt: skip
    if kind == COMMAND:
        values = _COMMAND.unpack(data)
        return Command(sequence, sim_time_ns, values[6], values[7], np.array(values[8:11]))
    return Header(kind, sequence, sim_time_ns)
