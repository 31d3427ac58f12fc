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

from smafinger.paper.scenario import V_H
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
    (dict(T_init_C=10 ** 400), "override T_init_C = 1000000000000000000000000000000000000000: not a finite"),
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
    # one string is a list of one, as everywhere a list belongs (smafinger.values.one_or_many)
    assert Overrides.coerce("M_SF_Nm=0.02") == Overrides.coerce(["M_SF_Nm=0.02"])


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


# ---- studies: one change per variant ------------------------------------------------------------
def test_study_variants_change_only_what_they_name():
    from smafinger.paper import studies
    from smafinger.scenarios import get as scenario

    keys = [k for k, _ in studies.tasks()]
    assert len(keys) == len(set(keys))
    for study in studies.STUDIES:
        for v in study.variants:
            for name in study.scenarios:
                if not v.applies(name):
                    continue
                base, spec = scenario(name).spec(), v.spec(name)
                now = spec.params.to_dict()
                changed = {k for k, x in base.params.to_dict().items() if now[k] != x}
                assert changed <= {k for k, _ in v.overrides.params}, (v.key, name, changed)
                assert all(now[k] == (x.label if hasattr(x, "label") else x) for k, x in v.overrides.params)
                assert spec.dt_s == (v.dt_s or base.dt_s) and spec.profile == base.profile


def test_one_cdf_variant_is_one_coefficient():
    from smafinger.paper import studies

    for which, ov in studies.ONE_CDF.items():
        p = ov.apply(get("paper2010"))
        assert p.C_DF_heating_Nms == p.C_DF_cooling_Nms == studies.C_DF[which]


# ---- the studies' findings: computed, not written ---------------------------------------------------
def _brief(move, ret, final):
    return {"move_s": move, "return_s": ret, "return_settle_s": None, "final_deg": final}


def test_hysteresis_findings_count_what_the_step_recovers():
    from smafinger.paper.cycle_findings import hysteresis_findings

    table = [{"scenario": "a", "deadband": _brief(5.0, 7.0, -40.05), "as-specified": _brief(5.0, None, -41.3),
              "dt0.1ms": _brief(5.0, 6.3, -40.15), "algebraic": _brief(5.0, 6.6, -40.0)},
             {"scenario": "b", "deadband": _brief(5.0, 7.0, -39.9), "as-specified": _brief(5.0, 6.9, -39.95)}]
    text = "\n".join(hysteresis_findings(table))
    assert "Reached before the change (dead band, 1 ms): 4 targets. Not reached after it at 1 ms: 1 (`a` move 2)" in text
    assert "Of the 1 of these run at 0.1 ms, 1 are reached." in text
    assert "at most 0.10 deg from -40 deg before the change, 1.30 deg after it at 1 ms, 0.15 deg at 0.1 ms" in text
    assert "what the change broke at 1 ms is the step" in text
    table[0]["dt0.1ms"] = _brief(5.0, None, -41.0)
    text = "\n".join(hysteresis_findings(table))
    assert "what the change broke" not in text and "1 of the 1 targets lost at 1 ms and run at 0.1 ms" in text


def test_hysteresis_findings_compare_the_two_steps_target_by_target():
    from smafinger.paper.cycle_findings import hysteresis_findings

    table = [{"scenario": "a", "as-specified": _brief(5.0, 6.30, -40.0), "dt0.1ms": _brief(5.001, 6.32, -40.0)},
             {"scenario": "b", "as-specified": _brief(4.0, None, -41.0), "dt0.1ms": _brief(4.0, 3.0, -40.0)},
             {"scenario": "c", "as-specified": _brief(4.0, 3.0, -40.0)}]
    text = "\n".join(hysteresis_findings(table))
    assert ("3 targets reached at both, their reach times 1.0 ms apart at the median and at most 20.0 ms (`a` move 2); "
            "reached at one step only: `b` move 2.") in text
    assert "`c`" not in text
    text = "\n".join(hysteresis_findings([{k: v for k, v in row.items() if k != "dt0.1ms"} for row in table]))
    assert "The 1 ms step against 0.1 ms" not in text


