"""The symbolic cache never unpickles or executes a file this user's key did not sign."""

from __future__ import annotations

import hashlib
import hmac
import os
import pickle

import pytest

from flexsat.dynamics import symbolic
from flexsat.dynamics.symbolic import cache as symbolic_cache


class _Planted:
    """Unpickling this runs a command: what an attacker would put in the cache."""

    def __init__(self, marker: str) -> None:
        self.marker = marker

    def __reduce__(self):
        return (os.system, (f"touch {self.marker}",))


@pytest.fixture
def own_key(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    return symbolic_cache._cache_key()


def _plant(path, payload: bytes, key: bytes | None) -> None:
    header = b""
    if key is not None:
        digest = hmac.new(key, payload, hashlib.sha256).hexdigest().encode()
        header = symbolic_cache._SIGNATURE + digest
    path.write_bytes(header + b"\n" + payload)


@pytest.mark.parametrize("signed_with", [None, b"another user's key, 32 bytes long!"])
def test_a_planted_pickle_is_regenerated_not_run(tmp_path, monkeypatch, own_key, signed_with):
    cache, marker = tmp_path / "cache", tmp_path / "ran"
    cache.mkdir()
    path = symbolic._cache_path(cache, "model", 1, "exact", ".pickle")
    _plant(path, pickle.dumps(_Planted(str(marker))), signed_with)
    monkeypatch.setattr(symbolic, "_derive", lambda n, rates: "derived again")
    assert symbolic._load_model(1, "exact", cache) == "derived again"
    assert not marker.exists()
    assert pickle.loads(symbolic_cache._read_signed(path)) == "derived again"  # overwritten, signed


def test_planted_source_is_not_executed(tmp_path, own_key):
    cache, marker = tmp_path / "cache", tmp_path / "ran"
    cache.mkdir()
    path = symbolic._cache_path(cache, "reference", 1, "exact", ".py")
    source = f"# key: {symbolic_cache._fingerprint()}\nimport os\nos.system('touch {marker}')\n"
    _plant(path, source.encode(), None)
    assert symbolic_cache._read_signed(path) is None
    assert not marker.exists()


def test_a_key_others_can_read_is_not_trusted(tmp_path, own_key):
    assert own_key is not None and len(own_key) == 32
    key_path = symbolic_cache._key_path()
    assert key_path.stat().st_mode & 0o777 == 0o600
    key_path.chmod(0o644)
    assert symbolic_cache._cache_key() is None
