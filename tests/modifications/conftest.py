"""Warm the shared PEM map once per session (the first build compiles the PEM tables)."""

import pytest

from ._support import pem_healthy_map


@pytest.fixture(scope="session", autouse=True)
def _warm_map():
    pem_healthy_map()
