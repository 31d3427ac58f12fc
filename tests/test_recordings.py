"""Reading bench recordings: CSV, Parquet and MATLAB (Simulink) files, mappings, and refusals."""

import math

import numpy as np
import pandas as pd
import pytest
import scipy.io as sio

from smafinger.recordings import (
    MappingError, Recording, RecordingError, Series, SignalMap, Source, parse_map_options, read_recording,
)


# ---- helpers ----------------------------------------------------------------------------------
def write_csv(path, columns: dict[str, list[str]]):
    """A CSV from columns of cell texts (all of one length); '' is an empty cell."""
    names = list(columns)
    n = len(columns[names[0]])
    lines = [",".join(names)] + [",".join(columns[c][i] for c in names) for i in range(n)]
    path.write_text("\n".join(lines) + "\n")
    return path


def base_columns(n=10):
    return {
        "t_s": [repr(0.1 * i) for i in range(n)],
        "duty": [repr(0.05 * i) for i in range(n)],
        "theta_deg": [repr(-40.0 + i) for i in range(n)],
    }


def simulink(t, values, block="model/To Workspace", label=""):
    """A 'Structure With Time' variable as Simulink's To Workspace block saves it."""
    values = np.asarray(values, dtype=float)
    values = values[:, None] if values.ndim == 1 else values
    return {"time": np.asarray(t, dtype=float)[:, None],
            "signals": {"values": values, "dimensions": float(values.shape[1]), "label": label, "blockName": block},
            "blockName": block}


def refusal(path, mapping=None):
    with pytest.raises(RecordingError) as info:
        read_recording(path, mapping)
    msg = str(info.value)
    assert "\n" not in msg, "one line"
    assert str(path) in msg, "names the file"
    return msg


# ---- CSV ----------------------------------------------------------------------------------
def test_csv_canonical_columns_read_in_si(tmp_path):
    f = write_csv(tmp_path / "run.csv", base_columns())
    rec = read_recording(f)
    assert isinstance(rec, Recording) and rec.file == str(f)
    assert rec.input_kind == "duty" and rec.output_name == "theta_rad"
    np.testing.assert_array_equal(rec.input.t_s, [0.1 * i for i in range(10)])
    np.testing.assert_array_equal(rec.input.values, [0.05 * i for i in range(10)])
    np.testing.assert_array_equal(rec.output.values, [math.radians(-40.0 + i) for i in range(10)])
    assert rec.T_C is None and rec.resistance_ohm is None
    assert rec.meta["format"] == "csv" and rec.meta["sources"] == {"duty": "duty", "theta_deg": "theta_deg"}


def test_csv_slow_signal_keeps_its_own_times(tmp_path):
    """A 1 kHz duty and a 100 Hz position in one file: the position leaves 9 cells in 10 empty."""
    n = 100
    cols = {"t_s": [repr(i * 1e-3) for i in range(n)],
            "voltage_V": [repr(8.0 * (i % 7 < 3)) for i in range(n)],
            "position_m": [repr(1e-4 * i) if i % 10 == 0 else "" for i in range(n)],
            "T_C": [repr(25.0 + i) if i % 20 == 0 else "" for i in range(n)]}
    rec = read_recording(write_csv(tmp_path / "rates.csv", cols))
    assert rec.input_kind == "voltage_V" and len(rec.input) == n
    np.testing.assert_array_equal(rec.output.t_s, [i * 1e-3 for i in range(0, n, 10)])
    np.testing.assert_array_equal(rec.output.values, [1e-4 * i for i in range(0, n, 10)])
    np.testing.assert_array_equal(rec.T_C.t_s, [i * 1e-3 for i in range(0, n, 20)])


