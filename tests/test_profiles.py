"""Target profiles and drive programs built directly, as the public classes (found by an API
fuzz: a tuple where a Segment belongs, None where a word or text belongs, or numbers given as
text raised AttributeError or numpy's errors from inside the checks)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from smafinger import ProfileError, TargetProfile, VoltageProgram
from smafinger.profiles import Segment


@pytest.mark.parametrize("make, words", [
    (lambda: TargetProfile((Segment(0.0, -25.0, None),)), "enable: None is not a word"),
    (lambda: TargetProfile(((0.0, -25.0),)), "segment 0: (0.0, -25.0) is not a Segment"),
    (lambda: TargetProfile("0:-25"), "not str"),
    (lambda: TargetProfile((Segment(0.0, "-25"),)), "target: '-25' is not a number"),
    (lambda: TargetProfile((Segment(True, -25.0),)), "start_s: True is not a number"),
    (lambda: TargetProfile.parse(None), "profile: None is not text"),
    (lambda: VoltageProgram((0.0, 8.0, 0.0)), "not (0.0, 8.0, 0.0)"),
    (lambda: VoltageProgram((("0", "8", "0"),)), "must hold numbers"),
    (lambda: VoltageProgram(((0.0, 8.0), (1.0, 8.0, 0.0))), "the same number of values"),
    (lambda: VoltageProgram(()), "at least one step"),
    (lambda: VoltageProgram(np.zeros((0, 3))), "at least one step"),
    (lambda: VoltageProgram.parse(None), "voltage program: None is not text"),
    (lambda: VoltageProgram.parse(8.0, "duty"), "duty program: 8.0 is not text"),
])
def test_a_malformed_profile_or_program_is_a_profile_error_naming_it(make, words):
    with pytest.raises(ProfileError) as err:
        make()
    assert words in str(err.value)


def test_numbers_of_any_kind_are_kept_as_floats():
    """numpy scalars and arrays are numbers: kept as floats, so that the run's summary is JSON
    (a float32 target reached json.dumps(summary()) and failed there)."""
    p = TargetProfile([Segment(np.int64(0), np.float32(-25.5)), Segment(None, -40)])
    assert p == TargetProfile.parse("0:-25.5,reach:-40")
    assert all(type(v) is float for s in p.segments for v in (s.target,) + ((s.start_s,) if s.start_s is not None else ()))
    json.dumps([s.__dict__ for s in p.segments])
    prog = VoltageProgram(np.array([[0.0, 8.0, 0.0], [1.0, 0.0, 0.0]], dtype=np.float32))
    assert prog == VoltageProgram.parse("0:8:0,1:0:0")
    assert {type(v) for st in prog.steps for v in st} == {float}


def test_the_command_line_prints_a_programs_start_as_a_number(capsys):
    """The start read from text is a numpy scalar inside the check: printed as 1.0, not
    np.float64(1.0) (found by review)."""
    from smafinger.cli import main

    assert main(["simulate", "--strategy", "open-loop", "--voltage", "1:8:0,6:0:0", "--t-end", "1"]) == 2
    assert "the first step must start at 0 s, not 1.0\n" in capsys.readouterr().err
