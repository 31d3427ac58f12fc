"""MATLAB files out (write_mat) and round trips back through read_recording, CSV and .mat."""

import math

import numpy as np
import pandas as pd
import pytest
import scipy.io as sio
from hypothesis import given, settings
from hypothesis import strategies as st

import smafinger
from smafinger.recordings import RecordingError, matlab_name, read_recording, write_mat


def signals(n=50):
    t = np.arange(n) * 1e-3
    return t, {"duty": 0.5 * (np.arange(n) % 3 == 0), "theta_deg": -40 + 10 * t, "T_upper_C": 25 + 100 * t}


def test_structure_with_time_reads_back_exactly(tmp_path):
    t, sig = signals()
    f = tmp_path / "out.mat"
    names = write_mat(f, t, sig, {"command": "smafinger simulate --params paper2010"})
    assert names == {"duty": "duty", "theta_deg": "theta_deg", "T_upper_C": "T_upper_C"}
    rec = read_recording(f, {"T_C": "T_upper_C"})
    np.testing.assert_array_equal(rec.input.t_s, t)
    np.testing.assert_array_equal(rec.input.values, sig["duty"])
    np.testing.assert_array_equal(rec.output.values, sig["theta_deg"] * (math.pi / 180))
    np.testing.assert_array_equal(rec.T_C.values, sig["T_upper_C"])
    assert rec.meta["provenance"] == {"smafinger_version": smafinger.__version__,
                                      "command": "smafinger simulate --params paper2010"}
    assert rec.meta["labels"]["T_upper_C"] == "T_upper_C"


def test_file_has_simulinks_layout_as_matlab_sees_it(tmp_path):
    """Read with loadmat's defaults (MATLAB's view: every field a 2-D array)."""
    t, sig = signals(20)
    f = tmp_path / "out.mat"
    write_mat(f, t, sig)
    assert f.read_bytes()[:19] == b"MATLAB 5.0 MAT-file"
    m = sio.loadmat(f)
    th = m["theta_deg"][0, 0]
    assert th["time"].shape == (20, 1) and th["signals"][0, 0]["values"].shape == (20, 1)
    assert th["signals"][0, 0]["dimensions"][0, 0] == 1
    assert th["signals"][0, 0]["label"][0] == "theta_deg" and th["blockName"][0] == "smafinger"
    np.testing.assert_array_equal(th["signals"][0, 0]["values"][:, 0], sig["theta_deg"])
    assert sorted(k for k in m if not k.startswith("__")) == ["T_upper_C", "duty", "provenance", "theta_deg"]


def test_table_layout_reads_back(tmp_path):
    t, sig = signals()
    f = tmp_path / "table.mat"
    write_mat(f, t, {"V_upper_V": 8.0 * sig["duty"], "theta_deg": sig["theta_deg"]}, layout="table",
              table_name="run 1")
    m = sio.loadmat(f, squeeze_me=True, struct_as_record=False)
    assert set(m["run_1"]._fieldnames) == {"time", "V_upper_V", "theta_deg"}
    rec = read_recording(f, {"voltage_V": "V_upper_V"})
    np.testing.assert_array_equal(rec.input.values, 8.0 * sig["duty"])
    np.testing.assert_array_equal(rec.output.t_s, t)


def test_provenance_holds_strings_numbers_and_nested_structs(tmp_path):
    t, sig = signals(5)
    f = tmp_path / "p.mat"
    write_mat(f, t, {"duty": sig["duty"], "theta_deg": sig["theta_deg"]},
              {"params": {"h0": 20.0, "name": "paper2010", "gains": [3000, 3000, 50]}, "seed": 7,
               "interlock": True, "smafinger_version": "custom", "out file": tmp_path / "x.csv"})
    prov = read_recording(f).meta["provenance"]
    assert prov["params"] == {"h0": 20.0, "name": "paper2010", "gains": [3000.0, 3000.0, 50.0]}
    assert prov["seed"] == 7 and prov["smafinger_version"] == "custom"
    assert prov["interlock"] == 1  # a MATLAB logical; scipy reads it back as uint8
    assert prov["out_file"] == str(tmp_path / "x.csv")


@pytest.mark.parametrize("name, ident", [
    ("theta_deg", "theta_deg"), ("T_upper_C", "T_upper_C"), ("omega (deg/s)", "omega__deg_s_"),
    ("2nd", "x2nd"), ("_x", "x_x"), ("end", "end_"), ("", "x"), ("é", "x_"), ("a" * 80, "a" * 63),
])
def test_matlab_names_are_valid_identifiers(name, ident):
    assert matlab_name(name) == ident