def test_csv_mapping_with_scales_and_time_in_ms(tmp_path):
    cols = {"time_ms": ["0", "10", "20", "30"], "u_pct": ["0", "50", "100", "25"],
            "x_mm": ["0", "1.5", "3", "2"], "R": ["7.9", "7.8", "7.5", "7.6"]}
    f = write_csv(tmp_path / "bench.csv", cols)
    rec = read_recording(f, parse_map_options(
        ["t_s=time_ms*1e-3", "duty=u_pct/100", "position_m=x_mm*1e-3", "resistance_ohm=R"]))
    np.testing.assert_allclose(rec.input.t_s, [0, 0.01, 0.02, 0.03], rtol=1e-15)
    np.testing.assert_allclose(rec.input.values, [0, 0.5, 1.0, 0.25], rtol=1e-15)
    np.testing.assert_allclose(rec.output.values, [0, 1.5e-3, 3e-3, 2e-3], rtol=1e-15)
    assert rec.output.source == "x_mm" and rec.output.scale == 1e-3
    assert rec.resistance_ohm.values.tolist() == [7.9, 7.8, 7.5, 7.6]
    # the dict forms say the same
    same = read_recording(f, {"t_s": "time_ms*1e-3", "duty": ("u_pct", 0.01), "position_m": "x_mm*0.001",
                              "resistance_ohm": "R"})
    np.testing.assert_array_equal(same.output.values, rec.output.values)


def test_csv_mapping_chooses_between_two_inputs(tmp_path):
    cols = base_columns() | {"voltage_V": ["5"] * 10}
    f = write_csv(tmp_path / "two.csv", cols)
    assert "2 inputs found (duty, voltage_V)" in refusal(f)
    assert read_recording(f, {"voltage_V": "voltage_V"}).input_kind == "voltage_V"
    assert read_recording(f, {"duty": "duty"}).input_kind == "duty"


def test_recording_arrays_are_read_only(tmp_path):
    rec = read_recording(write_csv(tmp_path / "run.csv", base_columns()))
    with pytest.raises(ValueError):
        rec.input.values[0] = 1.0
    with pytest.raises(TypeError):
        rec.meta["format"] = "x"


def test_csv_from_excel_bom_crlf_quotes_spaces_and_blank_lines(tmp_path):
    f = tmp_path / "excel.csv"
    f.write_bytes(b'\xef\xbb\xbf"t_s", duty ,theta_deg\r\n0,0.5,-40\r\n0.001, 0.5 ,\r\n\r\n0.002,0.25,-39.5\r\n'
                  b'0.003,0.25,x\r\n')
    msg = refusal(f)
    assert "column 'theta_deg', data row 5 (line 6): 'x' is not a number" in msg  # the blank line counts
    f.write_bytes(f.read_bytes().replace(b"0.003,0.25,x\r\n", b""))
    rec = read_recording(f)
    assert rec.input.t_s.tolist() == [0.0, 0.001, 0.002] and rec.input.values.tolist() == [0.5, 0.5, 0.25]
    assert rec.output.t_s.tolist() == [0.0, 0.002]


# ---- Parquet ----------------------------------------------------------------------------------
def test_parquet_nulls_are_missing_samples(tmp_path):
    n = 50
    t = np.arange(n) * 2e-3
    df = pd.DataFrame({"t_s": t, "current_A": np.full(n, 0.4),
                       "position_m": pd.array([1e-3 * i if i % 5 == 0 else None for i in range(n)], dtype="Float64")})
    f = tmp_path / "run.parquet"
    df.to_parquet(f)
    rec = read_recording(f)
    assert rec.input_kind == "current_A" and rec.output_name == "position_m"
    np.testing.assert_array_equal(rec.output.t_s, t[::5])
    np.testing.assert_array_equal(rec.output.values, [1e-3 * i for i in range(0, n, 5)])


def test_parquet_nan_is_refused_with_its_row(tmp_path):
    pos = np.linspace(0, 1e-3, 8)
    pos[5] = np.nan
    f = tmp_path / "nan.parquet"
    # a float NaN, not a null (pandas would turn NaN into null): write it with pyarrow
    import pyarrow as pa
    import pyarrow.parquet as pq
    pq.write_table(pa.table({"t_s": np.arange(8.0), "duty": np.full(8, 0.3), "position_m": pos}), f)
    msg = refusal(f)
    assert "column 'position_m', row 6" in msg and "nan" in msg


