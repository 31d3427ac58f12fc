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


def test_a_scenario_name_always_means_the_same_definition():
    """A changed definition gets a new version (found by review: nothing held that rule). The
    record is append-only: a new scenario adds its name and hash; an existing name's hash never
    changes, and no recorded name disappears."""
    import json
    from pathlib import Path

    from smafinger.paper import scenarios as scn

    record = json.loads((Path(__file__).parent / "golden" / "scenario_definitions.json").read_text())
    now = {s.name: s.definition_sha256() for s in scn.all_scenarios()}
    changed = sorted(n for n in record if n in now and now[n] != record[n])
    gone = sorted(set(record) - set(now))
    new = {n: h for n, h in now.items() if n not in record}
    assert not changed, f"these scenarios changed their definition under one name; give them a new version: {changed}"
    assert not gone, f"recorded scenarios that no longer exist: {gone}"
    assert not new, f"new scenarios: add them to tests/golden/scenario_definitions.json: {json.dumps(new)}"
