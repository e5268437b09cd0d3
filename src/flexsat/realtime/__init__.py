"""The plant for flight software in the loop: paced to the wall clock, over UDP or ZeroMQ."""

from __future__ import annotations

from flexsat.realtime.client import PlantClient
from flexsat.realtime.fmu import export_fmu
from flexsat.realtime.fsw import fly_remote
from flexsat.realtime.packets import Command, PacketError, Sensor, decode
from flexsat.realtime.server import ServeStats, serve
from flexsat.realtime.transport import client_link, plant_link

__all__ = [
    "Command",
    "PacketError",
    "PlantClient",
    "Sensor",
    "ServeStats",
    "client_link",
    "decode",
    "export_fmu",
    "fly_remote",
    "plant_link",
    "serve",
]
