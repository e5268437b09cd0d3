"""flexsat.files: writes that never follow a link, reads of regular files only."""

from __future__ import annotations

import os
import stat

import pytest

from flexsat import files
from flexsat.errors import ConfigError

VICTIM_TEXT = "the victim's own content\n"


@pytest.fixture
def victim(tmp_path):
    """A file outside the output folder that links inside it point to."""
    path = tmp_path / "victim.txt"
    path.write_text(VICTIM_TEXT)
    return path


def _only_the_target_in(folder, name):
    return sorted(p.name for p in folder.iterdir()) == [name]


def test_a_link_at_the_target_is_replaced_and_its_file_untouched(tmp_path, victim):
    out = files.output_root(tmp_path / "out")
    (out / "metrics.json").symlink_to(victim)
    files.write_text(out / "metrics.json", "{}")
    assert victim.read_text() == VICTIM_TEXT
    assert not (out / "metrics.json").is_symlink()
    assert (out / "metrics.json").read_text() == "{}"
    assert _only_the_target_in(out, "metrics.json")  # no temporary file left


def test_the_written_file_has_the_mode_of_a_plain_open(tmp_path):
    umask = os.umask(0o022)
    os.umask(umask)
    path = files.write_bytes(tmp_path / "a.bin", b"\x00\x01")
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask
    assert path.read_bytes() == b"\x00\x01"


def test_a_failed_write_leaves_the_old_file_and_no_temporary_file(tmp_path):
    target = tmp_path / "table.csv"
    target.write_text("old")
    with pytest.raises(RuntimeError), files.replacing(target, "w") as handle:
        handle.write("half")
        raise RuntimeError("the writer failed")
    assert target.read_text() == "old"
    assert _only_the_target_in(tmp_path, "table.csv")


def test_a_writer_that_needs_the_suffix_gets_it(tmp_path):
    with files.replacing_name(tmp_path / "movie.mp4", keep_suffix=True) as name:
        assert name.endswith(".partial.mp4")
        assert os.path.dirname(name) == str(tmp_path)  # same folder: os.replace is atomic
    assert (tmp_path / "movie.mp4").exists()


def test_a_linked_folder_below_an_output_folder_is_refused(tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    out = files.output_root(tmp_path / "out")
    (out / "replays").symlink_to(outside, target_is_directory=True)
    with pytest.raises(ConfigError, match="replays is a symbolic link inside the output folder"):
        files.write_text(out / "replays" / "a.nc", "x")
    with pytest.raises(ConfigError, match="symbolic link"):  # deeper folders too
        files.ensure_dir(out / "replays" / "deeper")
    assert list(outside.iterdir()) == []


def test_an_output_folder_inside_another_may_not_be_a_link(tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    study = files.output_root(tmp_path / "study")
    (study / "openloop").symlink_to(outside, target_is_directory=True)
    with pytest.raises(ConfigError, match="openloop is a symbolic link"):
        files.output_root(study / "openloop")


def test_the_output_folder_itself_may_be_a_link_the_user_named(tmp_path):
    real = tmp_path / "scratch"
    real.mkdir()
    (tmp_path / "out").symlink_to(real, target_is_directory=True)
    out = files.output_root(tmp_path / "out")
    files.write_text(out / "figures" / "a.txt", "x")
    assert (real / "figures" / "a.txt").read_text() == "x"


def test_the_lock_is_never_opened_through_a_link(tmp_path, victim):
    out = files.output_root(tmp_path / "store")
    (out / "campaign.lock").symlink_to(victim)
    with pytest.raises(ConfigError, match=r"campaign\.lock is a symbolic link"):
        files.open_lock(out / "campaign.lock")
    assert victim.read_text() == VICTIM_TEXT
    (out / "campaign.lock").unlink()
    with files.open_lock(out / "campaign.lock") as lock:
        lock.write("process 1")
    assert (out / "campaign.lock").read_text() == "process 1"


def test_a_fifo_is_refused_without_blocking(tmp_path):
    # Opened non-blocking and checked with fstat: no writer is needed for the refusal.
    fifo = tmp_path / "c.toml"
    os.mkfifo(fifo)
    with pytest.raises(ConfigError, match=r"cannot read config file .*: not a regular file"):
        files.read_user_file(fifo, "config")
    with pytest.raises(ConfigError, match="not a regular file"):
        files.check_user_file(fifo, "modal data")


def test_a_device_and_a_folder_are_refused(tmp_path):
    with pytest.raises(ConfigError, match="cannot read scenario file /dev/zero: not a regular"):
        files.read_user_file("/dev/zero", "scenario")
    with pytest.raises(ConfigError, match="not a regular file"):
        files.read_user_file(tmp_path, "campaign")


def test_a_file_over_the_size_cap_is_refused(tmp_path, monkeypatch):
    path = tmp_path / "c.toml"
    path.write_bytes(b"x" * 2048)
    monkeypatch.setattr(files, "MAX_INPUT_BYTES", 2047)
    with pytest.raises(ConfigError, match="2048 bytes, more than"):
        files.read_user_file(path, "config")
    monkeypatch.setattr(files, "MAX_INPUT_BYTES", 2048)  # at the cap: read whole
    assert files.read_user_file(path, "config") == b"x" * 2048


def test_a_missing_file_is_named():
    with pytest.raises(ConfigError, match=r"config file not found: /no/such/c\.toml"):
        files.read_user_file("/no/such/c.toml", "config")
