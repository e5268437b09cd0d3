"""Keep numba's on-disk machine code in step with the compiled modules' sources.

numba checks a cached function against the file that defines it only. The RK4
loops (``integrators.py``, ``loops.py``) inline the kernels of ``kernels.py`` and
``linalg3.py``; after an edit to a kernel alone, their cached machine code would
still run the old physics. numba has no hook for such dependencies, so flexsat
keeps a digest of every compiled module's source next to the caches and, when it
changes, removes the cached machine code of all of them (rebuilt on the next run,
about 15 s). Called once, at ``import flexsat``. While no source file of the package
has changed since the last check (same names, sizes and modification times: a
``stat`` of each, no read), it reads and hashes nothing; otherwise it finds the
compiled modules and hashes them, a few hundred kilobytes (docs/performance.md,
'Start-up').
"""

from __future__ import annotations

import hashlib
import os
import re
import warnings
from pathlib import Path

__all__ = ["COMPILED_MODULES", "compiled_modules", "drop_stale_caches", "kernels_cached"]

# Pluggable compiled pieces (laws, loop stages, appendage kernels) reach the loops as
# numba first-class functions, which numba flags as experimental on every use; the
# feature is relied on deliberately (typed by signature, cached), so that one warning
# is silenced here. By its text, not its class (numba's NumbaExperimentalFeatureWarning):
# naming the class would import numba (0.2 s) into every process that imports flexsat,
# ``flexsat --help`` included.
warnings.filterwarnings("ignore", message="First-class function type feature is experimental")

# A module is part of the compiled code if it compiles functions, builds numba types,
# or holds constants that numba freezes into compiled code (marked by the comment
# "# Frozen into compiled code." at the start of a line).
_COMPILED = re.compile(r"^(@njit|from numba|import numba|# Frozen into compiled code\.)", re.M)


def compiled_modules(package: Path | None = None) -> tuple[str, ...]:
    """Modules compiled code depends on, relative to the package folder, sorted.

    Those with ``@njit`` functions, those that import numba (numba types and
    signatures the cache index pickles) and those marked as holding constants numba
    freezes into compiled code. Found by reading the sources, so a new compiled module
    (a law, a stage, a kernel) needs no entry in a list.
    """
    package = package or Path(__file__).parent
    return tuple(sorted(
        path.relative_to(package).as_posix() for path in package.rglob("*.py")
        if _COMPILED.search(path.read_text(encoding="utf-8"))
    ))  # fmt: skip


COMPILED_MODULES: tuple[str, ...]  # assigned by __getattr__ on first use
"""The package's compiled modules (:func:`compiled_modules`)."""


def __getattr__(name: str):
    """``COMPILED_MODULES``: the package's compiled modules (:func:`compiled_modules`),
    found on first use (PEP 562): finding them reads every source file."""
    if name == "COMPILED_MODULES":
        value = globals()["COMPILED_MODULES"] = compiled_modules()
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


_STAMP = "compiled_sources.sha256"


def _fingerprint(package: Path) -> str:
    """A digest of every source file's name, size and modification time (no read)."""
    entries = []
    for folder, dirs, files in os.walk(package):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        for name in files:
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                info = os.stat(path)
                entries.append(f"{path}\0{info.st_size}\0{info.st_mtime_ns}\n")
    return hashlib.sha256("".join(sorted(entries)).encode()).hexdigest()


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
    default = package is None
    package = package or Path(__file__).parent
    stamp = package / "__pycache__" / _STAMP
    fingerprint = _fingerprint(package)
    try:
        known = stamp.read_text().split()
    except OSError:
        known = []
    if len(known) == 2 and known[1] == fingerprint:
        return False  # no source file changed since the digest was written
    if default:
        modules = globals().get("COMPILED_MODULES") or __getattr__("COMPILED_MODULES")
    else:
        modules = compiled_modules(package)
    digest = hashlib.sha256()
    for module in modules:
        digest.update(module.encode())
        digest.update((package / module).read_bytes())
    current = digest.hexdigest()
    try:
        if known[:1] == [current]:  # files touched, compiled sources unchanged
            _write_stamp(stamp, current, fingerprint)
            return False
        for module in modules:
            stem = Path(module).stem
            for folder in _cache_dirs(package, module):
                for cached in folder.glob(f"{stem}.*.nb[ic]"):
                    cached.unlink(missing_ok=True)
        _write_stamp(stamp, current, fingerprint)
    except OSError:
        return False
    return True


def _write_stamp(stamp: Path, digest: str, fingerprint: str) -> None:
    """Write the compiled sources' digest and the files' fingerprint, atomically."""
    stamp.parent.mkdir(exist_ok=True)
    partial = stamp.with_suffix(f".{os.getpid()}.partial")
    partial.write_text(f"{digest}\n{fingerprint}\n")
    partial.replace(stamp)


def kernels_cached() -> bool:
    """True if numba's disk cache holds the compiled kernels: False on the first run
    after an install or an upgrade (:func:`drop_stale_caches` drops them all together).

    Looks for the cache index of :mod:`flexsat.dynamics.kernels` in the folder numba's
    own cache locator chose (beside the sources, ``NUMBA_CACHE_DIR``, or a per-user
    folder when the sources are read-only); compiles nothing.

    Returns
    -------
    bool
        Whether the kernels' cache index exists.
    """
    from flexsat.dynamics import kernels

    cache = Path(kernels.accelerations._cache._cache_path)  # numba has no public getter
    return any(cache.glob("kernels.*.nbi"))
