"""Shared helpers for the Python tests of tumble (run by scripts/test.sh)."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture
def root():
    """The repository's root, for scenes/ and examples/."""
    return ROOT


@pytest.fixture()
def binary(root):
    """The `tumble` program to run: TUMBLE_BIN, else the newer of target/release and
    target/debug (built in release if neither exists)."""
    if os.environ.get("TUMBLE_BIN"):
        return os.environ["TUMBLE_BIN"]
    built = [root / "target" / kind / "tumble" for kind in ("release", "debug")]
    built = [p for p in built if p.exists()]
    if not built:
        subprocess.run(
            ["cargo", "build", "--release", "--locked", "--bin", "tumble"], cwd=root, check=True
        )
        built = [root / "target" / "release" / "tumble"]
    return str(max(built, key=lambda p: p.stat().st_mtime))
