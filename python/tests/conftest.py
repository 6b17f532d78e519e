"""Shared paths for the Python package's tests."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def scenes() -> Path:
    """The shipped scene files."""
    return ROOT / "assets" / "scenes"
