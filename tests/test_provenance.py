"""Issue 13: every output says how it was made, a run can be made again from it exactly,
and physically absurd results carry warnings."""

import json

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.io import loadmat

from smafinger import __version__, simulate
from smafinger.engine.run import make_spec, run_spec
from smafinger.parameters import get
from smafinger.export import PARQUET_KEY, read_provenance, sidecar_path
from smafinger.plausibility import OVERHEAT_MARGIN_C, STRESS_RATING_PA, austenite_finish_C, check, wire_strain
from smafinger.provenance import (ProvenanceError, definition_hash, provenance, run_definition,
                                  spec_from_definition, spec_from_provenance)


# ---- run definitions ---------------------------------------------------------------------------
@pytest.mark.parametrize("args, kw", [
    (("paper2010", "cooperative", "0:-25,reach:-55:both,reach:-40"), {}),
    (("authors2020", "independent", "0:-25:upper,5:-40:none"), dict(independent_wait=False, tol_deg=0.1)),
    (("paper2010-table2", "open-loop", None, "0:8:0,6:0:0"), dict(dt_s=5e-4, method="euler")),
    (("linear-bias-spring", "open-loop", None, "0:0.25,3:0"), dict(drive="duty", tol_m=1e-4)),
    (("linear-bias-spring", "open-loop", None, "0:0.2,2:0"), dict(drive="current")),
    (("paper2010", "cooperative", "0:-25"), dict(method="exponential", dt_s=5e-3, pwm="averaged")),
    (("paper2010", "cooperative", "0:-25"), dict(controller="sliding-mode")),
    (("paper2010", "independent", "0:-25"), dict(controller="resistance")),
])
def test_a_definition_rebuilds_the_same_spec(args, kw):
    spec = make_spec(*args, t_end_s=4.0, **kw)
    record = json.loads(json.dumps(provenance(spec)))  # through JSON text, as written
    assert record["smafinger_version"] == __version__
    assert spec_from_provenance(record) == spec
    assert record["run_sha256"] == definition_hash(run_definition(spec))


@given(h0=st.floats(0.0, 1e4), msf=st.floats(0.0, 1.0), t_end=st.integers(1, 10_000).map(lambda k: k * 1e-3),
       target=st.floats(-55.0, -25.0))
@settings(max_examples=40, deadline=None)
def test_any_overridden_set_round_trips_exactly(h0, msf, t_end, target):
    p = get("paper2010").replace(h0_heating_W_m2K=h0, M_SF_Nm=msf)
    spec = make_spec(p, "cooperative", f"0:{target!r}", t_end_s=t_end, output_interval_s=t_end)
    again = spec_from_definition(json.loads(json.dumps(run_definition(spec))))
    assert again == spec and again.params.h0_heating_W_m2K == h0


def test_an_edited_definition_is_refused():
    record = json.loads(json.dumps(provenance(make_spec("paper2010", "cooperative", "0:-25", t_end_s=1.0))))
    record["run"]["parameters"]["M_SF_Nm"] = 0.02
    with pytest.raises(ProvenanceError, match="does not match run_sha256"):
        spec_from_provenance(record)
    for broken, message in [({"schema": 99}, "schema 99"), ({**record["run"], "dt_s": "fast"}, "dt_s = 'fast'"),
                            ({k: v for k, v in record["run"].items() if k != "method"}, "missing method"),
                            ({**record["run"], "drive": [1]}, r"drive = \[1\]")]:
        with pytest.raises(ProvenanceError, match=message):
            spec_from_definition(broken)


def test_a_recorded_run_whose_step_was_unstable_is_refused_saying_its_results_are_wrong():
    """A stiff slider's run recorded at rk4 1 ms (before such steps were refused: it went unstable,
    held by the end stops, and its results are wrong): --from refuses it, and its advice is one
    --from can follow (the step's own advice, --dt, is refused with --from; found by review)."""
    p = get("linear-bias-spring").replace(wire_length_m=0.1, slider_mass_kg=0.005)
    definition = run_definition(make_spec(p, "open-loop", voltage="0:0.1", drive="duty", t_end_s=1.0))
    assert definition["dt_s"] == 1.25e-4
    with pytest.raises(ProvenanceError, match=r"run: dt_s = 0.001 is beyond rk4's stability limit .*, so the recorded "
                                              r"run went unstable and its results are wrong .* without --from"):
        spec_from_definition({**definition, "dt_s": 1e-3}, "--from old.json: run")


