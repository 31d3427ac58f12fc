"""The engine against the golden record of every paper run (tests/golden/make_golden.py)."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent / "golden"))
from compare import differences, load  # noqa: E402
from make_golden import paper_tasks  # noqa: E402

from smafinger.engine.run import run_spec  # noqa: E402

META, TRACES = load()
TASKS = paper_tasks()


def test_the_record_covers_every_run():
    assert sorted(k for k, _ in TASKS) == sorted(META["runs"])


@pytest.mark.parametrize("key,spec", TASKS, ids=[k for k, _ in TASKS])
def test_run_is_bit_identical_to_the_golden_record(key, spec):
    assert differences(key, run_spec(spec), META, TRACES) == []
