"""Run-size switch: ``ORRC_QUICK=1`` in the environment shrinks long runs.

The test suite sets it when it executes the chapters, so the same chapter source
runs at full size in the book and at reduced size under test (never a copy).
"""
from __future__ import annotations

import os


def quick() -> bool:
    """True when the environment variable ORRC_QUICK is set to 1/true/yes."""
    return os.environ.get("ORRC_QUICK", "").strip().lower() in ("1", "true", "yes")


def size(full: int, quick_size: int) -> int:
    """``full`` normally, ``quick_size`` under ORRC_QUICK=1."""
    return quick_size if quick() else full
