"""Fuzzing the command line (issue 13): exit 0 with sane outputs, or exit 2 with one line;
never a traceback, a hang or a file left behind (the rule: :func:`fuzz_runner.judge`).

Quick profile (CI, about 1,000 cases, a few minutes)::

    python -m pytest tests/fuzz

Long profile (>= 10,000 cases; the tally is printed at the end)::

    SMAFINGER_FUZZ=long python -m pytest tests/fuzz -p no:cacheprovider
"""

import pytest
from hypothesis import HealthCheck, given, settings

import fuzz_inputs as inputs
from conftest import LONG, SCALE, tally
from fuzz_runner import judge

pytestmark = [pytest.mark.fuzz_long] if LONG else []


def fuzz_settings(n: int):
    return settings(max_examples=n * SCALE, deadline=None, derandomize=not LONG, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.function_scoped_fixture, HealthCheck.filter_too_much])


@fuzz_settings(450)
@given(case=inputs.simulate_cases())
def test_simulate_command_lines(runner, case):
    tally("simulate", judge(case, runner.run(case)))


@fuzz_settings(150)
@given(case=inputs.params_cases())
def test_parameter_files(runner, case):
    tally("parameter files", judge(case, runner.run(case)))


@fuzz_settings(150)
@given(case=inputs.sweep_cases())
def test_sweep_specs(runner, case):
    tally("sweep specs", judge(case, runner.run(case)))


@fuzz_settings(250)
@given(case=inputs.identify_cases())
def test_identify_data_files(runner, case):
    tally("identify data", judge(case, runner.run(case)))
