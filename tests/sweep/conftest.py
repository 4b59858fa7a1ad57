"""Fixtures of the sweep tests."""

from __future__ import annotations

import pytest

import gearchaos as gc

pytest.register_assert_rewrite("sweep_helpers")


@pytest.fixture(scope="session")
def sheng() -> gc.GearSet:
    return gc.preset("hindawi2021")
