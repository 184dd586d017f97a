"""Shared paths: the repository root (for tests/data and the Rust examples)."""

import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
DATA = ROOT / "tests" / "data"


@pytest.fixture(scope="session")
def root():
    return ROOT
