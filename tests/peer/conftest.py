"""The peer suite's helpers (``judge``, ``truth``) are importable by name; the tally of verdicts is printed
at the end of the session."""

from __future__ import annotations

import sys
from pathlib import Path

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)


def pytest_terminal_summary(terminalreporter) -> None:  # type: ignore[no-untyped-def]
    from judge import TALLY

    if TALLY:
        total = sum(TALLY.values())
        terminalreporter.write_line(
            f"peer suite: {total} cases judged: {TALLY['tighter']} tighter, {TALLY['equal']} equal, "
            f"{TALLY['wider']} wider than codac's expected values (an unsound case fails its test)"
        )
