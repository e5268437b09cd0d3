"""The reference Python client of the real-time plant: HELLO, sensor packets, commands.

A flight software (or a bench) that speaks the protocol of ``docs/realtime.md``
needs only this: say HELLO until the plant answers with its first sensor packet,
then answer each sensor packet with one command packet, until the END packet.
:mod:`flexsat.realtime.fsw` flies a control law with it.
"""

from __future__ import annotations

import time

import numpy as np

from flexsat.errors import SimulationError
from flexsat.realtime import packets
from flexsat.realtime.transport import Link

__all__ = ["HELLO_INTERVAL_S", "PlantClient"]

HELLO_INTERVAL_S = 0.2
"""The client repeats HELLO this often until the plant's first sensor packet [s]."""


class PlantClient:
    """One client of a served plant.

    Parameters
    ----------
    link : Link
        The client's side (:func:`flexsat.realtime.transport.client_link`).

    Attributes
    ----------
    malformed : int
        Packets dropped for a wrong magic, version, type or length [-].
    answered : int
        Commands sent [-].
    """

    def __init__(self, link: Link) -> None:
        self.link = link
        self.malformed = 0
        self.answered = 0
        self._received_ns = 0
        self._sequence = -1  # the last sensor packet returned

    def connect(self, timeout_s: float) -> packets.Sensor:
        """Say HELLO until the first sensor packet arrives; return it.

        Parameters
        ----------
        timeout_s : float
            Longest wait [s].

        Returns
        -------
        Sensor
            The plant's first sample (instant 0).

        Raises
        ------
        SimulationError
            No sensor packet within ``timeout_s``.
        """
        end = time.perf_counter() + timeout_s
        while time.perf_counter() < end:
            self.link.send(packets.encode_hello())
            packet = self.next(HELLO_INTERVAL_S)
            if isinstance(packet, packets.Sensor):
                return packet
        raise SimulationError(f"no sensor packet from the plant within {timeout_s:g} s")

    def next(self, timeout_s: float) -> packets.Sensor | packets.Header | None:
        """The next sensor or END packet, waiting at most ``timeout_s`` [s]; None if none.

        Malformed packets are counted (:attr:`malformed`) and skipped, and so is a sensor
        packet not newer than the last one returned (the plant repeats its last packet
        when a HELLO comes before any command).

        Parameters
        ----------
        timeout_s : float
            Longest wait [s].

        Returns
        -------
        Sensor, Header (END) or None
        """
        end = time.perf_counter() + timeout_s
        while True:
            data = self.link.receive(max(end - time.perf_counter(), 0.0))
            if data is None:
                return None
            self._received_ns = time.monotonic_ns()
            try:
                packet = packets.decode(data)
            except packets.PacketError:
                self.malformed += 1
                continue
            if isinstance(packet, packets.Sensor):
                if packet.sequence <= self._sequence:
                    continue
                self._sequence = packet.sequence
                return packet
            if packet.type == packets.END:
                return packet

    def command(self, sensor: packets.Sensor, torque: np.ndarray) -> None:
        """Answer ``sensor`` with the body torque ``torque`` [N m], shape (3,), frame B.

        Parameters
        ----------
        sensor : Sensor
            The packet answered (its sequence, time and stamp are returned).
        torque : ndarray, shape (3,)
            Commanded body torque, frame B [N m].
        """
        compute = time.monotonic_ns() - self._received_ns
        self.link.send(packets.encode_command(sensor.sequence, sensor.sim_time_ns,
                                              sensor.plant_stamp_ns, compute, torque))  # fmt: skip
        self.answered += 1
