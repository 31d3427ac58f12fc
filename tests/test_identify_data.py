"""Bad bench data gets one clear line naming the file, the row and the problem; nothing is written."""

import math

import numpy as np
import pytest
from typer.testing import CliRunner

from smafinger.analysis.data import (
    MIN_ROWS_JOINT, MIN_ROWS_KINETICS, DataError, load_angle_curve, load_strain_curve,
)
from smafinger.cli.identify import app


# ---- helpers ----------------------------------------------------------------------------
def strain_rows(n=40):
    """A plausible constant-load cycle: heat 30 -> 140 degC, then cool back."""
    half = n // 2
    T = np.concatenate([np.linspace(30, 140, half), np.linspace(140, 30, n - half)[1:]])
    xi_h = 0.5 * (1 + np.cos(np.pi * np.clip((T[:half] - 80) / 30, 0, 1)))
    xi_c = 0.5 * (1 + np.cos(np.pi * np.clip((T[half:] - 50) / 30, 0, 1)))
    e = 0.04 * np.concatenate([xi_h, xi_c])
    return [f"{t:.3f} {x:.6f} {100 + (i % 3):.2f}" for i, (t, x) in enumerate(zip(T, e))]


def write(path, lines):
    path.write_text("\n".join(lines) + "\n")
    return path


def angle_rows(n=30, voltage=True):
    head = "time_s,angle_deg" + (",voltage_V" if voltage else "")
    rows = [f"{0.1 * i:.2f},{-40 + 0.5 * i:.3f}" + (",5" if voltage else "") for i in range(n)]
    return [head] + rows


def error_of(loader, path):
    with pytest.raises(DataError) as info:
        loader(path)
    msg = str(info.value)
    assert "\n" not in msg, "one line"
    assert str(path) in msg, "names the file"
    return msg


# ---- strain-temperature files -------------------------------------------------------------
def test_good_strain_file_loads_with_header_and_comments(tmp_path):
    rows = strain_rows()
    f = write(tmp_path / "ok.txt", ["# a comment", "temperature strain stress", ""] + rows)
    c = load_strain_curve(f)
    assert c.n == len(rows)
    assert c.T_C[c.split] == pytest.approx(140.0)
    assert c.stress_Pa.mean() == pytest.approx(101e6, rel=0.01)


@pytest.mark.parametrize("row, replacement, expected", [
    (5, "50.0 0.01", "row 5 (line 5): 2 column(s), missing stress"),
    (7, "50.0", "row 7 (line 7): 1 column(s), missing strain, stress"),
    (3, "50.0 0.01 100 7", "row 3 (line 3): 4 columns, expected 3"),
    (9, "50.0 abc 100", "row 9 (line 9): strain 'abc' is not a number"),
    (4, "50,0 0.01 100", "row 4 (line 4): temperature '50,0' is not a number"),
    (6, "nan 0.01 100", "row 6 (line 6): temperature is NaN"),
    (6, "50 0.01 NaN", "row 6 (line 6): stress is NaN"),
    (8, "50 0.01 inf", "row 8 (line 8): stress is infinite"),
    (10, "50 0.01 2500", "row 10 (line 10): stress 2500 MPa is outside the sensible range [0, 1500] MPa"),
    (10, "50 0.01 -20", "row 10 (line 10): stress -20 MPa is outside the sensible range"),
    (2, "500 0.01 100", "row 2 (line 2): temperature 500 degC is outside the sensible range [-100, 300] degC"),
    (2, "-150 0.01 100", "row 2 (line 2): temperature -150 degC is outside"),
    (2, "50 4.1 100", "not in percent"),
])
def test_bad_strain_values(tmp_path, row, replacement, expected):
    rows = strain_rows()
    rows[row - 1] = replacement
    msg = error_of(load_strain_curve, write(tmp_path / "bad.txt", rows))
    assert expected in msg


def test_strain_too_few_points(tmp_path):
    rows = strain_rows(MIN_ROWS_KINETICS - 2)
    msg = error_of(load_strain_curve, write(tmp_path / "short.txt", rows))
    assert f"row {len(rows)}" in msg and "too few points" in msg