def _cycle(key, reach, sched):
    row = {"key": key, "reading": key, "short": key}
    for kind, (i, c) in (("reach", reach), ("schedule", sched)):
        row.update({f"{kind}_independent_s": i, f"{kind}_cooperative_s": c,
                    f"{kind}_reduction": None if i is None or c is None else (i - c) / i})
    return row


def test_cycle_findings_follow_the_numbers():
    from smafinger.paper.cycle_findings import cycle_findings

    table = [_cycle("as-specified", (25.3, 14.7), (37.0, 23.9)), _cycle("enabled", (19.4, 14.7), (34.1, 23.9)),
             _cycle("cdf-heating", (19.4, 14.7), (34.1, 23.9)), _cycle("cdf-cooling", (26.3, 57.3), (35.9, 22.8))]
    text = "\n".join(cycle_findings(table))
    # the issue's numbers: 24% with one C_DF, 42% with the switching; in seconds 4.7 of 10.6 s
    assert "| 25.3 s / 14.7 s (42%); the authors' enable rule 19.4 s / 14.7 s (24%)"[2:] in text
    assert ("Of the 10.6 s the co-operative cycle saves with the switching, 5.9 s (56%) come from the switching "
            "itself: with one C_DF it saves 4.7 s.") in text
    assert "The co-operative cycle is the same under the set's heating-phase switching" in text
    assert "The enable rule gives exactly the one-C_DF times" in text
    assert "Both cycle times within 20% of the paper's: as-specified on the 10 s schedule" in text
    assert "Closest co-operative time to the paper's 27.5 s: 23.9 s (as-specified, on the 10 s schedule)" in text
    table[2] = _cycle("cdf-heating", (19.4, 15.0), (34.1, 23.9))
    assert "is the same under" not in "\n".join(cycle_findings(table)).split("on the 10 s schedule (independent")[0]


def test_move_findings_pick_the_closest_definition():
    from smafinger.paper.cycle_findings import move_findings

    def row(strategy, end, times):
        return {"variant": "as-specified", "variant_label": "as specified", "variant_short": "as specified",
                "strategy": strategy, "end": end,
                "ends": end, "moves_s": times, "paper_per_move_s": 0.0,
                "mean_s": None if None in times else sum(times) / len(times)}

    moves = [row("independent", "reached", [6.0, 7.0, 5.0, 7.0]), row("independent", "rest", [9.0, 9.5, 9.0, 9.9]),
             row("cooperative", "reached", [6.0, 5.0, 4.0]), row("cooperative", "settled", [6.0, None, 6.0])]
    text = "\n".join(move_findings(moves, [_cycle("as-specified", (None, None), (37.0, 23.9))]))
    assert "Independent (paper: 9.38 s per move): closest mean 9.35 s (rest; as specified); 1 of 2" in text
    assert "Co-operative (paper: 9.17 s per move): closest mean 5.00 s (reached; as specified); 0 of 1" in text
    assert "37.5 = 3 x 10 + 7.5 and 27.5 = 2 x 10 + 7.5, the same 7.5 s last move for both" in text
    assert "smafinger's last moves end 7.0 s and 3.9 s into their 10 s" in text


@pytest.mark.parametrize("name", ["fig8-h0-65-upper-v1", "sec31-vh-8.5-lower-v1", "fig10a-two-node-v1"])
def test_open_loop_scenarios_drive_at_the_runs_own_v_h(name):
    """The open-loop scenarios drive a wire at the set's V_H. Their programs were written with
    Table II's 8 V when the module was imported, so '--set V_H_V=4' was recorded in the run's
    parameters and changed nothing it did (found by review: the same energy to the last digit)."""
    from smafinger import scenarios

    s = scenarios.get(name)
    assert V_H in s.voltage
    base = s.spec()
    levels = {v for step in base.voltage.steps for v in step[1:] if v}
    assert levels == {base.params.V_H_V}
    four = s.spec(overrides=["V_H_V=4"])
    assert four.params.V_H_V == 4.0 and {v for step in four.voltage.steps for v in step[1:] if v} == {4.0}


