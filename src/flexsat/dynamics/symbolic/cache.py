"""On-disk cache of derived models and generated sources.

Everything that reads or writes the cache folder lives here: its location, the key
that makes a stale file unusable, atomic writes, and the serialization of a derived
model.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import pickle
import sys
import tempfile
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

import sympy as sp

if TYPE_CHECKING:
    from flexsat.dynamics.symbolic.derivation import SymbolicModel

__all__ = ["cache_dir"]


def cache_dir() -> Path:
    """Directory of the on-disk cache: ``$FLEXSAT_CACHE_DIR``, else ``~/.cache/flexsat``.

    Derived models and generated numeric code live in its ``symbolic/``
    subdirectory. Files are named by topology (number of appendages, panel-rate
    variant) and a hash of the sources of this package, the SymPy version and the
    Python version, so a stale file is never used; it is safe to delete the
    directory at any time. The directory is read once per process and topology.
    """
    env = os.environ.get("FLEXSAT_CACHE_DIR")
    return Path(env).expanduser() if env else Path.home() / ".cache" / "flexsat"


def _cache_subdir() -> Path:
    return cache_dir() / "symbolic"


@functools.cache
def _fingerprint() -> str | None:
    """Hash of this package's sources and the tool versions; ``None`` disables the cache.

    Any edit to the derivation, the symbols or the code generator changes the key, so
    a file written by another version of flexsat is never read.
    """
    digest = hashlib.sha256()
    try:
        for source in sorted(Path(__file__).parent.glob("*.py")):
            digest.update(source.name.encode() + b"\0" + source.read_bytes())
    except OSError:
        return None
    digest.update(
        f"|sympy {sp.__version__}|python {sys.version_info[0]}.{sys.version_info[1]}".encode()
    )
    return digest.hexdigest()[:20]


def _cache_path(
    directory: Path | None, kind: str, n_appendages: int, panel_rates: str, suffix: str
) -> Path | None:
    key = _fingerprint()
    if directory is None or key is None:
        return None
    return directory / f"{kind}-n{n_appendages}-{panel_rates}-{key}{suffix}"


def _write_atomic(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` via a temporary file and ``os.replace``.

    Readers in other processes see either no file or a complete one. Failure to
    write (read-only or full disk) only costs the cache, with a warning.
    """
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
    except OSError as exc:
        warnings.warn(
            f"flexsat: cannot write the symbolic cache file {path}: {exc}",
            RuntimeWarning,
            stacklevel=3,
        )


def read_model(path: Path) -> SymbolicModel | None:
    """The derived model stored at ``path``; ``None`` if missing, stale or damaged."""
    from flexsat.dynamics.symbolic.derivation import SymbolicModel

    try:
        model = pickle.loads(path.read_bytes())
    except Exception:  # missing, stale or damaged: the caller derives again
        return None
    return model if isinstance(model, SymbolicModel) else None


def write_model(path: Path, model: SymbolicModel) -> None:
    """Store a derived model at ``path`` (atomically, see :func:`_write_atomic`)."""
    _write_atomic(path, pickle.dumps(model, protocol=pickle.HIGHEST_PROTOCOL))


def read_source(path: Path) -> str | None:
    """The generated source stored at ``path`` if written under the current key, else ``None``."""
    try:
        source = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):  # missing or damaged: the caller generates again
        return None
    return source if f"# key: {_fingerprint()}\n" in source else None


def write_source(path: Path, source: str) -> None:
    """Store a generated source at ``path`` (atomically, see :func:`_write_atomic`)."""
    _write_atomic(path, source.encode("utf-8"))
