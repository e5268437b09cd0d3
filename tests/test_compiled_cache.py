"""numba's cached machine code is dropped when any compiled module's source changes."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

import flexsat
from flexsat._compiled_cache import COMPILED_MODULES, drop_stale_caches, kernels_cached
from flexsat.config import nominal
from flexsat.dynamics import kernels
from flexsat.dynamics.plant import Plant


def _package_copy(tmp_path: Path) -> Path:
    source = Path(flexsat.__file__).parent
    package = tmp_path / "flexsat"
    for module in COMPILED_MODULES:
        target = package / module
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source / module, target)
    return package


def _fake_caches(package: Path) -> list[Path]:
    files = []
    for module in COMPILED_MODULES:
        cache = (package / module).parent / "__pycache__"
        cache.mkdir(exist_ok=True)
        stem = Path(module).stem
        for name in (f"{stem}.rk4_step-10.py311.nbi", f"{stem}.rk4_step-10.py311.1.nbc"):
            (cache / name).write_bytes(b"machine code")
            files.append(cache / name)
    return files


def test_an_edit_to_a_kernel_drops_every_compiled_cache(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    package = _package_copy(tmp_path)
    assert drop_stale_caches(package)  # first run: no digest yet
    caches = _fake_caches(package)
    bytecode = package / "dynamics" / "__pycache__" / "kernels.cpython-311.pyc"
    bytecode.write_bytes(b"bytecode")
    assert not drop_stale_caches(package)  # unchanged sources: caches kept
    assert all(path.exists() for path in caches)
    kernels = package / "dynamics" / "kernels.py"
    kernels.write_text(kernels.read_text() + "\n# an edit\n")
    assert drop_stale_caches(package)
    # The loops that inline the kernels lose their machine code too, not only kernels.py.
    assert not any(path.exists() for path in caches)
    assert bytecode.exists()  # Python's own bytecode is not numba's to drop
    assert not drop_stale_caches(package)


def test_caches_under_numba_cache_dir_are_dropped_too(tmp_path, monkeypatch):
    package = _package_copy(tmp_path / "src")
    custom = tmp_path / "numba-cache"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(custom))
    drop_stale_caches(package)
    folder = custom / str((package / "simulate").resolve()).lstrip("/")
    folder.mkdir(parents=True)
    cached = folder / "loops.rk4_closed_loop-20.py311.nbi"
    cached.write_bytes(b"machine code")
    laws = package / "control" / "laws" / "asmc.py"
    laws.write_text(laws.read_text() + "\n# an edit\n")
    assert drop_stale_caches(package)
    assert not cached.exists()


def test_kernels_cached_reads_the_folder_numba_caches_the_kernels_in(monkeypatch, tmp_path):
    # The study compiles in two processes only when this says the cache is empty: it
    # must look where numba writes (its cache locator's folder), not guess a path.
    Plant.from_config(nominal()).accelerations(np.zeros(18), np.zeros(18))  # cached now
    assert kernels_cached()
    monkeypatch.setattr(kernels.accelerations._cache, "_cache_path", str(tmp_path))
    assert not kernels_cached()
    (tmp_path / "kernels.accelerations-152.py312.nbi").write_bytes(b"")
    assert kernels_cached()
