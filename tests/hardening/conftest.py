"""Counts of fuzzed inputs, reported in the test session's summary."""

from __future__ import annotations

import collections

import pytest

FUZZ_COUNTS: collections.Counter = collections.Counter()


@pytest.fixture
def fuzz_counter():
    return FUZZ_COUNTS
