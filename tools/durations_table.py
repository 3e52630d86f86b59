"""The test suite's time as a markdown table, from the output of ``make test`` run with ``--durations=N``.

    bash tools/dev.sh test --durations=40 -q -p no:cacheprovider > test.log 2>&1
    python tools/durations_table.py test.log > table.md

Reads pytest's "slowest N durations" block and its last summary line (``2324 passed in 480.12s (0:08:00)``);
prints the total, the pass/fail counts and one row per slow test (phase: ``setup`` is a module fixture's
time charged to the first test that uses it). No third-party code: the log's format is pytest's own.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

_ROW = re.compile(r"^(\d+\.\d+)s (setup|call|teardown)\s+(\S+)")
_SUMMARY = re.compile(r"^=*\s*(.*\d+ passed.* in (\d+\.\d+)s.*?)\s*=*$")


def parse(text: str) -> tuple[list, str, float]:
    """(rows (seconds, phase, test id), summary line, wall seconds) of a pytest log."""
    rows, summary, wall = [], None, None
    for line in text.splitlines():
        m = _ROW.match(line.strip())
        if m:
            rows.append((float(m.group(1)), m.group(2), m.group(3)))
        s = _SUMMARY.match(line.strip())
        if s:
            summary, wall = s.group(1), float(s.group(2))
    if summary is None:
        raise ValueError("no pytest summary line ('N passed in S s') in the log: did the run finish?")
    if not rows:
        raise ValueError("no 'slowest durations' rows in the log: run pytest with --durations=40.")
    return rows, summary, wall


def table(rows, summary, wall, top: int = 40) -> str:
    lines = [f"Result: `{summary}` ({wall / 60:.1f} min wall).", "",
             f"Slowest {min(top, len(rows))} (of the test run's phases; these sum to {sum(r[0] for r in rows[:top]):.0f} s "
             f"of the {2 * wall:.0f} core-seconds two workers had):", "",
             "| # | seconds | phase | test |", "|---:|---:|---|---|"]
    for k, (sec, phase, test) in enumerate(rows[:top], 1):
        lines.append(f"| {k} | {sec:.2f} | {phase} | `{test}` |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python tools/durations_table.py PYTEST_LOG")
    print(table(*parse(Path(sys.argv[1]).read_text())), end="")
