"""The fuzz suite's worker and its tally (printed at the end of the session).

Profiles: the quick one (about 1,000 cases, CI) by default; ``SMAFINGER_FUZZ=long`` runs
ten times as many (>= 10,000). ``SMAFINGER_FUZZ_REPORT=FILE.json`` writes the tally.
"""

import json
import os
import sys
from collections import Counter
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fuzz_runner import Runner  # noqa: E402

LONG = os.environ.get("SMAFINGER_FUZZ", "") == "long"
#: cases per test in the quick profile (x10 in the long one)
SCALE = 10 if LONG else 1
#: a case that answers later than this is a hang [s]
TIMEOUT_S = float(os.environ.get("SMAFINGER_FUZZ_TIMEOUT", "120"))

TALLY: dict[str, Counter] = {}


def _warm_kernels() -> None:
    """Compile the engine for both mechanisms here, with no time limit: on a fresh machine the
    first compile takes about a minute of CPU (more on a busy one), which is not a hang; the
    worker then loads it from numba's cache."""
    from smafinger.engine.run import make_spec, run_spec

    for params, profile in (("paper2010", "0:-30"), ("linear-bias-spring", "0:0.005")):
        run_spec(make_spec(params, "cooperative", profile, t_end_s=0.01))


@pytest.fixture(scope="session")
def runner(tmp_path_factory):
    _warm_kernels()
    r = Runner(tmp_path_factory.mktemp("fuzz"), TIMEOUT_S)
    yield r
    r.close()


def tally(test: str, kind: str) -> None:
    TALLY.setdefault(test, Counter())[kind] += 1


def pytest_terminal_summary(terminalreporter):
    if not TALLY:
        return
    total = Counter()
    terminalreporter.section(f"fuzz ({'long' if LONG else 'quick'} profile)")
    for test, counts in sorted(TALLY.items()):
        total.update(counts)
        terminalreporter.write_line(f"{test}: {sum(counts.values())} cases: " +
                                    ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    terminalreporter.write_line(f"all: {sum(total.values())} cases: " +
                                ", ".join(f"{k} {v}" for k, v in sorted(total.items())))
    path = os.environ.get("SMAFINGER_FUZZ_REPORT")
    if path:
        Path(path).write_text(json.dumps({"profile": "long" if LONG else "quick",
                                          "tests": {t: dict(c) for t, c in TALLY.items()}, "all": dict(total)},
                                         indent=2) + "\n")
