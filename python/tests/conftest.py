"""Shared fixtures: the repository, the shared real data, the `brtf` CLI
binary the Python results are compared with, and real Radiance."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SHARED = REPO.parent / "shared"
GOLDEN_PAPER = SHARED / "data" / "rgl-epfl-pgII-raw" / "golden_paper.txt"
KLEMS_FABRIC = SHARED / "data" / "lbnl-frads-klems-fabrics" / "klems_aniso_high.xml"
ALU = sorted((REPO / "data" / "alu-ggx").glob("*.mpc"))


def shared_file(path: Path) -> Path:
    """A file of ../shared/data: CI always has it, so a missing one fails."""
    if not path.is_file():
        pytest.fail(f"{path} is missing: the tests read real data from ../shared/data")
    return path


@pytest.fixture(scope="session")
def golden_paper() -> Path:
    return shared_file(GOLDEN_PAPER)


@pytest.fixture(scope="session")
def klems_fabric() -> Path:
    return shared_file(KLEMS_FABRIC)


@pytest.fixture(scope="session")
def alu() -> list:
    assert len(ALU) == 5, f"expected the five data/alu-ggx/*.mpc files, found {ALU}"
    return ALU


@pytest.fixture(scope="session")
def cli() -> Path:
    """The `brtf` binary: $BRTF_BIN, else the newest of target/{release,debug}/brtf."""
    if os.environ.get("BRTF_BIN"):
        path = Path(os.environ["BRTF_BIN"])
        if not path.is_file():
            pytest.fail(f"BRTF_BIN={path} does not exist")
        return path
    found = [p for p in (REPO / "target" / "release" / "brtf", REPO / "target" / "debug" / "brtf") if p.is_file()]
    if not found:
        pytest.fail("no brtf binary: run `cargo build` (or set BRTF_BIN)")
    return max(found, key=lambda p: p.stat().st_mtime)


def run_cli(cli: Path, *args, stdin: str | None = None) -> str:
    done = subprocess.run(
        [str(cli), *map(str, args)], input=stdin, capture_output=True, text=True, cwd=REPO
    )
    assert done.returncode == 0, f"brtf {' '.join(map(str, args))} failed:\n{done.stderr}"
    return done.stdout


@pytest.fixture(scope="session")
def radiance_bin() -> Path:
    """Real Radiance (oconv, rtrace) from $RADIANCE_BIN or the pyradiance package."""
    candidates = []
    if os.environ.get("RADIANCE_BIN"):
        candidates.append(Path(os.environ["RADIANCE_BIN"]))
    try:
        import pyradiance  # noqa: F401

        candidates.append(Path(pyradiance.__file__).parent / "bin")
    except ImportError:
        pass
    if shutil.which("rtrace"):
        candidates.append(Path(shutil.which("rtrace")).parent)
    for c in candidates:
        if (c / "rtrace").is_file() and (c / "oconv").is_file():
            return c
    pytest.fail("real Radiance is missing: install pyradiance==1.3.1 (scripts/test.sh does)")
