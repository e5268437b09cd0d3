"""``flexsat animate``, run as a user runs it: in a subprocess."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr
from PIL import Image

from flexsat.simulate import OpenLoopScenario, run_openloop

FLEXSAT = [sys.executable, "-m", "flexsat"]


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*FLEXSAT, *args], capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def result_nc(nominal_plant, tmp_path_factory) -> Path:
    result = run_openloop(nominal_plant, OpenLoopScenario(duration_s=2.0))
    return result.to_netcdf(tmp_path_factory.mktemp("run") / "result.nc")


def test_animate_writes_a_gif(result_nc: Path, tmp_path: Path) -> None:
    target = tmp_path / "films" / "run.gif"
    done = run("animate", str(result_nc), "-o", str(target), "--magnification", "40",
               "--fps", "10", "--max-frames", "6")  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert f"wrote {target}" in done.stdout
    assert "6 frames" in done.stdout and "deformation ×40" in done.stdout
    with Image.open(target) as im:
        assert im.format == "GIF"
        assert im.n_frames == 6
        assert im.info["duration"] == 100
        assert b"deformation x40," in im.info["comment"]


@pytest.mark.parametrize(
    ("make", "fragment"),
    [
        (lambda p: None, "file not found"),
        (lambda p: p.write_text("not netcdf\n"), "not a readable NetCDF file"),
        (lambda p: xr.Dataset({"a": ("x", [1.0])}).to_netcdf(p), "not a flexsat simulation result"),
    ],
    ids=["missing", "not-netcdf", "foreign-netcdf"],
)
def test_animate_bad_file_exits_2_with_one_line(tmp_path: Path, make, fragment) -> None:
    path = tmp_path / "input.nc"
    make(path)
    done = run("animate", str(path), "-o", str(tmp_path / "out.gif"))
    assert done.returncode == 2
    assert fragment in done.stderr and str(path) in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "out.gif").exists()


def test_animate_bad_suffix_exits_2(result_nc: Path, tmp_path: Path) -> None:
    done = run("animate", str(result_nc), "-o", str(tmp_path / "run.png"))
    assert done.returncode == 2
    assert ".gif or .mp4" in done.stderr
    assert "Traceback" not in done.stderr
