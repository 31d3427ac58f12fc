"""The example bench runs shipped in ``src/smafinger/data/``: what the script makes, and that
the set which made them predicts them to their noise."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest
import typer
from scipy.io import loadmat
from typer.testing import CliRunner

import smafinger
from smafinger.cli.identify_actuator import actuator

DATA = Path(smafinger.__file__).parent / "data"
SCRIPT = Path(__file__).resolve().parent.parent / "examples" / "make_bench_data.py"
MANIFEST = json.loads((DATA / "bench_runs.json").read_text())


def test_the_shipped_runs_are_small_and_described():
    assert MANIFEST["noise_m"] == 30e-6
    for name, run in MANIFEST["runs"].items():
        assert (DATA / name).stat().st_size < 256_000, name
        assert run["role"] in ("fit", "validate", "replay")
    assert (DATA / MANIFEST["truth"]).exists()


def test_the_script_makes_the_shipped_runs(tmp_path):
    spec = importlib.util.spec_from_file_location("make_bench_data", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.make(tmp_path)
    for name in list(MANIFEST["runs"]) + ["bench_truth.toml", "bench_runs.json"]:
        if name.endswith(".mat"):  # its header holds the time it was written
            a, b = loadmat(DATA / name, simplify_cells=True), loadmat(tmp_path / name, simplify_cells=True)
            for var in ("u_pwm", "x_mm"):
                np.testing.assert_array_equal(a[var]["time"], b[var]["time"])
                np.testing.assert_array_equal(a[var]["signals"]["values"], b[var]["signals"]["values"])
        else:
            assert (DATA / name).read_bytes() == (tmp_path / name).read_bytes(), name


def test_the_true_set_predicts_every_open_loop_run_to_the_noise(tmp_path):
    args = ["--params", str(DATA / MANIFEST["truth"]), "--workers", "1", "--report", str(tmp_path / "r.json")]
    for name, run in MANIFEST["runs"].items():
        if run["role"] != "replay":
            args += ["--validate", f"{DATA / name}::{run['map']}" if run["map"] else str(DATA / name)]
    app = typer.Typer()
    app.command()(actuator)
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    for f in json.loads((tmp_path / "r.json").read_text())["files"]:
        offset = MANIFEST["runs"][Path(f["file"].split("::")[0]).name]["offset_m"]
        assert f["rms_m"] < 1.15 * MANIFEST["noise_m"], f
        assert f["offset_m"] == pytest.approx(offset, abs=2e-5)
