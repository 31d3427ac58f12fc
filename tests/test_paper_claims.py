"""The paper's claims, asserted on the outputs of the named scenarios.

Every scenario runs once (module fixture, about 5 s in all once numba's cache is warm) at
the scenarios' own settings (1 ms step and output), and every claim of
:func:`smafinger.paper.scenarios.claims` is evaluated on those runs exactly as
``smafinger reproduce`` evaluates it for ``report.md``: the criterion is written in the
claim, not here. A claim the model is known not to reproduce (``claim.known_gap``) is
asserted as the paper states it and marked ``xfail(strict=True)``: it is reported, not
bent, and the marker goes (by deleting ``known_gap``) if the model ever reproduces it.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from smafinger import scenarios
from smafinger.engine.run import run_spec
from smafinger.paper import sec31
from smafinger.paper.claim import Verdict
from smafinger.paper.derived import Run, derive

CLAIMS = scenarios.claims()


@pytest.fixture(scope="module")
def runs():
    out = {}
    for s in scenarios.all_scenarios():
        r = run_spec(s.spec())
        out[s.name] = Run(s.name, r.spec, r, r.summary(), derive(s.derive, r), scenario=s)
    return out


def _as_param(claim):
    marks = [pytest.mark.xfail(strict=True, reason=claim.known_gap)] if claim.known_gap else []
    return pytest.param(claim, id=claim.key, marks=marks)


# ---- the claims -------------------------------------------------------------------------------
@pytest.mark.parametrize("claim", [_as_param(c) for c in CLAIMS if c.checks])
def test_claim_holds(runs, claim):
    outcome = claim.evaluate(runs)
    assert outcome.verdict is Verdict.YES, outcome.explain()


@pytest.mark.parametrize("claim", CLAIMS, ids=[c.key for c in CLAIMS])
def test_claim_reads_every_one_of_its_runs(runs, claim):
    have = claim.available(runs)
    expected = len(claim.scenarios) if claim.scenarios else len(runs)
    assert have is not None and len(have) == expected + len(claim.also)
    outcome = claim.evaluate(runs)
    assert outcome.verdict is not Verdict.NOT_RUN and outcome.shows


def test_claims_are_well_formed():
    keys = [c.key for c in CLAIMS]
    assert len(keys) == len(set(keys))
    names = set(scenarios.names())
    for c in CLAIMS:
        assert set(c.scenarios) <= names and set(c.also) <= names, c.key
        assert c.figure and c.statement and c.paper, c.key
        assert not c.known_gap or c.checks, f"{c.key}: a known gap needs a criterion that fails"


# ---- registry -----------------------------------------------------------------------------
def test_registry_names_are_versioned_and_cite_a_figure():
    names = scenarios.names()
    assert len(names) == len(set(names)) >= 40
    for n in names:
        s = scenarios.get(n)
        assert re.search(r"-v[0-9]+$", n) and s.name == n, n
        assert s.figure and s.description
    for required in ("fig8-h0-60-upper-v1", "fig10a-two-node-v1", "fig11-controller-off-v1", "fig11-controller-off-v2",
                     "fig15-independent-v1", "fig15-independent-v2", "fig15-independent-scheduled-v2",
                     "fig15-cooperative-v1", "authors2020-profile1-v1", "authors2020-profile2-v1"):
        assert required in names


def test_unknown_scenario_names_the_known_ones():
    with pytest.raises(ValueError, match="unknown scenario 'fig99-v1'.*fig15-cooperative-v1"):
        scenarios.get("fig99-v1")


def test_spec_applies_overrides_after_the_scenarios_own():
    s = scenarios.get("fig8-h0-60-upper-v1")
    spec = s.spec(overrides=["M_SF_Nm=0.02"], dt_s=5e-4, output_interval_s=1e-2, tol_deg=0.2, hold_s=1.0)
    assert spec.params.h0_heating_W_m2K == 60.0 and spec.params.h0_cooling_W_m2K == 60.0
    assert spec.params.M_SF_Nm == 0.02
    assert (spec.dt_s, spec.output_interval_s, spec.tol_deg, spec.hold_s) == (5e-4, 1e-2, 0.2, 1.0)
    assert scenarios.get("fig11-controller-off-v1").spec().params.controller_in_cooling is False
    assert scenarios.get("fig11-controller-on-v1").spec().params.controller_update_s == 0.01


@pytest.mark.parametrize("wire", ["upper", "lower"])
def test_fig8_varies_h0_over_the_figures_values(wire):
    assert [s.value for s in sec31.FIG8.scenarios() if s.wire == wire] == [60.0, 65.0, 70.0]


def test_open_loop_voltage_and_spring_lengths_come_from_the_parameter_set():
    table2 = sec31.TABLE2
    s = scenarios.get("fig8-h0-60-upper-v1")
    assert s.voltage == "0:V_H:0,20:0:0"  # the run's own V_H (paper.scenario.V_H)
    assert s.spec().voltage.steps == ((0.0, table2.V_H_V, 0.0), (20.0, 0.0, 0.0))
    middle = [s for s in sec31.SPRINGS["upper"].scenarios() if s.wire == "upper"][1]
    assert middle.spec().params.spring_length_upper_m == table2.spring_length_upper_m


# ---- Sec. 2.6: the interlock, every run -------------------------------------------------------
@pytest.mark.parametrize("name", scenarios.names())
def test_zero_interlock_violations(runs, name):
    assert runs[name].summary["interlock_violations"] == 0


# ---- Fig. 15: the cycle time and the cycles themselves --------------------------------------------
@pytest.mark.parametrize("name", ["fig15-independent-v1", "fig15-cooperative-v1"])
def test_fig15_on_reach_cycle_time_is_the_sum_of_reached_s(runs, name):
    run = runs[name]
    assert run.derived["cycle_s"] is not None
    assert run.derived["cycle_s"] == pytest.approx(sum(s["reached_s"] for s in run.summary["segments"]), abs=1e-6)
    n = len(run.summary["segments"])
    assert run.derived["elapsed_s"] == pytest.approx(run.derived["cycle_s"] + (n - 1) * run.spec.hold_s, abs=1e-6)


@pytest.mark.parametrize("name", [n for n in scenarios.names() if n.startswith("fig15-")])
def test_fig15_cycles_visit_every_target(runs, name):
    segs = runs[name].summary["segments"]
    assert [s["target_deg"] for s in segs][-1] == -40.0
    assert all(s["reached_s"] is not None for s in segs), [s["reached_s"] for s in segs]


@pytest.mark.parametrize("name", ["fig15-independent-v2", "fig15-independent-scheduled-v2"])
def test_fig15_independent_v2_uses_only_the_agonist(runs, name):
    """Sec. 4.1: one actuator at a time, the other "simply works as a bias spring": the upper wire
    for the extension and its return, the lower one for the flexion and its return."""
    r = runs[name].result
    seg = r.signal("segment")
    for wire, own in (("upper", (0, 1)), ("lower", (2, 3))):
        other, mine = ~np.isin(seg, own), np.isin(seg, own)
        assert np.all(r.signal(f"enabled_{wire}")[other] == 0.0) and np.all(r.signal(f"duty_{wire}")[other] == 0.0)
        assert not mine.any() or r.signal(f"duty_{wire}")[mine].max() > 0.0  # (its segments may not have started)
    assert np.isin(seg, (0, 1)).any()


def test_fig15_v1_independent_uses_the_antagonist_for_the_return(runs):
    """What -v2 corrects: the v1 schedule enables the lower wire (once the upper one is back to
    martensite) for what should be the upper wire's passive return to -40 deg."""
    r = runs["fig15-independent-scheduled-v1"].result
    back = r.signal("segment") == 1
    assert np.any(r.signal("enabled_lower")[back] == 1.0) and r.signal("duty_lower")[back].mean() > 0.0
    assert np.all(r.signal("enabled_upper")[back] == 0.0)


def test_heating_value_rule_is_one_damping_coefficient():
    s = scenarios.get("fig13-extension-case1-v1")
    rule = run_spec(s.spec(["damping_switch=heating-value"]))
    one = run_spec(s.spec([f"C_DF_cooling_Nms={s.parameters().C_DF_heating_Nms}"]))
    assert np.array_equal(rule.signal("theta_deg"), one.signal("theta_deg"))


def test_every_figure_draws(runs, tmp_path):
    for f in scenarios.FIGURES:
        f.plot([runs[s.name] for s in f.scenarios], f.title, tmp_path / f"{f.key}.png")
        assert (tmp_path / f"{f.key}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", f.key