def test_parquet_time_in_ms_and_a_repeated_time(tmp_path):
    f = tmp_path / "ms.parquet"
    pd.DataFrame({"ms": [0, 5, 10, 10, 20], "voltage_V": [0.0, 8, 8, 8, 0], "theta_deg": [-40.0] * 5}).to_parquet(f)
    msg = refusal(f, {"t_s": "ms*1e-3"})
    assert "column 'ms', row 4: time repeats (0.01 s after 0.01 s)" in msg
    pd.DataFrame({"ms": [0, 5, 10, 15], "voltage_V": [0.0, 8, 8, 0], "theta_deg": [-40.0] * 4}).to_parquet(f)
    assert read_recording(f, {"t_s": "ms/1000"}).input.t_s.tolist() == [0.0, 0.005, 0.01, 0.015]
    pd.DataFrame({"t_s": [0.0, 1.0], "duty": ["a", "b"], "theta_deg": [0.0, 0.0]}).to_parquet(f)
    msg = refusal(f)
    assert "column 'duty' holds " in msg and "string, not numbers" in msg


# ---- MATLAB ----------------------------------------------------------------------------------
@pytest.mark.parametrize("oned_as", ["row", "column"])
def test_mat_structure_with_time_of_1d_arrays(tmp_path, oned_as):
    """scipy.io.savemat writes a 1-D array as a 1 x N row: a Structure With Time made of 1-D
    arrays was read as N one-sample signals, and the message listed all of them (20 kB; found
    by review)."""
    t = np.linspace(0.0, 2.0, 901)
    f = tmp_path / "rows.mat"
    sio.savemat(f, {"duty": {"time": t, "signals": {"values": np.full(t.size, 0.25)}},
                    "position_m": {"time": t, "signals": {"values": 1e-3 * t}}}, oned_as=oned_as)
    rec = read_recording(f)
    np.testing.assert_array_equal(rec.input.t_s, t)
    np.testing.assert_array_equal(rec.input.values, np.full(t.size, 0.25))
    np.testing.assert_array_equal(rec.output.values, 1e-3 * t)


def test_a_refusal_lists_a_dozen_names_at_most(tmp_path):
    from smafinger.recordings.reader import LISTED_NAMES

    wide = tmp_path / "wide.csv"  # no time column among 300: the CSV reader's own refusal
    wide.write_text(",".join(f"c{k}" for k in range(300)) + "\n" + ",".join("1" for _ in range(300)) + "\n")
    msg = refusal(wide)
    assert "no time column" in msg and "and 288 more" in msg and len(msg) < 1000

    t = np.linspace(0.0, 1.0, 11)
    f = tmp_path / "many.mat"
    sio.savemat(f, {"tout": t[:, None], **{f"sig{k:03d}": t[:, None] for k in range(200)}})
    msg = refusal(f)
    listed = msg.split("(variables: ")[1].split(" and ")[0].split(", ")
    assert len(listed) == LISTED_NAMES and "and 189 more" in msg and len(msg) < 1000  # 201 variables


@pytest.mark.parametrize("compress", [False, True])
@pytest.mark.parametrize("oned_as", ["row", "column"])
def test_mat_simulink_several_signals_at_different_rates(tmp_path, compress, oned_as):
    t_fast = np.arange(0, 2.0, 1e-3)
    t_slow = np.arange(0, 2.0, 1e-2)
    duty = np.where((t_fast % 0.5) < 0.2, 0.6, 0.0)
    theta = -40 + 5 * np.sin(t_slow)
    T = 30 + 10 * t_slow
    f = tmp_path / "bench.mat"
    sio.savemat(f, {"u_pwm": simulink(t_fast, duty), "theta_deg": simulink(t_slow, theta, "m/angle"),
                    "T_C": simulink(t_slow, T)}, do_compression=compress, oned_as=oned_as)
    rec = read_recording(f, {"duty": "u_pwm"})
    np.testing.assert_array_equal(rec.input.t_s, t_fast)
    np.testing.assert_array_equal(rec.input.values, duty)
    np.testing.assert_array_equal(rec.output.t_s, t_slow)
    np.testing.assert_allclose(rec.output.values, np.radians(theta), rtol=1e-15)
    np.testing.assert_array_equal(rec.T_C.values, T)
    assert rec.meta["block_names"]["theta_deg"] == "m/angle"
    assert set(rec.meta["variables"]) == {"u_pwm", "theta_deg", "T_C"}


