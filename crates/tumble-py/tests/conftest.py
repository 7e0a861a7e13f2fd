"""Shared helpers for the Python tests of tumble (run by scripts/test.sh)."""

import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture
def root():
    """The repository's root, for scenes/ and examples/."""
    return ROOT
