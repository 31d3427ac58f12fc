"""The paper layer's machinery: typed overrides, claim verdicts, JSON rounding, and the
report's findings computed from the numbers (no runs needed)."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from smafinger.parameters import ParameterError, get
from smafinger.paper import findings as F
from smafinger.paper.claim import Check, Claim, Verdict
from smafinger.paper.investigation import READINGS
from smafinger.paper.overrides import Overrides
from smafinger.paper.report import claims_table
from smafinger.paper.runner import json_ready


# ---- overrides ---------------------------------------------------------------------------------
def test_overrides_route_parameters_and_run_settings():
    ov = Overrides.of(T_init_C=60, tol_deg=0.2, independent_wait=False)
    assert ov.params == (("T_init_C", 60.0),) and isinstance(ov.params[0][1], float)
    assert ov.settings() == {"tol_deg": 0.2, "independent_wait": False}
    assert ov.apply(get("paper2010")).T_init_C == 60.0
    assert ov.texts() == ("T_init_C=60.0", "tol_deg=0.2", "independent_wait=false")


def test_later_overrides_win():
    a = Overrides.of(T_init_C=60.0, hold_s=2.0, M_SF_Nm=0.02)
    b = Overrides.parse(["T_init_C=40", "controller_in_cooling=false"]).then(Overrides.of(hold_s=1.0))
    ab = a.then(b)
    assert dict(ab.params) == {"T_init_C": 40.0, "M_SF_Nm": 0.02, "controller_in_cooling": False}
    assert ab.hold_s == 1.0 and a.then(Overrides()) == a


@pytest.mark.parametrize("bad,match", [
    (dict(T_init_Celsius=60.0), "override T_init_Celsius = 60.0: unknown parameter or run setting"),
    (dict(T_init_C="hot"), "override T_init_C = 'hot': not a finite number"),
    (dict(T_init_C=math.nan), "override T_init_C = nan: not a finite number"),
    (dict(controller_in_cooling=1), "override controller_in_cooling = 1: not a bool"),
    (dict(tol_deg=True), "override tol_deg = True: not a finite number"),
])
def test_bad_overrides_name_the_field_and_the_value(bad, match):
    with pytest.raises(ParameterError, match=match):
        Overrides.of(**bad)


def test_parsed_overrides_name_the_problem():
    with pytest.raises(ParameterError, match="not of the form NAME=VALUE"):
        Overrides.parse(["M_SF_Nm"])
    with pytest.raises(ParameterError, match="unknown parameter: 'M_XX'"):
        Overrides.parse(["M_XX=1"])
    with pytest.raises(ParameterError, match="M_SF_Nm: 'abc' is not a number"):
        Overrides.parse(["M_SF_Nm=abc"])
    with pytest.raises(ParameterError, match="list of NAME=VALUE"):
        Overrides.coerce("M_SF_Nm=0.02")


def test_out_of_range_override_is_refused_when_applied():
    with pytest.raises(ParameterError, match=r"M_SF_Nm = 20.0 is outside the allowed range"):
        Overrides.of(M_SF_Nm=20.0).apply(get("paper2010"))


# ---- claims -----------------------------------------------------------------------------------
def _runs(**values):
    return {k: SimpleNamespace(key=k, ok=True, scenario=object(), summary={}, derived={"x": v})
            for k, v in values.items()}


def _claim(checks, fallback=(), **kw):
    return Claim(key="k", figure="Fig. 0", statement="s", paper="p", scenarios=("a", "b"),
                 measure=lambda runs: {"a": runs[0].derived["x"], "b": runs[1].derived["x"]},
                 shows=lambda v: f"{v['a']} / {v['b']}", checks=checks, fallback=fallback, **kw)


SMALLER = Check("b < a", lambda v: v["b"] < v["a"])
HALF = Check("b < a / 2", lambda v: v["b"] < v["a"] / 2)


@pytest.mark.parametrize("a,b,verdict", [(10, 4, Verdict.YES), (10, 6, Verdict.PARTLY), (10, 12, Verdict.NO)])
def test_verdict_all_some_none(a, b, verdict):
    out = _claim((SMALLER, HALF)).evaluate(_runs(a=a, b=b))
    assert out.verdict is verdict and out.shows == f"{a} / {b}"
    assert out.failed == tuple(c.text for c in (SMALLER, HALF) if not c.test({"a": a, "b": b}))


def test_fallback_gives_partly_and_no_checks_only_reports():
    loose = Check("b < 2 a", lambda v: v["b"] < 2 * v["a"])
    assert _claim((HALF,), (loose,)).evaluate(_runs(a=10, b=12)).verdict is Verdict.PARTLY
    assert _claim((HALF,), (loose,)).evaluate(_runs(a=10, b=30)).verdict is Verdict.NO
    assert _claim(()).evaluate(_runs(a=1, b=2)).verdict is Verdict.REPORTED


def test_a_claim_without_its_runs_is_not_run():
    assert _claim((SMALLER,)).evaluate(_runs(a=10)).verdict is Verdict.NOT_RUN
    failed = _runs(a=10, b=4)
    failed["b"].ok = False
    assert _claim((SMALLER,)).evaluate(failed).verdict is Verdict.NOT_RUN


def test_the_report_row_follows_the_criterion():
    strict, lenient = _claim((HALF,)), _claim((SMALLER,))
    runs = _runs(a=10, b=6)
    rows = {c: claims_table([c.evaluate(runs)])[4] for c in (strict, lenient)}
    assert "| 10 / 6 | no | criterion: b < a / 2 |" in rows[strict]
    assert "| 10 / 6 | yes | criterion: b < a |" in rows[lenient]
    gap = _claim((HALF,), known_gap="why it fails")
    assert "known not to hold: why it fails" in claims_table([gap.evaluate(runs)])[4]
    assert "not run" in claims_table([strict.evaluate({})])[-2]


# ---- JSON ---------------------------------------------------------------------------------------
def test_json_numbers_lose_float_noise_but_keep_the_clock():
    obj = {"reached_s": [6.2170000000000005, 18.541000000000004, 79.999999999], "bad": math.nan,
           "n": np.int64(3), "x": np.float32(0.5), "flag": np.bool_(True), "arr": np.array([0.1 + 0.2])}
    out = json_ready(obj)
    assert out == {"reached_s": [6.217, 18.541, 79.999999999], "bad": None, "n": 3, "x": 0.5, "flag": True,
                   "arr": [0.3]}
    json.dumps(out)


@given(st.integers(0, 10**12))
def test_json_keeps_every_whole_nanosecond_below_1000_s(ticks):
    t = ticks * 1e-9
    assert json_ready(t) == float(f"{t:.9f}")


# ---- findings: computed, not written ----------------------------------------------------------------
def _rows(ind: float, coop: float, **changes):
    """A table with every reading at (ind, coop) seconds, three segments each."""
    rows = []
    for rd in READINGS:
        i, c = changes.get(rd.key, (ind, coop))
        rows.append({"key": rd.key, "reading": rd.label, "topic": rd.topic, "independent_s": i, "cooperative_s": c,
                     "cooperative_overshoot_deg": 0.2, "reduction": None if i is None or c is None else (i - c) / i,
                     "independent_reached_s": [i / 3] * 3 if i else None, "cooperative_reached_s": [c / 3] * 3 if c else None,
                     "cooperative_shared_with_baseline": rd.cooperative is None, "interlock_violations": 0})
    return rows


def test_findings_follow_the_numbers():
    half = "\n".join(F.findings(_rows(18.5, 14.7)))
    assert "readings with both times within 20% of the paper's: none" in half
    assert "18.5 s (independent) and 14.7 s (co-operative; 13 of 13 finish): 49% and 53% of the paper's" in half
    assert "below the paper's 27%" in half and "inside the 15%-40% band" in half
    close = "\n".join(F.findings(_rows(36.0, 26.0, Tamb60=(37.0, 27.0))))
    assert "ambient and initial 60 degC (the authors' 2020 model) 37.0 s / 27.0 s (27%): both times within 20%" in close
    assert "below the paper's" not in close and "outside the" not in close
    never = "\n".join(F.findings(_rows(18.5, 14.7, **{"tol0.1": (20.8, None)})))
    assert "within 0.1 deg: the co-operative cycle does not finish within 80 s" in never