def test_mat_one_signal_per_file(tmp_path):
    """Input and output in separate files are each one Structure With Time: read each alone."""
    t = np.arange(0, 1, 1e-3)
    f = tmp_path / "one.mat"
    sio.savemat(f, {"duty": simulink(t, np.full(t.size, 0.25))})
    msg = refusal(f)
    assert "no output variable" in msg and "'duty'" in msg


def test_mat_multi_column_and_struct_array_signals(tmp_path):
    """A mux'ed N x 2 signal and a Scope's struct array are addressed as VAR(k)."""
    t = np.arange(0, 1, 1e-2)
    mux = simulink(t, np.c_[np.full(t.size, 5.0), 1e-3 * t])
    scope = {"time": t[:, None], "signals": np.array(
        [(np.full((t.size, 1), 0.3), "duty"), (10 * t[:, None], "theta")],
        dtype=[("values", object), ("label", object)])[None, :], "blockName": "m/Scope"}
    f = tmp_path / "multi.mat"
    sio.savemat(f, {"mux": mux, "scope": scope})
    rec = read_recording(f, {"voltage_V": "mux(1)", "position_m": "mux(2)"})
    assert rec.input.values[0] == 5.0 and rec.output.values[-1] == pytest.approx(1e-3 * t[-1])
    rec = read_recording(f, {"duty": "scope(1)", "theta_deg": "scope(2)"})
    assert rec.meta["labels"]["scope(2)"] == "theta"
    np.testing.assert_allclose(rec.output.values, np.radians(10 * t), rtol=1e-15)


@pytest.mark.parametrize("fmt", ["4", "5"])
def test_mat_array_format_and_to_file_layout(tmp_path, fmt):
    t = np.linspace(0, 1, 11)
    f = tmp_path / "arr.mat"
    sio.savemat(f, {"volt": np.c_[t, np.full(11, 3.0)], "ang": np.vstack([t, -30 + t])}, format=fmt)
    rec = read_recording(f, {"voltage_V": "volt", "theta_deg": "ang"})
    np.testing.assert_array_equal(rec.input.t_s, t)
    np.testing.assert_allclose(rec.output.values, np.radians(-30 + t), rtol=1e-15)


def test_mat_plain_vectors_take_the_mapped_time_vector(tmp_path):
    t = np.arange(0, 0.5, 0.01)
    f = tmp_path / "vec.mat"
    sio.savemat(f, {"tout": t * 1e3, "duty": np.full(t.size, 0.5), "theta_deg": -40 + t})
    rec = read_recording(f, {"t_s": "tout*1e-3"})
    np.testing.assert_allclose(rec.output.t_s, t, rtol=1e-15)
    assert "no time vector 't_s'" in refusal(f)


@pytest.mark.parametrize("layout", ["array", "simulink", "table"])
def test_mat_signals_with_their_own_time_and_a_mapped_time(tmp_path, layout):
    """[time, value] arrays, Structures With Time and table-like structs carry their own time,
    read in seconds as saved. A mapped t_s that gives the same times is fine; one that does not
    (the times saved in ms and t_s=t_ms*1e-3, or a name that is not there) used to be ignored,
    leaving the times 1000x too long; now the signal is refused, naming both."""
    t_ms = np.arange(0.0, 100.0, 10.0)
    duty, theta = np.full(t_ms.size, 0.3), -40 + 0.1 * t_ms
    f = tmp_path / f"{layout}.mat"
    if layout == "array":
        variables = {"duty": np.c_[t_ms, duty], "theta_deg": np.c_[t_ms, theta]}
    elif layout == "simulink":
        variables = {"duty": simulink(t_ms, duty), "theta_deg": simulink(t_ms, theta)}
    else:
        variables = {"run": {"time": t_ms[:, None], "duty": duty[:, None], "theta_deg": theta[:, None]}}
    sio.savemat(f, {**variables, "t_ms": t_ms[:, None], "t_same": t_ms[:, None]})
    np.testing.assert_array_equal(read_recording(f).input.t_s, t_ms)  # as saved
    np.testing.assert_array_equal(read_recording(f, {"t_s": "t_same"}).input.t_s, t_ms)
    for mapping, got in (("t_ms*1e-3", "t_s=t_ms*0.001 (10 times from 0 to 0.09 s)"),
                         ("nonexistent/1000", "t_s=nonexistent*0.001 (no time vector")):
        msg = refusal(f, {"t_s": mapping})
        assert "with its own time (10 samples from 0 to 90 s" in msg and got in msg, msg
        assert "remove t_s from the mapping" in msg