def test_strain_must_heat_then_cool(tmp_path):
    rows = [f"{30 + i:.1f} 0.01 100" for i in range(40)]  # heating only
    msg = error_of(load_strain_curve, write(tmp_path / "noheat.txt", rows))
    assert "row 40" in msg and "cooling half" in msg


def test_strain_empty_missing_and_row_counting_skips_comments(tmp_path):
    assert "no data rows" in error_of(load_strain_curve, write(tmp_path / "empty.txt", ["# nothing"]))
    assert "file not found" in error_of(load_strain_curve, tmp_path / "absent.txt")
    rows = strain_rows()
    rows[2] = "50 x 100"
    msg = error_of(load_strain_curve, write(tmp_path / "c.txt", ["# c1", "# c2"] + rows))
    assert "row 3 (line 5)" in msg


# ---- angle-vs-time CSV ---------------------------------------------------------------------
def test_good_angle_file_and_column_aliases(tmp_path):
    c = load_angle_curve(write(tmp_path / "a.csv", angle_rows()))
    assert c.voltage_V is not None and c.t_s.size == 30
    rows = ["t [s], theta (deg)"] + [f"{0.1 * i},{-40}" for i in range(12)]
    c = load_angle_curve(write(tmp_path / "b.csv", rows))
    assert c.voltage_V is None and c.angle_deg[0] == -40


@pytest.mark.parametrize("header, unit, column", [
    ("time_s,angle_rad", "'rad', but the angle is read in deg", "angle_rad"),
    ("time [ms],angle [deg]", "'ms', but the time is read in s", "time [ms]"),
    ("t (min),theta_deg", "'min', but the time is read in s", "t (min)"),
    ("time_s,angle_deg,voltage (mV)", "'mv', but the voltage is read in v", "voltage (mV)"),
])
def test_a_unit_other_than_the_one_read_in_is_refused(tmp_path, header, unit, column):
    """The unit in a header names what the numbers are: 'angle_rad' was read as degrees, and
    'time [ms]' as seconds whenever the times stayed under 600."""
    rows = [header] + [f"{0.1 * i:.2f},{-0.7 + 0.01 * i:.3f},5" for i in range(30)]
    msg = error_of(load_angle_curve, write(tmp_path / "u.csv", rows))
    assert f"line 1: column {column!r} is in {unit}" in msg
    assert load_angle_curve(write(tmp_path / "ok.csv", ["Time [sec],Angle (°),V"] + rows[1:])).t_s.size == 30


@pytest.mark.parametrize("row, replacement, expected", [
    (4, "0.3,", "row 4 (line 5): angle is missing (empty field)"),
    (4, "0.3", "row 4 (line 5): angle column missing"),
    (6, "0.5,abc,5", "row 6 (line 7): angle 'abc' is not a number"),
    (6, "0.5,nan,5", "row 6 (line 7): angle is NaN"),
    (6, "NaN,-30,5", "row 6 (line 7): time is NaN"),
    (6, "0.4,-30,5", "row 6 (line 7): time 0.4 s is not after the previous row's 0.4 s"),
    (6, "0.1,-30,5", "row 6 (line 7): time 0.1 s is not after the previous row's 0.4 s"),
    (1, "-1,-40,5", "row 1 (line 2): time -1 s is negative"),
    (6, "0.5,-400,5", "row 6 (line 7): angle -400 deg is outside the sensible range [-180, 180] deg"),
    (6, "0.5,-30,250", "row 6 (line 7): voltage 250 V is outside the sensible range [0, 100] V"),
    (6, "0.5,-30,-1", "row 6 (line 7): voltage -1 V is outside"),
    (6, "5000,-30,5", "beyond 600 s"),
])
def test_bad_angle_values(tmp_path, row, replacement, expected):
    rows = angle_rows()
    rows[row] = replacement  # rows[0] is the header
    msg = error_of(load_angle_curve, write(tmp_path / "bad.csv", rows))
    assert expected in msg