def test_the_h2_claim_is_not_shown_without_h0s_runs():
    """Its third check ("h2 changes the range less than h0 does") passed when h0's runs were not
    selected, and the report then said the known gap "should go" (found by review)."""
    from smafinger.paper import scenarios

    claim = next(c for c in scenarios.claims() if c.key == "h2-upper")
    v = {"range_deg": [18.0, 16.0, 14.0], "start_s": [4.0, 5.0, 6.0], "h0_spread_deg": None}
    assert [c.test(v) for c in claim.checks] == [True, True, False]
    assert [c.test({**v, "h0_spread_deg": 5.0}) for c in claim.checks] == [True, True, True]


def test_fig13_asks_that_the_antagonist_pulls():
    """Case 2's faster return came from the damping rule with the antagonist never transforming,
    and was marked 'yes' (found by review): a check now needs the antagonist to transform."""
    from smafinger.paper import scenarios

    for key in ("fig13-extension", "fig13-flexion"):
        claim = next(c for c in scenarios.claims() if c.key == key)
        v = {"case1": 5.6, "case2": 3.0, "antagonist_xi_min": 1.0}
        assert [c.test(v) for c in claim.checks] == [True, False]
        assert [c.test({**v, "antagonist_xi_min": 0.9}) for c in claim.checks] == [True, True]
        assert "damping" in claim.known_gap


def test_a_move_is_over_when_reached_and_cooled_not_when_cooled_alone():
    """The per-move table compared 'the wires it began partly austenite back to martensite' with
    the paper's move time: 0.0 s for every outward move, which begins all martensite (noticed in
    review). A move now counts as over by that definition when it is reached and cooled."""
    from smafinger.engine.run import simulate
    from smafinger.paper.derived import segment_detail
    from smafinger.paper.issue10 import MOVE_ENDS

    r = simulate("paper2010", profile="0:-30,6:-40", t_end_s=12.0)
    out, back = segment_detail(r, 0), segment_detail(r, 1)
    assert out["cooled_s"] == 0.0 and out["reached_s"] > 1.0 and out["reached_cooled_s"] == out["reached_s"]
    assert back["cooled_s"] > 0.0 and back["reached_cooled_s"] == max(back["reached_s"], back["cooled_s"])
    assert "cooled_s" not in dict(MOVE_ENDS) and "reached_cooled_s" in dict(MOVE_ENDS)


def test_a_claim_whose_run_failed_is_not_reported_as_not_selected():
    """Found by review: a selected run that failed made its claims 'not run (their scenarios were
    not selected)' in the report and on the terminal."""
    from types import SimpleNamespace

    from smafinger.paper import scenarios as scn
    from smafinger.paper.claim import Verdict
    from smafinger.paper.report import claims_table

    claim = next(c for c in scn.claims() if c.scenarios)
    failed = {n: SimpleNamespace(ok=False, scenario=object()) for n in claim.scenarios[:1]}
    o = claim.evaluate(failed)
    assert o.verdict is Verdict.NOT_RUN and o.runs_failed == claim.scenarios[:1]
    unselected = claim.evaluate({})
    assert unselected.verdict is Verdict.NOT_RUN and unselected.runs_failed == ()
    text = "\n".join(claims_table([o, unselected]))
    assert f"1 claim(s) not evaluated because a run failed: {claim.figure}" in text
    assert f"({claim.scenarios[0]} failed)" in text
    assert "1 claim(s) not run (their scenarios were not selected)" in text


def test_the_report_says_which_investigation_runs_failed():
    """A failed run's cells read 'never' in the study tables, like a run that did not finish:
    the report now says which failed above them (found by review)."""
    from types import SimpleNamespace

    from smafinger.paper.report import failed_runs_note

    runs = {"a": SimpleNamespace(ok=True), "cycle:tamb60:fig15-independent-v2": SimpleNamespace(ok=False)}
    note = "\n".join(failed_runs_note(runs))
    assert note.startswith("**1 run(s) failed: cycle:tamb60:fig15-independent-v2.**") and "`never`" in note
    assert failed_runs_note({"a": SimpleNamespace(ok=True)}) == []


def test_numpy_numbers_are_overrides_too():
    """np.float32 and np.int64 were refused as 'not a finite number' (found by an API fuzz)."""
    import numpy as np

    assert Overrides.of(T_init_C=np.float32(60.0)) == Overrides.of(T_init_C=60.0)
    assert dict(Overrides.of(T_init_C=np.int64(60)).params)["T_init_C"] == 60.0
