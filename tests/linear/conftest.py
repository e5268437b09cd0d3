import pytest

from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.linear import linearize


@pytest.fixture(scope="session")
def plant() -> Plant:
    return Plant.from_config(nominal())


@pytest.fixture(scope="session")
def rest_model(plant):
    return linearize(plant)