def test_angle_missing_columns_and_too_few_points(tmp_path):
    msg = error_of(load_angle_curve, write(tmp_path / "h.csv", ["time,volts"] + ["0,1"] * 12))
    assert "line 1: no angle column [deg] in the header (found: 'time', 'volts')" in msg
    msg = error_of(load_angle_curve, write(tmp_path / "n.csv", ["0.0,-40", "0.1,-39"]))
    assert "no time column" in msg and "the first line must be a header" in msg
    rows = angle_rows(MIN_ROWS_JOINT - 1)
    msg = error_of(load_angle_curve, write(tmp_path / "s.csv", rows))
    assert f"row {MIN_ROWS_JOINT - 1} (line {MIN_ROWS_JOINT})" in msg and "too few points" in msg
    assert "empty file" in error_of(load_angle_curve, write(tmp_path / "e.csv", [""]))


@pytest.mark.parametrize("header, extra, expected", [
    ("time_s,angle_deg,supply_V", "", "line 1: column 'supply_V' is not one a curve may have (time: time, t;"),
    ("time_s,angle_deg,voltage,V", ",5", "line 1: column 'V' is a second voltage column (after 'voltage')"),
    ("time [s],angle [deg]", "", "row 1 (line 2): a value in column 3, which the header does not name"),
    ("time [s],angle [deg],", "", "row 1 (line 2): a value in column 3, which the header does not name"),
])
def test_a_column_the_reader_does_not_know_is_refused(tmp_path, header, extra, expected):
    """An unknown column was skipped: a voltage column under another name (or under no name,
    the header one column short) was dropped, and the curve fitted at the default 8 V."""
    rows = [header] + [f"{0.1 * i:.2f},{-40 + i:.1f},5{extra}" for i in range(30)]
    assert expected in error_of(load_angle_curve, write(tmp_path / "x.csv", rows))


def test_a_trailing_comma_and_volts_are_read(tmp_path):
    rows = ["time,angle,volts,"] + [f"{0.1 * i:.2f},{-40 + i:.1f},5," for i in range(30)]
    c = load_angle_curve(write(tmp_path / "ok.csv", rows))
    assert c.voltage_V is not None and np.all(c.voltage_V == 5.0) and c.t_s.size == 30


# ---- CLI: one line on stderr, exit 2, nothing written ----------------------------------------
def _outputs(tmp_path):
    return [str(tmp_path / "fit.toml"), str(tmp_path / "fit.json"), str(tmp_path / "fit.png")]