def test_mat_two_column_signals_not_time_value_are_refused_with_a_mapped_time(tmp_path):
    """An N x 2 matrix of two signals ([duty, position], Simulink's 'Array' format) with the time
    in tout: its first column was read as the time (a ramp of duty passes as increasing times)."""
    tout = np.linspace(0.0, 1.0, 21)
    f = tmp_path / "two.mat"
    sio.savemat(f, {"tout": tout[:, None], "sig": np.c_[np.linspace(0, 0.5, 21), np.linspace(0, 2e-3, 21)],
                    "duty": np.linspace(0, 0.5, 21)[:, None]})
    msg = refusal(f, {"t_s": "tout", "position_m": "sig"})
    assert "variable 'sig': is an N x 2 [time, value] array" in msg and "t_s=tout" in msg


def test_mat_two_by_two_matrix_is_refused_as_ambiguous(tmp_path):
    f = tmp_path / "tiny.mat"
    sio.savemat(f, {"duty": np.array([[0.0, 0.01], [0.2, 0.3]]), "theta_deg": np.c_[[0.0, 0.01, 0.02], [1, 2, 3]]})
    assert "2 x 2 matrix" in refusal(f)


def test_mat_provenance_and_other_variables(tmp_path):
    t = np.arange(0, 1, 0.1)
    f = tmp_path / "prov.mat"
    sio.savemat(f, {"duty": simulink(t, np.full(t.size, 0.1)), "theta_deg": simulink(t, -40 + t),
                    "provenance": {"rig": "finger-2", "supply_V": 8.0}, "notes": "warm day"})
    rec = read_recording(f)
    assert rec.meta["provenance"] == {"rig": "finger-2", "supply_V": 8.0}
    assert rec.meta["ignored"] == ("notes",)


# ---- mapping syntax ----------------------------------------------------------------------------
def test_map_options_parse_and_print_back():
    smap = parse_map_options(["position_m=x_mm*1e-3", "duty = u_pct/100", "theta_deg=angle*-1", "t_s=t"])
    assert smap.get("position_m") == Source("x_mm", 1e-3)
    assert smap.get("duty") == Source("u_pct", 0.01)
    assert smap.get("theta_deg") == Source("angle", -1.0)
    assert smap.source("T_C") == Source("T_C", 1.0)
    assert parse_map_options(smap.to_options()) == smap
    assert SignalMap.from_dict({"position_m": ("x*mm", 2.0)}).get("position_m").name == "x*mm"


@pytest.mark.parametrize("option, fragment", [
    ("position_m", "expected NAME=SOURCE"),
    ("pos=x", "'pos' is not a signal name"),
    ("duty=", "source column/variable name is empty"),
    ("duty=u*abc", "'abc' after '*'"),
    ("duty=u*0", "must be a finite non-zero number"),
    ("duty=u/inf", "must be a finite non-zero number"),
])
def test_bad_map_options_are_refused(option, fragment):
    with pytest.raises(MappingError) as info:
        parse_map_options([option])
    assert fragment in str(info.value)


def test_map_twice_and_bad_dict_values_are_refused():
    with pytest.raises(MappingError, match="mapped twice"):
        parse_map_options(["duty=a", "duty=b"])
    with pytest.raises(MappingError, match="scale 'x' is not a number"):
        SignalMap.from_dict({"duty": ("u", "x")})
    with pytest.raises(MappingError, match="scale True is not a number"):
        SignalMap.from_dict({"duty": ("u", True)})
    # numpy's numbers are numbers (np.float32 was refused; found by an API fuzz)
    assert SignalMap.from_dict({"duty": ("u", np.int64(100))}).get("duty").scale == 100.0
    assert SignalMap.from_dict({"duty": ("u", np.float32(0.5))}).get("duty").scale == 0.5
    with pytest.raises(MappingError, match="neither"):
        SignalMap.from_dict({"duty": 3})


