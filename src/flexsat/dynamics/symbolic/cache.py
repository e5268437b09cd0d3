"""On-disk cache of derived models and generated sources.

Everything that reads or writes the cache folder lives here: its location, the key
that makes a stale file unusable, atomic signed writes, and the serialization of a
derived model.

Loading a pickle or generated source runs code, so every cache file is signed
(HMAC-SHA256) with a per-user secret key kept apart from the cache
(``~/.config/flexsat/cache-key``, mode 0600): a file planted in the cache folder is
never unpickled or executed, only regenerated.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import hmac
import os
import pickle
import secrets
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


_SIGNATURE = b"flexsat-hmac-sha256:"


def _key_path() -> Path:
    """This user's secret cache key: kept apart from the cache, in the config folder."""
    config = os.environ.get("XDG_CONFIG_HOME") or Path.home() / ".config"
    return Path(config) / "flexsat" / "cache-key"


def _cache_key() -> bytes | None:
    """The cache key (created on first use, mode 0600); None if it cannot be trusted.

    Cache files are signed with it (HMAC-SHA256), so a file planted in the cache
    folder by anyone who cannot read this key is never unpickled or executed.
    """
    path = _key_path()
    try:
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            with os.fdopen(fd, "wb") as f:
                f.write(secrets.token_bytes(32))
        info = path.stat()
        if info.st_uid != os.getuid() or info.st_mode & 0o077:
            return None  # not this user's, or readable by others
        key = path.read_bytes()
    except OSError:
        return None
    return key if len(key) >= 32 else None


def _read_signed(path: Path) -> bytes | None:
    """The payload of a cache file whose signature checks with this user's key, else None."""
    key = _cache_key()
    try:
        data = path.read_bytes()
    except OSError:
        return None
    header, _, payload = data.partition(b"\n")
    if key is None or not header.startswith(_SIGNATURE):
        return None
    expected = hmac.new(key, payload, hashlib.sha256).hexdigest().encode()
    return payload if hmac.compare_digest(header[len(_SIGNATURE) :], expected) else None


def _write_atomic(path: Path, data: bytes) -> None:
    """Write ``data``, signed, to ``path`` via a temporary file and ``os.replace``.

    Readers in other processes see either no file or a complete one. Failure to
    write (read-only or full disk, no usable key) only costs the cache, with a warning.
    """
    key = _cache_key()
    if key is None:
        warnings.warn(
            f"flexsat: no usable cache key ({_key_path()}); the symbolic cache is off",
            RuntimeWarning,
            stacklevel=3,
        )
        return
    signature = hmac.new(key, data, hashlib.sha256).hexdigest().encode()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(_SIGNATURE + signature + b"\n" + data)
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

    data = _read_signed(path)  # unpickling runs code: only what this user wrote
    if data is None:
        return None
    try:
        model = pickle.loads(data)
    except Exception:  # stale or damaged: the caller derives again
        return None
    return model if isinstance(model, SymbolicModel) else None


def write_model(path: Path, model: SymbolicModel) -> None:
    """Store a derived model at ``path`` (atomically, see :func:`_write_atomic`)."""
    _write_atomic(path, pickle.dumps(model, protocol=pickle.HIGHEST_PROTOCOL))


def read_source(path: Path) -> str | None:
    """The generated source stored at ``path`` if written under the current key, else ``None``."""
    data = _read_signed(path)  # the source is executed: only what this user wrote
    if data is None:
        return None
    try:
        source = data.decode("utf-8")
    except UnicodeDecodeError:  # damaged: the caller generates again
        return None
    return source if f"# key: {_fingerprint()}\n" in source else None


def write_source(path: Path, source: str) -> None:
    """Store a generated source at ``path`` (atomically, see :func:`_write_atomic`)."""
    _write_atomic(path, source.encode("utf-8"))