def test_cli_kinetics_bad_data_writes_nothing(tmp_path):
    good = write(tmp_path / "good.txt", strain_rows())
    rows = strain_rows()
    rows[11] = "50 0.01 nan"
    bad = write(tmp_path / "bad.txt", rows)
    before = sorted(p.name for p in tmp_path.iterdir())
    out, rep, png = _outputs(tmp_path)
    r = CliRunner().invoke(app, ["kinetics", str(good), str(bad), "--out", out, "--report", rep, "--plot", png,
                                 "--no-progress"])
    assert r.exit_code == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and str(bad) in lines[0] and "row 12 (line 12): stress is NaN" in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    # a bad --validate file is refused the same way
    r = CliRunner().invoke(app, ["kinetics", str(good), "--validate", str(bad), "--out", out, "--no-progress"])
    assert r.exit_code == 2 and "row 12" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_cli_joint_bad_data_and_usage_errors_write_nothing(tmp_path):
    good = write(tmp_path / "heat.csv", angle_rows())
    rows = angle_rows(voltage=False)
    rows[9] = "0.05,-30"
    bad = write(tmp_path / "cool.csv", rows)
    nov = write(tmp_path / "nov.csv", angle_rows(voltage=False))
    before = sorted(p.name for p in tmp_path.iterdir())
    out, rep, png = _outputs(tmp_path)
    run = lambda *a: CliRunner().invoke(app, ["joint", *a, "--out", out, "--report", rep, "--plot", png,  # noqa: E731
                                               "--no-progress"])
    r = run("--heating", str(good), "--cooling", str(bad), "--heat-s", "1")
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert str(bad) in r.stderr and "row 9 (line 10): time 0.05 s is not after" in r.stderr
    # cooling curve without voltage column and without --heat-s
    r = run("--heating", str(good), "--cooling", str(nov))
    assert r.exit_code == 2 and "--heat-s" in r.stderr and str(nov) in r.stderr
    # a heating file given as cooling: its voltage never returns to 0
    r = run("--heating", str(good), "--cooling", str(good))
    assert r.exit_code == 2 and "never returns to 0 V" in r.stderr
    # --heat-s count mismatch, heat-s beyond the data, bad output name, bad --params
    assert run("--heating", str(good), "--cooling", str(nov), "--heat-s", "1", "--heat-s", "2").exit_code == 2
    r = run("--heating", str(good), "--cooling", str(nov), "--heat-s", "99")
    assert r.exit_code == 2 and "not before the end" in r.stderr
    r = CliRunner().invoke(app, ["joint", "--heating", str(good), "--cooling", str(nov), "--heat-s", "1",
                                 "--out", str(tmp_path / "fit.txt")])
    assert r.exit_code == 2 and "must end in .toml" in r.stderr
    r = run("--heating", str(good), "--cooling", str(nov), "--heat-s", "1", "--params", "nosuchset")
    assert r.exit_code == 2 and "unknown parameter set" in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_voltage_programs_from_columns_and_heat_s(tmp_path):
    from smafinger.analysis.joint_fit import cooling_program, heating_program

    rows = ["time,angle,voltage"] + [f"{0.5 * i},{-40},{8 if i < 6 else 0}" for i in range(20)]
    c = load_angle_curve(write(tmp_path / "c.csv", rows))
    assert cooling_program(c, 5.0, None).steps == ((0.0, 8.0, 0.0), (3.0, 0.0, 0.0))
    assert cooling_program(c, 8.0, 3.0).steps == ((0.0, 8.0, 0.0), (3.0, 0.0, 0.0))  # --heat-s matching the file
    with pytest.raises(ValueError, match="contradicts the voltage column"):  # it used to win, at 8 V by default
        cooling_program(c, 5.0, 2.5)
    with pytest.raises(DataError, match="switches off at t = 3 s"):  # the end of a heating curve is a cooling
        heating_program(c, 5.0)
    h = load_angle_curve(write(tmp_path / "h.csv", angle_rows(voltage=False)))
    assert heating_program(h, 6.0).steps == ((0.0, 6.0, 0.0),)
    with pytest.raises(ValueError, match="heat_s"):
        cooling_program(h, 5.0, math.nan)


def test_an_angle_curve_must_count_its_time_from_the_switch_on(tmp_path):
    """t = 0 is the switch-on: a curve logged from t = 100 s was read as a 103.5 s heating program
    and fitted to nonsense (heating RMS 11.9 deg for 0.05, exit 0; found by review). Its first row
    may be after 0 by at most its first sampling interval."""
    rows = angle_rows()  # every 0.1 s from 0
    shifted = [rows[0]] + [f"{100 + 0.1 * i:.2f}," + r.split(",", 1)[1] for i, r in enumerate(rows[1:])]
    msg = error_of(load_angle_curve, write(tmp_path / "late.csv", shifted))
    assert "row 1 (line 2): time 100 s of the first row is after 0 by more than the first sampling " \
           "interval (0.1 s)" in msg and "switched on" in msg
    # a curve whose first sample is one interval after the switch-on is fine, a little more is not
    for first, ok in ((0.1, True), (0.05, True), (0.1001, False)):
        late = [rows[0]] + [f"{first + 0.1 * i:.4f}," + r.split(",", 1)[1] for i, r in enumerate(rows[1:])]
        path = write(tmp_path / f"first{first}.csv", late)
        if ok:
            assert load_angle_curve(path).t_s[0] == pytest.approx(first)
        else:
            assert "of the first row is after 0" in error_of(load_angle_curve, path)
