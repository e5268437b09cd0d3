"""Layout of the symbolic reference package (flexsat.dynamics.symbolic).

The package has one module per concern; these tests keep its public names importable
from the package itself and keep every access to the cache folder in one module.
"""

from __future__ import annotations

from pathlib import Path

import flexsat.dynamics.symbolic as symbolic
from flexsat.dynamics.symbolic import cache

PACKAGE = Path(symbolic.__file__).parent


def test_public_names_importable_from_the_package():
    for name in symbolic.__all__:
        assert getattr(symbolic, name) is not None, name


def test_only_the_cache_module_reads_or_writes_files():
    for source in sorted(PACKAGE.glob("*.py")):
        text = source.read_text(encoding="utf-8")
        if source.name == "cache.py":
            assert "import pickle" in text and "os.replace" in text
            continue
        needles = ("import pickle", "os.replace", "tempfile", "read_bytes", "read_text", "open(")
        for needle in needles:
            assert needle not in text, f"{source.name} uses {needle}: belongs in cache.py"


def test_cache_key_covers_every_module_of_the_package(tmp_path, monkeypatch):
    # The key hashes each source of the package: editing any one of them (here: a copy
    # of the package with one module changed) gives another key, so no stale file is read.
    key = cache._fingerprint()
    assert key is not None and len(key) == 20
    copy = tmp_path / "symbolic"
    copy.mkdir()
    for source in PACKAGE.glob("*.py"):
        (copy / source.name).write_bytes(source.read_bytes())
    keys = set()
    for source in sorted(copy.glob("*.py")):
        original = source.read_bytes()
        source.write_bytes(original + b"\n# edited\n")
        monkeypatch.setattr(cache, "__file__", str(copy / "cache.py"))
        cache._fingerprint.cache_clear()
        keys.add(cache._fingerprint())
        source.write_bytes(original)
    cache._fingerprint.cache_clear()
    monkeypatch.undo()
    assert key not in keys and len(keys) == len(list(PACKAGE.glob("*.py")))
    assert cache._fingerprint() == key
