"""The files flexsat writes into an output folder, and the user files it reads.

Writes
    Every file flexsat writes inside an output folder (``--out``, a campaign
    store, a study) goes through :func:`replacing` (or :func:`write_text`,
    :func:`write_bytes`): the content is written to a new temporary file in the
    target's folder, created exclusively, then moved onto the target with
    :func:`os.replace`. A symbolic link at the target is replaced by the file,
    never followed, so no byte lands outside the folder. Folders go through
    :func:`ensure_dir`: below an output folder a command named
    (:func:`output_root`), every folder flexsat creates or enters must be a real
    folder; a symbolic link there is refused (:class:`~flexsat.errors.ConfigError`,
    exit code 2). The output folder itself may be a link: the user named it.
    The one file opened in place, the campaign lock (its ``flock`` must be shared by
    every run), is opened without following a link (:func:`open_lock`).

Reads
    A file a user names (a config, scenario, campaign or modal data file, a result
    to plot) is read only if it is a regular file of at most
    :data:`MAX_INPUT_BYTES` (:func:`read_user_file`, :func:`check_user_file`): a
    FIFO, a device or a folder is refused with one message instead of blocking or
    filling the memory.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO

from flexsat.errors import ConfigError

__all__ = [
    "MAX_INPUT_BYTES",
    "check_user_file",
    "ensure_dir",
    "open_lock",
    "output_root",
    "read_user_file",
    "replacing",
    "replacing_name",
    "write_bytes",
    "write_text",
]

MAX_INPUT_BYTES = 256 * 2**20
"""Largest user input file flexsat reads [bytes] (256 MiB): a config, scenario or
campaign TOML is a few kB, a modal data file of a thousand modes a few MB."""

_UMASK = os.umask(0o022)
os.umask(_UMASK)  # read once: every file written gets the mode a plain open() would give

_ROOTS: set[str] = set()
"""Output folders named on the command line (absolute, links not resolved). Forked
figure processes inherit it."""


def _absolute(path: str | Path) -> str:
    return os.path.abspath(os.fspath(path))


def _root_of(path: str) -> str | None:
    """The deepest registered output folder holding ``path`` (or being it)."""
    best = None
    for root in _ROOTS:
        if (path == root or path.startswith(root.rstrip(os.sep) + os.sep)) and (
            best is None or len(root) > len(best)
        ):
            best = root
    return best


def ensure_dir(path: str | Path) -> Path:
    """Create the folder ``path`` (and its parents) and check that no symbolic link
    lies between the output folder that holds it and ``path``.

    Parameters
    ----------
    path : str or Path
        The folder. Outside every output folder (:func:`output_root`) it is simply
        created.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ConfigError
        A folder below the output folder is a symbolic link or not a folder.
    """
    path = Path(path)
    absolute = _absolute(path)
    root = _root_of(absolute)
    if root is None:
        path.mkdir(parents=True, exist_ok=True)
        return path
    Path(root).mkdir(parents=True, exist_ok=True)
    current = root
    for part in Path(os.path.relpath(absolute, root)).parts:
        if part == os.curdir:
            continue
        current = os.path.join(current, part)
        _check_component(current, root)
        with contextlib.suppress(FileExistsError):
            os.mkdir(current)
        _check_component(current, root)
    return path


def _check_component(folder: str, root: str) -> None:
    if os.path.islink(folder):
        raise ConfigError(
            f"{folder} is a symbolic link inside the output folder {root}: flexsat writes "
            "only into real folders there; remove the link or choose another --out"
        )
    if os.path.lexists(folder) and not os.path.isdir(folder):
        raise ConfigError(f"{folder} exists inside the output folder {root} and is not a folder")


def output_root(path: str | Path) -> Path:
    """Register ``path`` as an output folder (created, checked by :func:`ensure_dir`).

    An output folder inside another one (a study's part) is checked as a folder of
    the outer one: it may not be a symbolic link.

    Parameters
    ----------
    path : str or Path
        The folder a command writes into.

    Returns
    -------
    Path
        ``path``.
    """
    ensure_dir(path)
    _ROOTS.add(_absolute(path))
    return Path(path)


@contextlib.contextmanager
def replacing_name(path: str | Path, keep_suffix: bool = False) -> Iterator[str]:
    """A temporary file name in ``path``'s folder, moved onto ``path`` on success.

    For writers that need a file name (NetCDF, PIL's GIF writer). The temporary file
    exists, empty, and ends in ``.partial``; it is removed if the block raises.
    Below an output folder, the folder is checked by :func:`ensure_dir`.

    Parameters
    ----------
    path : str or Path
        The target; a symbolic link there is replaced, not followed.
    keep_suffix : bool
        End the temporary name in ``path``'s suffix too (``.partial.gif``), for a
        writer that picks its format from the name (ffmpeg).

    Yields
    ------
    str
        The temporary file's name.
    """
    path = Path(path)
    ensure_dir(path.parent)
    suffix = ".partial" + (path.suffix if keep_suffix else "")
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=suffix)
    os.close(fd)
    try:
        os.chmod(tmp, 0o666 & ~_UMASK)
        yield tmp
        os.replace(tmp, path)
    finally:
        if os.path.lexists(tmp):
            os.remove(tmp)


@contextlib.contextmanager
def replacing(path: str | Path, mode: str = "wb", encoding: str | None = None) -> Iterator[IO]:
    """An open temporary file in ``path``'s folder, moved onto ``path`` on success.

    Parameters
    ----------
    path : str or Path
        The target; a symbolic link there is replaced, not followed.
    mode : str
        ``"wb"`` or ``"w"``.
    encoding : str, optional
        Text encoding with ``"w"`` (default UTF-8).

    Yields
    ------
    file object
        The temporary file, open for writing.
    """
    if "b" not in mode and encoding is None:
        encoding = "utf-8"
    with replacing_name(path) as tmp, open(tmp, mode, encoding=encoding) as handle:
        yield handle
        handle.flush()


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` through :func:`replacing`.

    Parameters
    ----------
    path : str or Path
        The file.
    text : str
        The content.

    Returns
    -------
    Path
        ``path``.
    """
    with replacing(path, "w") as handle:
        handle.write(text)
    return Path(path)


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through :func:`replacing`.

    Parameters
    ----------
    path : str or Path
        The file.
    data : bytes
        The content.

    Returns
    -------
    Path
        ``path``.
    """
    with replacing(path, "wb") as handle:
        handle.write(data)
    return Path(path)


def open_lock(path: str | Path) -> IO:
    """Open (creating it) a lock file in place, refusing a link or a non-regular file.

    Parameters
    ----------
    path : str or Path
        The lock file.

    Returns
    -------
    file object
        Open for reading and writing (``"a+"``), positioned at its end.

    Raises
    ------
    ConfigError
        ``path`` is a symbolic link or not a regular file.
    OSError
        It cannot be created or opened.
    """
    path = Path(path)
    ensure_dir(path.parent)
    flags = os.O_RDWR | os.O_CREAT | os.O_APPEND | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC
    try:
        fd = os.open(path, flags, 0o666)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise ConfigError(
                f"{path} is a symbolic link: flexsat does not write through it; remove it"
            ) from None
        raise
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise ConfigError(f"{path} is not a regular file; remove it")
    os.set_blocking(fd, True)
    return os.fdopen(fd, "a+")


def _open_user_file(path: Path, what: str, limit: int | None) -> int:
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)  # a FIFO opens at once
    except FileNotFoundError:
        raise ConfigError(f"{what} file not found: {path}") from None
    except OSError as exc:
        raise ConfigError(f"cannot read {what} file {path}: {exc.strerror or exc}") from None
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        os.close(fd)
        raise ConfigError(
            f"cannot read {what} file {path}: not a regular file (a FIFO, a device or a "
            "folder); flexsat reads only regular files"
        )
    if limit is not None and info.st_size > limit:
        os.close(fd)
        raise ConfigError(
            f"{what} file {path}: {info.st_size} bytes, more than the {_cap(limit)} flexsat reads"
        )
    os.set_blocking(fd, True)
    return fd


def _cap(limit: int) -> str:
    return f"{limit} bytes ({limit / 2**20:.4g} MiB)"


def read_user_file(path: str | Path, what: str) -> bytes:
    """The content of a user's input file, read only if regular and not too large.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str
        What it holds, for the message (``"config"``, ``"scenario"``...).

    Returns
    -------
    bytes
        At most :data:`MAX_INPUT_BYTES`.

    Raises
    ------
    ConfigError
        Missing, unreadable, not a regular file (a FIFO, a device, a folder) or
        larger than :data:`MAX_INPUT_BYTES`.
    """
    limit = MAX_INPUT_BYTES
    fd = _open_user_file(Path(path), what, limit)
    with os.fdopen(fd, "rb") as handle:
        try:
            data = handle.read(limit + 1)
        except OSError as exc:
            raise ConfigError(f"cannot read {what} file {path}: {exc.strerror or exc}") from None
    if len(data) > limit:  # grew while read
        raise ConfigError(f"{what} file {path}: more than the {_cap(limit)} flexsat reads")
    return data


def check_user_file(path: str | Path, what: str, limited: bool = True) -> Path:
    """Check that a user's input file is a regular file a reader may open by name.

    For readers that take a file name (NetCDF, NPZ); the same checks as
    :func:`read_user_file`.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str
        What it holds, for the message.
    limited : bool
        Refuse a file larger than :data:`MAX_INPUT_BYTES`; False for a run's NetCDF
        result, which its reader opens lazily.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ConfigError
        As :func:`read_user_file`.
    """
    os.close(_open_user_file(Path(path), what, MAX_INPUT_BYTES if limited else None))
    return Path(path)
