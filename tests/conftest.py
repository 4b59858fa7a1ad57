"""Session-wide checks for the whole suite: the run ends every process it starts (issue 24;
see process_guard.py)."""

from process_guard import pytest_configure, pytest_sessionfinish

__all__ = ["pytest_configure", "pytest_sessionfinish"]