# ---- the outputs carry it ------------------------------------------------------------------------
def test_every_signal_format_and_the_summary_carry_the_provenance(tmp_path):
    r = simulate("paper2010", "cooperative", "0:-25", t_end_s=1.0, output_interval_s=0.01)
    want = provenance(r.spec)
    for name in ("r.csv", "r.parquet", "r.mat"):
        r.save(tmp_path / name)
    r.write_summary(tmp_path / "s.json")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv", "r.mat", "r.parquet", "r.provenance.json", "s.json"]
    assert sidecar_path(tmp_path / "r.csv") == tmp_path / "r.provenance.json"
    assert list(pd.read_csv(tmp_path / "r.csv").columns) == r.column_names  # plain CSV: readable as is
    assert json.loads(pq.read_schema(tmp_path / "r.parquet").metadata[PARQUET_KEY]) == want
    assert list(pd.read_parquet(tmp_path / "r.parquet").columns) == r.column_names
    mat = loadmat(tmp_path / "r.mat", squeeze_me=True)
    assert str(mat["provenance"]["run_sha256"][()]) == want["run_sha256"]
    assert str(mat["provenance"]["smafinger_version"][()]) == __version__
    np.testing.assert_array_equal(mat["theta_deg"]["signals"][()]["values"][()], r.theta_deg)
    summary = json.loads((tmp_path / "s.json").read_text())
    assert summary["provenance"] == want and summary["warnings"] == []
    for name in ("r.csv", "r.provenance.json", "r.parquet", "r.mat", "s.json"):
        assert read_provenance(tmp_path / name)["run_sha256"] == want["run_sha256"]
        assert spec_from_provenance(read_provenance(tmp_path / name)) == r.spec


def test_the_same_run_makes_the_same_bytes(tmp_path):
    r = simulate("authors2020", "cooperative", "0:-25,reach:-40", t_end_s=3.0)
    again = run_spec(spec_from_provenance(read_provenance_of(r, tmp_path)))
    for i, res in enumerate((r, again)):
        for suffix in (".csv", ".parquet", ".mat"):
            res.save(tmp_path / f"{i}{suffix}")
    for suffix in (".csv", ".provenance.json", ".parquet", ".mat"):
        assert (tmp_path / f"0{suffix}").read_bytes() == (tmp_path / f"1{suffix}").read_bytes(), suffix


def read_provenance_of(result, folder):
    result.write_summary(folder / "first.json")
    return read_provenance(folder / "first.json")


def _cli(*args) -> None:
    from smafinger.cli import main

    assert main(list(args)) == 0


def test_a_thinned_result_says_so_and_its_re_run_writes_every_sample(tmp_path, monkeypatch):
    """A decimated result's file used to state the run alone, as if it held every sample; a
    re-run from a file that keeps every 10th sample (reproduce's) wrote every sample but copied
    ``samples_every: 10`` into its own provenance and summary (found by review)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SMAFINGER_ENGINE", "compiled")
    r = simulate("paper2010", "cooperative", "0:-25", t_end_s=1.0)
    thin = r.decimated(5).decimated(2)
    assert thin.samples_every == 10 and thin.metrics == r.metrics
    thin.save("thin.csv")
    assert json.loads(sidecar_path("thin.csv").read_text())["samples_every"] == 10
    assert len(pd.read_csv("thin.csv")) == 101
    _cli("simulate", "--from", "thin.csv", "--out", "again.csv", "--summary", "again.json", "--no-progress")
    assert len(pd.read_csv("again.csv")) == 1001
    assert "samples_every" not in json.loads(sidecar_path("again.csv").read_text())
    assert "samples_every" not in json.loads((tmp_path / "again.json").read_text())["provenance"]
    r.save("whole.csv")
    assert "samples_every" not in json.loads(sidecar_path("whole.csv").read_text())


def test_a_scenario_re_run_from_its_mat_file_is_the_same_file(tmp_path, monkeypatch):
    """The MATLAB file's provenance gave back the run alone: a re-run from it lost the
    scenario's name, and so its bytes differed from the first file's (found by review)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SMAFINGER_ENGINE", "compiled")
    _cli("simulate", "--scenario", "fig11-controller-on-v1", "--t-end", "1", "--out", "s.mat", "--no-progress")
    assert read_provenance(tmp_path / "s.mat")["scenario"] == "fig11-controller-on-v1"
    _cli("simulate", "--from", "s.mat", "--out", "again.mat", "--no-progress")
    assert (tmp_path / "s.mat").read_bytes() == (tmp_path / "again.mat").read_bytes()


