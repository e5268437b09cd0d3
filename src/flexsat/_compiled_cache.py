"""Keep numba's on-disk machine code in step with the compiled modules' sources.

numba checks a cached function against the file that defines it only. The RK4
loops (``integrators.py``, ``loops.py``) inline the kernels of ``kernels.py`` and
``linalg3.py``; after an edit to a kernel alone, their cached machine code would
still run the old physics. numba has no hook for such dependencies, so flexsat
keeps a digest of every compiled module's source next to the caches and, when it
changes, removes the cached machine code of all of them (rebuilt on the next run,
about 15 s). Called once, at ``import flexsat``; it costs a hash of a few hundred
kilobytes.
"""

from __future__ import annotations

import hashlib
import os
import warnings
from pathlib import Path

from numba.core.errors import NumbaExperimentalFeatureWarning

__all__ = ["COMPILED_MODULES", "drop_stale_caches"]

# Pluggable compiled pieces (appendage kernels) reach the loops as numba first-class
# functions, which numba flags as experimental on every use; the feature is relied
# on deliberately (typed by signature, cached), so that one warning is silenced here.
warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning)

COMPILED_MODULES = (
    "dynamics/linalg3.py",
    "dynamics/status.py",
    "dynamics/appendages/contract.py",
    "dynamics/appendages/plate.py",
    "dynamics/packed.py",
    "dynamics/kernels.py",
    "dynamics/integrators.py",
    "dynamics/records.py",
    "control/quaternion.py",
    "control/actuation.py",
    "control/laws.py",
    "simulate/loops.py",
)
"""Modules with ``@njit(cache=True)`` functions, or whose constants and numba types
compiled code depends on, relative to the package folder."""

_STAMP = "compiled_sources.sha256"


def _cache_dirs(package: Path, module: str) -> list[Path]:
    """Where numba may keep a module's cache: ``__pycache__`` or under NUMBA_CACHE_DIR."""
    folder = (package / module).parent.resolve()
    dirs = [folder / "__pycache__"]
    custom = os.environ.get("NUMBA_CACHE_DIR")
    if custom:
        dirs.append(Path(custom) / str(folder).lstrip(os.sep))
    return dirs


def drop_stale_caches(package: Path | None = None) -> bool:
    """Remove the compiled caches if any compiled module's source changed.

    Parameters
    ----------
    package : Path, optional
        The flexsat package folder (default: this module's folder).

    Returns
    -------
    bool
        True if caches were removed. A read-only installation is left alone (numba
        then caches elsewhere, keyed by the installed files, which do not change).
    """
    package = package or Path(__file__).parent
    digest = hashlib.sha256()
    for module in COMPILED_MODULES:
        digest.update(module.encode())
        digest.update((package / module).read_bytes())
    current = digest.hexdigest()
    stamp = package / "__pycache__" / _STAMP
    try:
        if stamp.exists() and stamp.read_text() == current:
            return False
        for module in COMPILED_MODULES:
            stem = Path(module).stem
            for folder in _cache_dirs(package, module):
                for cached in folder.glob(f"{stem}.*.nb[ic]"):
                    cached.unlink(missing_ok=True)
        stamp.parent.mkdir(exist_ok=True)
        partial = stamp.with_suffix(f".{os.getpid()}.partial")
        partial.write_text(current)
        partial.replace(stamp)
    except OSError:
        return False
    return True
