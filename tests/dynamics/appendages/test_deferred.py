"""The chain is registered by name and config; its module loads on first use.

Each check that reads ``sys.modules`` runs in a fresh interpreter: this process may
have imported the chain already.
"""

from __future__ import annotations

import pickle
import subprocess
import sys

import pytest

from flexsat.dynamics.appendages import AppendageModel, appendage_model
from flexsat.dynamics.appendages.chain import ChainModel
from flexsat.dynamics.appendages.chain_config import ChainConfig
from flexsat.dynamics.appendages.deferred import DeferredModel

_FRESH = """
import sys
from importlib import resources
import flexsat.dynamics.appendages as appendages
from flexsat.config import load_config
before = "flexsat.dynamics.appendages.chain" in sys.modules
with resources.as_file(resources.files("flexsat.config.presets") / "chain.toml") as path:
    config = load_config(path)
assert any(app.model == "chain" for app in config.appendages)
validated = "flexsat.dynamics.appendages.chain" in sys.modules
appendages.appendage_model("chain").kernels
print(before, validated, "flexsat.dynamics.appendages.chain_kernels" in sys.modules)
"""


def test_the_chain_module_loads_only_when_the_model_is_used():
    proc = subprocess.run([sys.executable, "-c", _FRESH], capture_output=True, text=True,
                          timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    # not at import, not to validate a chain's config; its kernels once asked for
    assert proc.stdout.split() == ["False", "False", "True"]


def test_the_registered_chain_answers_as_the_model():
    model = appendage_model("chain")
    assert isinstance(model, DeferredModel)
    assert isinstance(model, AppendageModel)
    real = ChainModel()
    assert model.name == real.name == "chain"
    assert model.config_class is real.config_class is ChainConfig
    for flag in ("transmits_inertia", "holds_locked", "holds_drive", "work_size"):
        assert getattr(model, flag) == getattr(real, flag), flag
    assert model.kernels == real.kernels  # the same compiled functions
    assert model.coordinates.__func__ is ChainModel.coordinates  # its methods: the model's


def test_a_deferred_model_pickles_as_registered():
    model = appendage_model("chain")
    copy = pickle.loads(pickle.dumps(model))
    assert isinstance(copy, DeferredModel)
    assert copy.name == "chain" and copy.config_class is ChainConfig
    assert copy.kernels == ChainModel().kernels


def test_a_model_that_does_not_match_its_registration_is_refused():
    wrong = DeferredModel("flexsat.dynamics.appendages.chain:ChainModel", "plate", ChainConfig)
    with pytest.raises(TypeError, match="registered as 'plate'"):
        wrong.kernels  # noqa: B018 (the first use loads the module)