BAD_WRITES = [
    (dict(path="out.txt"), "must end in .mat"),
    (dict(layout="wide"), "layout 'wide' is not one of signals, table"),
    (dict(t_s=[0.0, 0.0, 1.0]), "t_s[1] = 0.0 must be finite and after the previous time"),
    (dict(t_s=[0.0, np.nan, 1.0]), "t_s[1] = nan"),
    (dict(signals={"duty": [0.1, 0.2]}), "signal 'duty' has shape (2,), expected (3,)"),
    (dict(signals={"duty": ["a", "b", "c"]}), "signal 'duty' is not numeric"),
    (dict(signals={"a-b": [0, 0, 0], "a_b": [1, 1, 1]}), "signals 'a-b' and 'a_b' both make the MATLAB name 'a_b'"),
    (dict(signals={"provenance": [0, 0, 0]}), "signal 'provenance' would be named 'provenance', which is taken"),
    (dict(signals={"time": [0, 0, 0]}, layout="table"), "signal 'time' would be named 'time'"),
    (dict(signals={}), "non-empty dict"),
    (dict(provenance={"x": None}), "provenance.x = None is not a string, a number or a numeric list"),
    (dict(provenance={"p": {"deep": object}}), "provenance.p.deep"),
    (dict(provenance={"big": 2**60}), "too large for a MATLAB double"),
]


@pytest.mark.parametrize("change, fragment", BAD_WRITES)
def test_bad_writes_are_refused_and_write_nothing(tmp_path, change, fragment):
    args = dict(path="out.mat", t_s=[0.0, 0.5, 1.0], signals={"duty": [0.1, 0.2, 0.3]}, provenance=None)
    args.update(change)
    args["path"] = tmp_path / args["path"]
    with pytest.raises(RecordingError) as info:
        write_mat(**args)
    assert fragment in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_a_failed_write_keeps_the_old_file_and_leaves_nothing(tmp_path, monkeypatch):
    t, sig = signals(10)
    f = tmp_path / "out.mat"
    write_mat(f, t, sig)
    before = f.read_bytes()

    def broken_savemat(fh, mdict, **kw):
        fh.write(b"MATLAB 5.0 half")
        raise OSError("disk full")

    monkeypatch.setattr(sio, "savemat", broken_savemat)
    with pytest.raises(OSError, match="disk full"):
        write_mat(f, t, {"duty": np.zeros(10)})
    assert f.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["out.mat"]


# ---- round-trip properties -------------------------------------------------------------------
@st.composite
def runs(draw):
    n = draw(st.integers(2, 40))
    steps = draw(st.lists(st.floats(1e-6, 5.0), min_size=n - 1, max_size=n - 1))
    t = np.unique(draw(st.floats(0.0, 1e3)) + np.concatenate([[0.0], np.cumsum(steps)]))
    t = t if t.size >= 2 else np.array([0.0, 1.0])
    k = t.size
    duty = np.array(draw(st.lists(st.floats(0.0, 1.0), min_size=k, max_size=k)))
    theta = np.array(draw(st.lists(st.floats(-180.0, 180.0), min_size=k, max_size=k)))
    return t, duty, theta


@settings(max_examples=60, deadline=None)
@given(runs(), st.sampled_from(["signals", "table"]))
def test_any_run_round_trips_through_mat_exactly(tmp_path_factory, run, layout):
    t, duty, theta = run
    f = tmp_path_factory.mktemp("rt") / "run.mat"
    write_mat(f, t, {"duty": duty, "theta_deg": theta}, layout=layout)
    rec = read_recording(f)
    np.testing.assert_array_equal(rec.input.t_s, t)
    np.testing.assert_array_equal(rec.output.t_s, t)
    np.testing.assert_array_equal(rec.input.values, duty)
    np.testing.assert_array_equal(rec.output.values, theta * (math.pi / 180))


@settings(max_examples=60, deadline=None)
@given(runs(), st.integers(1, 5))
def test_any_run_round_trips_through_csv_exactly(tmp_path_factory, run, every):
    """Written by pandas (shortest round-trip decimals), the output only every few rows."""
    t, duty, theta = run
    f = tmp_path_factory.mktemp("rt") / "run.csv"
    sparse = np.where(np.arange(t.size) % every == 0, theta, np.nan)
    sparse[-1] = theta[-1]
    pd.DataFrame({"t_s": t, "duty": duty, "theta_deg": sparse}).to_csv(f, index=False)
    rec = read_recording(f)
    np.testing.assert_array_equal(rec.input.t_s, t)
    np.testing.assert_array_equal(rec.input.values, duty)
    keep = ~np.isnan(sparse)
    np.testing.assert_array_equal(rec.output.t_s, t[keep])
    np.testing.assert_array_equal(rec.output.values, theta[keep] * (math.pi / 180))