def test_files_without_a_definition_are_refused(tmp_path):
    (tmp_path / "x.json").write_text('{"segments": []}')
    (tmp_path / "y.csv").write_text("t_s\n0\n")
    (tmp_path / "z.parquet").write_bytes(b"PAR1 not really")
    for name, message in [("x.json", "holds no smafinger run definition"), ("y.csv", "holds no smafinger"),
                          ("z.parquet", "cannot be read"), ("nope.json", "no such file")]:
        with pytest.raises(ProvenanceError, match=message):
            read_provenance(tmp_path / name)


# ---- plausibility --------------------------------------------------------------------------------
def test_equations_of_the_checks():
    assert austenite_finish_C(np.array([0.0, 10.3e6]), 110.0, 10.3e6).tolist() == [110.0, 111.0]
    eps = wire_strain(np.array([0.0, 75e6, 28e6]), np.array([1.0, 0.0, 1.0]), 75e9, 28e9, 0.023)
    np.testing.assert_allclose(eps, [0.023, 1e-3, 0.024])


def test_absurd_drive_and_spring_give_warnings_sane_runs_none():
    hot = simulate("paper2010", "open-loop", voltage="0:100:0", t_end_s=3.0)
    (w,) = hot.metrics["warnings"]
    assert w.startswith("upper wire: 1252 degC") and "above its austenite finish temperature" in w
    stiff = simulate(resolve_with("spring_K_N_m=1e6"), "open-loop", voltage="0:8:0", t_end_s=2.0)
    texts = " | ".join(stiff.metrics["warnings"])
    assert "upper wire: stress" in texts and "lower wire: stress" in texts and "beyond the recoverable strain" in texts
    for run in (simulate("paper2010", "cooperative", "0:-25,reach:-55,reach:-40", t_end_s=30.0),
                simulate("authors2020", "independent", "0:-25:upper,5:-55:both", t_end_s=20.0),
                simulate("linear-bias-spring", "open-loop", voltage="0:8,10:0", t_end_s=20.0)):
        assert run.metrics["warnings"] == [], run.metrics["warnings"]
        assert run.summary()["warnings"] == []


def test_thresholds_are_applied_at_their_values():
    r = simulate("paper2010", "open-loop", voltage="0:8:0", t_end_s=2.0)
    assert check(r) == []
    peak_over = float(np.max(r.T_upper_C - austenite_finish_C(r.sigma_upper_Pa, 110.0, 10.3e6)))
    assert peak_over < OVERHEAT_MARGIN_C and float(np.max(r.sigma_upper_Pa)) < STRESS_RATING_PA


def test_values_no_wire_has_are_warned_of():
    """xi outside [0, 1] and a wire in compression were returned without a word (found by review)."""
    p = get("linear-bias-spring").replace(hysteresis="authors2020")
    r = simulate(p, "cooperative", "0:0.0058", t_end_s=10.0, controller="sliding-mode", method="authors-ode4",
                 dt_s=1e-3)
    assert float(np.max(r.xi_wire)) > 1.2
    assert any(w.startswith("wire wire: xi = 1.2") and "outside [0, 1]" in w and "do not clip" in w
               for w in r.metrics["warnings"]), r.metrics["warnings"]
    from types import SimpleNamespace

    from smafinger.plausibility import COMPRESSION_PA, _impossible_wire

    t = np.linspace(0.0, 1.0, 3)
    for least, expected in ((COMPRESSION_PA * 0.99, 0), (COMPRESSION_PA * 1.01, 1)):
        out = _impossible_wire(SimpleNamespace(signal=lambda name: np.full(3, 30.0)), p, "wire", np.zeros(3),
                               np.array([4e7, least, 4e7]), np.full(3, 50.0), t)
        assert len(out) == expected and all("the wire pushes" in w for w in out)


def test_a_temperature_nothing_can_reach_is_warned_of_at_its_threshold():
    from types import SimpleNamespace

    from smafinger.plausibility import COLD_MARGIN_C, _impossible_wire

    p = get("paper2010")  # no latent heat
    t = np.linspace(0.0, 1.0, 5)
    floor = min(p.T_amb_C, p.T_init_C) - COLD_MARGIN_C
    for wire_min, casing_min, expected in ((floor + 0.01, floor + 0.01, 0), (floor - 0.01, floor + 0.01, 1),
                                           (floor + 2.0, floor - 0.01, 1), (floor - 0.01, floor - 2.0, 2)):
        T = np.array([p.T_init_C, 60.0, wire_min, 40.0, 30.0])
        casing = np.array([p.T_amb_C, 25.0, casing_min, 23.0, 22.5])
        result = SimpleNamespace(signal=lambda name, c=casing: c)
        out = _impossible_wire(result, p, "upper", np.zeros(5), np.zeros(5), T, t)
        assert len(out) == expected, (wire_min, casing_min, out)
        assert all("numerical instability" in w for w in out)