# ---- refusals ----------------------------------------------------------------------------------
CSV_BAD_CELLS = [
    # (column, data row, new cell, message fragments)
    ("t_s", 5, "0.3", ["column 't_s', data row 5 (line 6)", "goes back", "increase strictly"]),
    ("t_s", 5, "0.30000000000000004", ["column 't_s', data row 5 (line 6)", "repeats"]),
    ("t_s", 3, "inf", ["column 't_s', data row 3 (line 4)", "finite"]),
    ("duty", 7, "nan", ["column 'duty', data row 7 (line 8)", "finite"]),
    ("theta_deg", 2, "-inf", ["column 'theta_deg', data row 2 (line 3)", "finite"]),
    ("duty", 4, "abc", ["column 'duty', data row 4 (line 5)", "'abc' is not a number"]),
    ("duty", 6, "1.5", ["column 'duty', data row 6 (line 7)", "outside [0, 1]"]),
    ("duty", 1, "-0.1", ["column 'duty', data row 1 (line 2)", "outside [0, 1]"]),
    ("theta_deg", 9, "181", ["column 'theta_deg', data row 9 (line 10)", "outside [-180, 180] deg"]),
    ("t_s", 8, "", ["column 't_s', data row 8 (line 9)", "time is empty but column 'duty' has a value"]),
]


@pytest.mark.parametrize("column, row, cell, fragments", CSV_BAD_CELLS)
def test_csv_bad_cells_are_refused_naming_column_and_row(tmp_path, column, row, cell, fragments):
    cols = base_columns()
    cols[column][row - 1] = cell
    msg = refusal(write_csv(tmp_path / "bad.csv", cols))
    for frag in fragments:
        assert frag in msg


RANGE_CASES = [
    # (canonical column, values, fragments): each file also has t_s and the other role's signal
    ("duty", [0, 50, 100, 20], ["column 'duty', data row 2 (line 3)", "looks like percent",
                                "--map duty=duty*0.01"]),
    ("voltage_V", [0, 8, 120, 0], ["column 'voltage_V', data row 3 (line 4)", "outside [0, 100] V"]),
    ("voltage_V", [0, 8000, 5000, 0], ["data row 2", "outside [0, 100] V"]),
    ("current_A", [0, 25, 0, 0], ["column 'current_A', data row 2 (line 3)", "outside [0, 20] A"]),
    ("position_m", [0, 0.001, -2.5, 0], ["column 'position_m', data row 3 (line 4)", "outside [-1, 1] m",
                                         "looks like millimetres", "position_m=position_m*0.001"]),
    ("theta_deg", [-40, -200, 0, 0], ["column 'theta_deg', data row 2 (line 3)", "outside [-180, 180] deg"]),
    ("T_C", [25, 30, 500, 40], ["column 'T_C', data row 3 (line 4)", "outside [-50, 400] degC"]),
    ("T_C", [25, -60, 30, 40], ["column 'T_C', data row 2 (line 3)"]),
    ("resistance_ohm", [8, 0, 8, 8], ["column 'resistance_ohm', data row 2 (line 3)", "outside (0, 10000] ohm"]),
    ("resistance_ohm", [8, 8, 8, 2e4], ["column 'resistance_ohm', data row 4 (line 5)", "outside (0, 10000]"]),
]


@pytest.mark.parametrize("column, values, fragments", RANGE_CASES)
def test_implausible_units_are_refused(tmp_path, column, values, fragments):
    cols = {"t_s": ["0", "1", "2", "3"], "duty": ["0.5"] * 4, "theta_deg": ["0"] * 4}
    if column in ("voltage_V", "current_A"):
        del cols["duty"]
    if column == "position_m":
        del cols["theta_deg"]
    cols[column] = [repr(float(v)) for v in values]
    msg = refusal(write_csv(tmp_path / f"{column}.csv", cols))
    for frag in fragments:
        assert frag in msg
    assert ("looks like" in msg) == any("looks like" in frag for frag in fragments)


