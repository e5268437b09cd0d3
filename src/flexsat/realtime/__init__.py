"""The plant for flight software in the loop: paced to the wall clock, over UDP or ZeroMQ."""

from __future__ import annotations
