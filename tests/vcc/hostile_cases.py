"""The hostile-input table `test_hostile_inputs.py` runs (its format: `hostile_table.py`):
the themed case modules imported in the order their cases were written, since a case's
place decides whether the default suite runs it (DEFAULT_EVERY there)."""

from __future__ import annotations

import importlib

from tests.vcc.hostile_table import CASES, _flags, case

for _theme in ("run", "data", "search", "argpred", "robot", "bench"):
    importlib.import_module(f"tests.vcc.hostile_cases_{_theme}")

from tests.vcc.hostile_cases_bench import REP, W_REP  # noqa: E402  (already imported, in their turn)
from tests.vcc.hostile_cases_search import EXOK, LE, W_OUT  # noqa: E402

# cases written after the bench cases: kept last, so that no case before them moves
case("learn-filters-bad", "learn", EXOK, *_flags(LE, filters="some"), setup="examples", writes=W_OUT)
case("bench-report-compiled-file", "bench", "report", *_flags(REP, compiled="{file}"), writes=W_REP)

__all__ = ["CASES"]