def test_percent_hint_scale_composes_with_a_mapped_scale(tmp_path):
    cols = {"t_s": ["0", "1", "2"], "u": ["0", "5000", "10000"], "theta_deg": ["0"] * 3}
    msg = refusal(write_csv(tmp_path / "u.csv", cols), {"duty": "u*0.01"})
    assert "column 'u', data row 2 (line 3)" in msg and "--map duty=u*0.0001" in msg
    assert "after the mapping's scale 0.01" in msg


FILE_CASES = [
    # (file name, columns or None for special content, mapping, fragments)
    ("no_time.csv", {"time": ["0", "1"], "duty": ["0", "0"], "theta_deg": ["0", "0"]}, None,
     ["no time column 't_s'", "'time'", "--map t_s="]),
    ("no_input.csv", {"t_s": ["0", "1"], "theta_deg": ["0", "0"]}, None,
     ["no input column", "duty, voltage_V, current_A", "'theta_deg'"]),
    ("no_output.csv", {"t_s": ["0", "1"], "duty": ["0", "0"]}, None, ["no output column", "position_m, theta_deg"]),
    ("two_outputs.csv", {"t_s": ["0", "1"], "duty": ["0", "0"], "position_m": ["0", "0"], "theta_deg": ["0", "0"]},
     None, ["2 outputs found (position_m, theta_deg)", "say which with a mapping"]),
    ("two_mapped.csv", {"t_s": ["0", "1"], "a": ["0", "0"], "b": ["0", "0"], "theta_deg": ["0", "0"]},
     {"duty": "a", "voltage_V": "b"}, ["the mapping names 2 inputs (duty, voltage_V)"]),
    ("one_sample.csv", {"t_s": ["0", "1"], "duty": ["0.1", ""], "theta_deg": ["0", "0"]}, None,
     ["column 'duty'", "1 sample(s)", "at least 2"]),
    ("missing_column.csv", {"t_s": ["0", "1"], "duty": ["0", "0"], "theta_deg": ["0", "0"]},
     {"position_m": "x_mm*1e-3"}, ["mapping position_m=x_mm*0.001: no column 'x_mm'", "'theta_deg'"]),
    ("dup.csv", None, None, ["column 'duty' appears 2 times"]),
    ("semicolon.csv", None, None, ["looks separated by ';'"]),
    ("empty.csv", None, None, ["the file is empty"]),
    ("ragged.csv", None, None, ["not a readable CSV file", "line 3"]),
    ("run.xlsx", None, None, ["unknown format '.xlsx'", ".csv"]),
    ("broken.parquet", None, None, ["not a readable Parquet file"]),
    ("broken.mat", None, None, ["not a readable MATLAB file"]),
    ("v73.mat", None, None, ["MATLAB v7.3 (HDF5)", "-v7"]),
]
SPECIAL = {
    "dup.csv": "t_s,duty,duty,theta_deg\n0,0,0,0\n1,0,0,0\n",
    "semicolon.csv": "t_s;duty;theta_deg\n0;0;0\n1;0;0\n",
    "empty.csv": "",
    "ragged.csv": "t_s,duty,theta_deg\n0,0,0\n1,0,0,7\n",
    "run.xlsx": "PK\x03\x04",
    "broken.parquet": "PAR1 this is not parquet",
    "broken.mat": "MATLAB 5.0 MAT-file, but then garbage" + "\x00" * 200,
}


@pytest.mark.parametrize("name, columns, mapping, fragments", FILE_CASES)
def test_files_that_do_not_fit_are_refused(tmp_path, name, columns, mapping, fragments):
    f = tmp_path / name
    if columns is not None:
        write_csv(f, columns)
    elif name == "v73.mat":  # the 128-byte header of an HDF5-based MAT-file (version 0x0200)
        f.write_bytes(b"MATLAB 7.3 MAT-file, Platform: GLNXA64".ljust(116) + b"\x00" * 8 + b"\x00\x02IM"
                      + b"\x00" * 384)
    else:
        f.write_text(SPECIAL[name])
    msg = refusal(f, mapping)
    for frag in fragments:
        assert frag in msg


def test_missing_file_and_directory_are_refused(tmp_path):
    assert "file not found" in refusal(tmp_path / "nope.csv")
    (tmp_path / "dir.csv").mkdir()
    assert "not a file" in refusal(tmp_path / "dir.csv")