def test_a_heating_resistance_that_is_not_the_wires_is_warned_of():
    """A changed wire_diameter_m alone kept the 0.5 mm wire's 4.1 ohm/m in Eq. (11): a 0.25 mm
    wire heated with 5x the power its resistance gives, without a word (found by review)."""
    from smafinger.plausibility import RESISTANCE_MISMATCH, _resistance_mismatch

    rig = get("linear-bias-spring")
    (w,) = _resistance_mismatch(rig.replace(wire_diameter_m=0.25e-3))
    assert w.startswith("resistance_ohm_per_m = 4.1 ohm/m heats the wire") and "(5.07x)" in w
    assert _resistance_mismatch(rig) == []  # 1.27x
    from smafinger.model.build import build_model
    from smafinger.model.resistance import resistivity

    wire = build_model(rig).wires[0]
    per_m = resistivity.py_func(wire, rig.T_init_C, rig.xi_init) / wire.area_m2  # Eq. R1 at the start, ohm/m
    assert per_m / 4.1 == pytest.approx(1.268, abs=1e-3)
    assert _resistance_mismatch(rig.replace(resistance_ohm_per_m=per_m / (RESISTANCE_MISMATCH * 0.999))) == []
    assert len(_resistance_mismatch(rig.replace(resistance_ohm_per_m=per_m / (RESISTANCE_MISMATCH * 1.001)))) == 1
    r = simulate(rig.replace(wire_diameter_m=0.25e-3), "open-loop", voltage="0:0.3,1:0", drive="duty", t_end_s=2.0)
    assert any(x.startswith("resistance_ohm_per_m") for x in r.metrics["warnings"])


def resolve_with(*overrides):
    return get("paper2010").with_overrides(list(overrides))


def test_no_scenario_of_the_paper_gives_a_warning():
    from smafinger.paper import scenarios

    for s in scenarios.all_scenarios():
        r = run_spec(s.spec())
        assert r.metrics["warnings"] == [], (s.name, r.metrics["warnings"])


def test_sweep_run_ids_take_any_number_of_wires_and_keep_the_joint_text():
    from smafinger.analysis.sweep_spec import canonical_run, run_id

    joint = make_spec("paper2010-table2", "open-loop", None, "0:8:0,8:0:0", t_end_s=1.0)
    assert canonical_run(joint)["voltage"] == "0.0:8.0:0.0,8.0:0.0:0.0"  # the text run ids were made from
    rig = make_spec("linear-bias-spring", "open-loop", None, "0:8,2:0", t_end_s=3.0)
    assert canonical_run(rig)["voltage"] == "0.0:8.0,2.0:0.0" and len(run_id(rig)) == 16


def test_a_given_resistance_calibration_is_part_of_the_run(tmp_path):
    """The resistance controller's calibration is what maps resistance to position: a run's
    definition holds it, so a re-run uses it (before, a calibration given through the API was
    left out, the re-run calibrated anew and ran differently under the same hash; found by
    review). A definition written before holds none and re-runs calibrating anew, as it did."""
    import dataclasses

    from smafinger.control.calibration import calibrate
    from smafinger.control.params import ResistanceFeedbackParameters

    p = get("paper2010")
    cal = calibrate(p)
    custom = dataclasses.replace(cal, c0=cal.c0 + 0.1)
    spec = make_spec(p, "cooperative", "0:-25", t_end_s=2.0,
                     controller=ResistanceFeedbackParameters(calibration=custom))
    record = json.loads(json.dumps(provenance(spec)))
    assert record["run"]["controller"]["calibration"]["c0"] == custom.c0
    again = spec_from_provenance(record)
    assert again == spec and again.controller.calibration == custom
    np.testing.assert_array_equal(run_spec(again).theta_deg, run_spec(spec).theta_deg)
    # as a definition without the calibration was written: the hash of the rest
    old = json.loads(json.dumps(provenance(make_spec(p, "cooperative", "0:-25", t_end_s=2.0, controller="resistance"))))
    del old["run"]["controller"]["calibration"]
    old["run_sha256"] = definition_hash(old["run"])
    assert spec_from_provenance(old).controller.calibration == cal
    old["run"]["controller"]["K_P_per_q"] = 123.0  # an edited one is still refused
    with pytest.raises(ProvenanceError, match="does not match run_sha256"):
        spec_from_provenance(old)
