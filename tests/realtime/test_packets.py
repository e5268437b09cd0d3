"""The real-time packets: round trips, every refusal, and the C header's layout.

The C header (examples/realtime/flexsat_packets.h) is parsed, not compiled: each
struct's fields, their C types and array lengths give sizes and offsets
(``#pragma pack(1)``), which must equal the Python struct formats' field by field.
"""

from __future__ import annotations

import re
import struct
from pathlib import Path

import numpy as np
import pytest

from flexsat.realtime import packets

HEADER_FILE = Path(__file__).resolve().parents[2] / "examples" / "realtime" / "flexsat_packets.h"
C_SIZES = {"uint16_t": 2, "uint32_t": 4, "uint64_t": 8, "double": 8}
STRUCT_CODES = {"H": "uint16_t", "I": "uint32_t", "Q": "uint64_t", "d": "double"}


def c_structs(text: str) -> dict[str, list[tuple[str, str, int]]]:
    """Each typedef'd struct's fields as (C type, name, count), nested structs expanded."""
    structs: dict[str, list[tuple[str, str, int]]] = {}
    for body, name in re.findall(r"typedef struct \{(.*?)\}\s*(\w+);", text, re.S):
        fields = []
        for ctype, field, count in re.findall(r"^\s*(\w+)\s+(\w+)(?:\[(\d+)\])?;", body, re.M):
            if ctype in structs:  # the header, inlined
                fields += [(t, f"{field}.{f}", n) for t, f, n in structs[ctype]]
            else:
                fields.append((ctype, field, int(count or 1)))
        structs[name] = fields
    return structs


def python_fields(fmt: str) -> list[tuple[str, int]]:
    """(C type, count) of each field of a little-endian struct format, in order."""
    return [(STRUCT_CODES[code], int(n or 1)) for n, code in re.findall(r"(\d*)([HIQd])", fmt)]


def offsets(fields) -> list[int]:
    """Packed offsets [bytes] of consecutive (C type, count) fields."""
    out, at = [], 0
    for ctype, count in fields:
        out.append(at)
        at += C_SIZES[ctype] * count
    return [*out, at]


@pytest.mark.parametrize(
    ("name", "fmt"),
    [("flexsat_header", packets.HEADER_FORMAT),
     ("flexsat_sensor_packet", packets.SENSOR_FORMAT),
     ("flexsat_command_packet", packets.COMMAND_FORMAT)],
)  # fmt: skip
def test_the_c_header_has_the_python_layout(name, fmt):
    c = c_structs(HEADER_FILE.read_text())[name]
    c_fields = [(ctype, count) for ctype, _, count in c]
    assert fmt.startswith("<")  # little-endian, no padding: the C header's pack(1)
    assert c_fields == python_fields(fmt)
    assert offsets(c_fields) == offsets(python_fields(fmt))
    assert offsets(c_fields)[-1] == struct.calcsize(fmt)


def test_the_c_header_has_the_python_constants():
    text = HEADER_FILE.read_text()
    pattern = r"#define FLEXSAT_(\w+) (0x[0-9A-F]+|\d+)u"
    defined = {k: int(v, 0) for k, v in re.findall(pattern, text)}
    assert defined["MAGIC"] == packets.MAGIC
    assert defined["VERSION"] == packets.VERSION
    for kind in ("HELLO", "SENSOR", "COMMAND", "END"):
        assert defined[kind] == getattr(packets, kind)
    assert packets.MAGIC.to_bytes(4, "little") == b"FXST"


def test_sensor_and_command_round_trip_bit_for_bit():
    seed = 20261207
    print("seed", seed)
    rng = np.random.default_rng(seed)
    q, omega, torque = rng.normal(size=4), rng.normal(size=3), rng.normal(size=3)
    sensor = packets.decode(packets.encode_sensor(7, 70_000_000, 123, q, omega))
    assert isinstance(sensor, packets.Sensor)
    assert (sensor.sequence, sensor.sim_time_ns, sensor.plant_stamp_ns) == (7, 70_000_000, 123)
    # float64 carried as IEEE bits: exactly equal, the SIL loop's premise
    assert np.array_equal(sensor.q, q) and np.array_equal(sensor.omega, omega)
    command = packets.decode(packets.encode_command(7, 70_000_000, 123, 456, torque))
    assert isinstance(command, packets.Command)
    assert (command.sequence, command.echo_stamp_ns, command.compute_ns) == (7, 123, 456)
    assert np.array_equal(command.torque, torque)
    assert packets.decode(packets.encode_hello()).type == packets.HELLO
    end = packets.decode(packets.encode_end(9, 5))
    assert (end.type, end.sequence, end.sim_time_ns) == (packets.END, 9, 5)
    kinds = (packets.HELLO, packets.SENSOR, packets.COMMAND)
    assert [packets.SIZES[k] for k in kinds] == [24, 88, 64]


def _patched(data: bytes, offset: int, fmt: str, value: int) -> bytes:
    out = bytearray(data)
    struct.pack_into(fmt, out, offset, value)
    return bytes(out)


GOOD = packets.encode_command(1, 0, 0, 0, np.zeros(3))


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"FXST", "shorter than the 24-byte header"),
        (_patched(GOOD, 0, "<I", 0xDEADBEEF), "magic 0xdeadbeef"),
        (_patched(GOOD, 4, "<H", 2), "version 2, expected 1"),
        (_patched(GOOD, 6, "<H", 9), "type 9"),
        (GOOD[:-1], "type 3 of 63 bytes"),
        (GOOD + b"\0", "type 3 of 65 bytes"),
        (_patched(GOOD, 12, "<I", 88), "header says 88"),
    ],
    ids=["short", "magic", "version", "type", "truncated", "extended", "size-field"],
)
def test_a_malformed_packet_is_refused_saying_why(data, message):
    with pytest.raises(packets.PacketError, match=re.escape(message)):
        packets.decode(data)
