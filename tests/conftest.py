"""Process set-up for the suite (one host device unless a test asks for more) and the
shared fixture; the helpers themselves live in tests/helpers.py."""

from __future__ import annotations

import os

os.environ.setdefault("XLA_FLAGS", "--xla_force_host_platform_device_count=1")

import pytest  # noqa: E402

from tests.helpers import run_both  # noqa: E402


@pytest.fixture
def both():
    return run_both
