"""The CLI contract of issue 2."""

import json
import subprocess
import sys

import pandas as pd
import pytest

from smafinger.cli import main

COLUMNS = ("t_s, theta_deg, theta_ref_deg, omega_deg_s, T_upper_C, T_lower_C, xi_upper, xi_lower, "
           "sigma_upper_Pa, sigma_lower_Pa, force_upper_N, force_lower_N, arm_upper_m, arm_lower_m, "
           "spring_upper_m, spring_lower_m, V_upper_V, V_lower_V, duty_upper, duty_lower").split(", ")


def test_simulate_writes_csv_parquet_summary_plot(tmp_path):
    csv, pq, js, png = (tmp_path / n for n in ("r.csv", "r.parquet", "s.json", "p.png"))
    rc = main(["simulate", "--params", "paper2010", "--strategy", "cooperative", "--profile", "0:-25,reach:-55",
               "--t-end", "15", "--out", str(csv), "--summary", str(js), "--plot", str(png), "--no-progress"])
    assert rc == 0
    df = pd.read_csv(csv)
    assert list(df.columns)[:len(COLUMNS)] == COLUMNS  # new columns are added at the end
    assert len(df) == 15001 and df["t_s"].iloc[-1] == pytest.approx(15.0)
    s = json.loads(js.read_text())
    for key in ("segments", "energy_J", "peak_temperature_C", "peak_stress_Pa", "interlock_violations", "steps", "wall_s"):
        assert key in s
    for key in ("start_s", "target_deg", "reached_s", "overshoot_deg"):
        assert key in s["segments"][0]
    assert set(s["energy_J"]) == {"upper", "lower"}
    assert png.stat().st_size > 10_000
    rc = main(["simulate", "--profile", "0:-25", "--t-end", "2", "--out", str(pq), "--output-interval", "0.01"])
    assert rc == 0 and list(pd.read_parquet(pq).columns)[:len(COLUMNS)] == COLUMNS and len(pd.read_parquet(pq)) == 201


def test_params_file_and_set(tmp_path):
    f = tmp_path / "p.toml"
    assert main(["params", "authors2020", "--set", "M_SF_Nm=0.02", "--out", str(f)]) == 0
    js = tmp_path / "s.json"
    assert main(["simulate", "--params", str(f), "--profile", "0:-25:upper", "--t-end", "2", "--summary", str(js)]) == 0
    summary = json.loads(js.read_text())
    assert summary["params"] == "authors2020" and summary["params_changed"] == ["M_SF_Nm"]


@pytest.mark.parametrize("args,needle", [
    (["simulate", "--set", "h0_heating_W_m2K=-3", "--profile", "0:-25"], "h0_heating_W_m2K"),
    (["simulate", "--profile", "0:abc"], "not a number"),
    (["simulate", "--strategy", "open-loop", "--voltage", "0:8:8"], "interlock"),
    (["simulate", "--strategy", "sideways", "--profile", "0:-25"], "strategy"),
    (["simulate", "--bogus"], "--bogus"),
    (["simulate", "--profile", "0:-25", "--dt", "1.5e-9"], "nanoseconds"),
    (["simulate", "--profile", "0:-25", "--dt", "1.5e-10"], "shorter than the clock's tick"),
    (["simulate", "--params", "nosuchset"], "nosuchset"),
    (["simulate", "--profile", "0:-25", "--out", "x.txt"], ".csv or .parquet"),
])
def test_usage_errors_exit_2_with_one_line(args, needle, tmp_path):
    out = tmp_path / "never.csv"
    proc = subprocess.run([sys.executable, "-m", "smafinger.cli", *args, "--summary", str(tmp_path / "never.json")]
                          if "--bogus" not in args else [sys.executable, "-m", "smafinger.cli", *args],
                          capture_output=True, text=True, cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and needle in lines[0], proc.stderr
    assert not out.exists() and not (tmp_path / "never.json").exists()
    assert list(tmp_path.iterdir()) == []


def test_atomic_write_keeps_umask_permissions_and_leaves_nothing_on_failure(tmp_path):
    import os

    from smafinger.results import atomic_write

    old = os.umask(0o022)
    try:
        atomic_write(tmp_path / "a.txt", lambda tmp: open(tmp, "w").write("x"))
    finally:
        os.umask(old)
    assert (tmp_path / "a.txt").stat().st_mode & 0o777 == 0o644

    def boom(tmp):
        open(tmp, "w").write("half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError):
        atomic_write(tmp_path / "b.txt", boom)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