@pytest.mark.parametrize("compress", [False, True])
def test_truncated_mat_files_are_refused(tmp_path, compress):
    t = np.arange(100.0)
    whole = tmp_path / "whole.mat"
    sio.savemat(whole, {"duty": simulink(t, np.full(100, 0.1)), "theta_deg": simulink(t, -40 + 0 * t)},
                do_compression=compress)
    data = whole.read_bytes()
    for cut in range(0, len(data) - 1, max(1, len(data) // 40)):
        f = tmp_path / f"cut{cut}.mat"
        f.write_bytes(data[:cut])
        refusal(f)


MAT_CASES = [
    # (variables, mapping, fragments)
    ({"duty": {"time": np.zeros((0, 0)), "signals": {"values": np.ones((5, 1))}},
      "theta_deg": simulink(np.arange(5.0), np.zeros(5))}, None,
     ["variable 'duty'", "has no time", "Structure With Time"]),
    ({"duty": simulink([0, 1, 1, 2], [0.1] * 4), "theta_deg": simulink(np.arange(4.0), np.zeros(4))}, None,
     ["variable 'duty', sample 3", "repeats"]),
    ({"duty": simulink([0, 2, 1, 3], [0.1] * 4), "theta_deg": simulink(np.arange(4.0), np.zeros(4))}, None,
     ["variable 'duty', sample 3", "goes back"]),
    ({"duty": simulink(np.arange(4.0), [0.1, 0.2, np.nan, 0.1]),
      "theta_deg": simulink(np.arange(4.0), np.zeros(4))}, None, ["variable 'duty', sample 3", "finite"]),
    ({"duty": simulink(np.arange(4.0), [0.1, 0.2, 0.3, 0.1]),
      "theta_deg": simulink(np.arange(4.0), [0, 0, 0, 300])}, None,
     ["variable 'theta_deg', sample 4", "outside [-180, 180] deg"]),
    ({"duty": simulink([0.0], [0.1]), "theta_deg": simulink(np.arange(4.0), np.zeros(4))}, None,
     ["variable 'duty'", "1 sample(s)"]),
    ({"duty": simulink(np.arange(4.0), np.full(4, 0.1)), "voltage_V": np.c_[np.arange(4.0), np.ones(4)],
      "theta_deg": simulink(np.arange(4.0), np.zeros(4))}, None, ["2 inputs found (duty, voltage_V)"]),
    ({"u": np.ones((3, 3, 3)), "theta_deg": simulink(np.arange(4.0), np.zeros(4))}, {"duty": "u"},
     ["variable 'u'", "not a signal"]),
    ({"theta_deg": simulink(np.arange(4.0), np.zeros(4))}, None, ["no input variable", "'theta_deg'"]),
]


@pytest.mark.parametrize("variables, mapping, fragments", MAT_CASES)
def test_mat_files_that_do_not_fit_are_refused(tmp_path, variables, mapping, fragments):
    f = tmp_path / "bad.mat"
    sio.savemat(f, variables)
    msg = refusal(f, mapping)
    for frag in fragments:
        assert frag in msg, msg


def test_mat_time_and_values_of_different_lengths(tmp_path):
    f = tmp_path / "len.mat"
    bad = simulink(np.arange(5.0), np.zeros(5))
    bad["signals"]["values"] = np.zeros((4, 1))
    sio.savemat(f, {"duty": bad, "theta_deg": simulink(np.arange(4.0), np.zeros(4))})
    msg = refusal(f)
    assert "variable 'duty'" in msg and "time has 5 samples but signals.values has 4 rows" in msg


def test_series_checks_its_own_samples():
    with pytest.raises(RecordingError, match="sample 2: time repeats"):
        Series("duty", [0.0, 0.0, 1.0], [0.1, 0.2, 0.3])
    with pytest.raises(RecordingError, match="1 sample"):
        Series("duty", [0.0], [0.1])
    with pytest.raises(RecordingError, match="sample 3: value is nan"):
        Series("duty", [0.0, 1.0, 2.0], [0.1, 0.2, np.nan])
    with pytest.raises(RecordingError, match="output 'theta_deg' is not one of"):
        Recording("f", Series("duty", [0, 1], [0, 0]), Series("theta_deg", [0, 1], [0, 0]))
