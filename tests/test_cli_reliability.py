"""Issues 13 and 14 at the command line: refusals are one line with exit 2 and write nothing,
outputs are all-or-none and say how they were made, a recorded run re-runs byte for byte."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
from scipy.io import loadmat

from smafinger import export
from smafinger.cli import app, main
from smafinger.engine.integrators import INTEGRATORS
from smafinger.engine.signals import MECHANISM_FIELDS, WIRE_FIELDS

QUICK = ["--profile", "0:-25", "--t-end", "1", "--no-progress"]


def run(capsys, *argv):
    rc = main(list(argv))
    out, err = capsys.readouterr()
    return rc, out, [ln for ln in err.splitlines() if ln.strip()]


def files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@pytest.fixture
def here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "d").mkdir()
    (tmp_path / "f").write_text("x")
    return tmp_path


@pytest.mark.parametrize("argv, needle", [
    (["simulate", "--params", "", *QUICK], "--params '': give a named set"),
    (["simulate", "--params", "d", *QUICK], "--params d: is a folder"),
    (["simulate", *QUICK, "--summary", "d"], "--summary d: the file name must end in .json"),
    (["simulate", *QUICK, "--summary", "d/x/y.json"], "--summary d/x/y.json: folder d/x does not exist"),
    (["simulate", *QUICK, "--plot", "d"], "--plot d: the file name must end in .png or .pdf or .svg"),
    (["simulate", *QUICK, "--out", "nofolder/r.csv"], "--out nofolder/r.csv: folder nofolder does not exist"),
    (["simulate", *QUICK, "--out", "s.csv", "--summary", "s.json", "--plot", "s.foo"], "--plot s.foo"),
    (["simulate", *QUICK, "--out", "s.csv", "--summary", "s.provenance.json"], "the same file is given for two"),
    (["params", "paper2010", "--out", "d"], "--out d: is a folder; give a file name"),
    (["params", ""], "parameter set '': give a named set"),
    (["params", "--out", "p.toml"], "--out needs a set"),  # found by review: exit 0, nothing written
    (["params", "--set", "V_H_V=abc"], "--set needs a set"),
    (["params", "paper2010", "--out", "p.csv"], "--out p.csv: the file name must end in .toml"),
    (["params", "paper2010", "--set", "name=\udcff", "--out", "p.toml"], "name: '\\udcff' is not valid text"),
    (["reproduce", "--out", "f", "--only", "fig8-h0-60-upper-v1"], "--out f: is a file; give a folder"),
    (["reproduce", "--out", "o", "--only", "fig99-v1"], "unknown scenario 'fig99-v1'"),
    (["simulate", "--t-end", "1e308", "--profile", "0:-25"], "t_end_s = 1e+308 s is beyond the clock's range"),
    (["simulate", "--dt", "1e308", "--profile", "0:-25"], "dt_s = 1e+308 s is beyond the clock's range"),
    (["simulate", "--hold-s", "1e308", "--profile", "0:-25"], "hold_s = 1e+308 s is beyond the clock's range"),
    (["simulate", "--strategy", "open-loop", "--voltage", "0:8:0,1e10:0:0", "--t-end", "1"], "voltage start [1]"),
    (["simulate", "--t-end", "1e6", "--profile", "0:-25"], f"1,000,000,001 samples x {len(MECHANISM_FIELDS) + 2 * len(WIRE_FIELDS)} signals"),
    (["simulate", "--t-end", "1", "--output-interval", "1e-9", "--profile", "0:-25"], "GiB allowed"),
    (["simulate", "--scenario", "fig12-extension-v1", "--params", "paper2010"], "--params: not used with --scenario"),
    (["simulate", "--scenario", "fig12-extension-v1", "--voltage", "0:8:0"], "--voltage: not used with --scenario"),
    (["simulate", "--strategy", "sideways"], "'sideways' is not one of 'open-loop', 'independent', 'cooperative'"),
    (["simulate", "--method", "rk5"], "'rk5' is not one of 'euler', 'rk4'"),
    (["simulate", "--from", "nothing.json"], "--from nothing.json: no such file"),
    (["sweep", "nothing.toml", "--mat", "x.txt"], "--mat x.txt: the file name must end in .mat"),
])
def test_refusals_are_one_line_exit_2_and_write_nothing(here, capsys, argv, needle):
    before = files(here)
    rc, _, err = run(capsys, *argv)
    assert rc == 2 and len(err) == 1 and err[0].startswith("smafinger: error: ") and needle in err[0], err
    assert files(here) == before and files(here / "d") == []


def test_a_failing_output_leaves_none_of_the_others(here, capsys, monkeypatch):
    def broken(fig, tmp, fmt):
        Path(tmp).write_bytes(b"half a png")
        raise OSError(28, "No space left on device", tmp)

    monkeypatch.setattr(export, "_save_figure", broken)
    rc, _, err = run(capsys, "simulate", *QUICK, "--out", "s.csv", "--summary", "s.json", "--plot", "s.png")
    assert rc == 1 and len(err) == 1 and "No space left on device" in err[0]
    assert files(here) == ["d", "f"]


def test_a_scenario_takes_the_run_options_it_can_and_refuses_the_others(here, capsys):
    rc, out, _ = run(capsys, "simulate", "--scenario", "fig12-extension-v1", "--t-end", "2", "--summary", "s.json",
                     "--set", "M_SF_Nm=0.02", "--no-progress")
    s = json.loads((here / "s.json").read_text())
    assert rc == 0 and s["t_end_s"] == 2.0 and s["provenance"]["scenario"] == "fig12-extension-v1"
    assert s["provenance"]["run"]["parameters"]["M_SF_Nm"] == 0.02
    assert s["provenance"]["run"]["parameters"]["friction_sticking"] == "initial-only"  # the scenario's own
    rc, _, err = run(capsys, "simulate", "--scenario", "fig12-extension-v1", "--tol-m", "1e-3")
    assert rc == 2 and "--tol-m: not used with --scenario" in err[0]


def test_warnings_are_printed_and_recorded(here, capsys):
    rc, _, err = run(capsys, "simulate", "--strategy", "open-loop", "--voltage", "0:100:0", "--t-end", "3",
                     "--summary", "hot.json", "--no-progress")
    assert rc == 0 and len(err) == 1 and err[0].startswith("smafinger: warning: upper wire: 1252 degC")
    assert json.loads((here / "hot.json").read_text())["warnings"] == [err[0].removeprefix("smafinger: warning: ")]
    rc, _, err = run(capsys, "simulate", "--set", "spring_K_N_m=1e6", "--strategy", "open-loop", "--voltage",
                     "0:8:0", "--t-end", "1", "--no-progress")
    assert rc == 0 and any("stress 72,776 MPa" in e for e in err) and any("recoverable strain" in e for e in err)


def test_a_blow_up_says_what_to_change(capsys):
    rc, _, err = run(capsys, "simulate", "--params", "paper2010-table2", "--set", "inertia_kg_m2=1e-9", "--strategy",
                     "open-loop", "--voltage", "0:8:0,10:0:0", "--method", "euler", "--t-end", "20", "--no-progress")
    assert rc == 1 and len(err) == 1 and err[0].startswith("smafinger: simulation failed: numerical blow-up at t = ")
    assert ("euler is stable only up to dt = 0.0001 ms against this set's damping (2e+07 1/s; now 1 ms): use a "
            "smaller --dt or --method exponential; check inertia_kg_m2 = 1e-09") in err[0]


def test_a_blow_up_of_an_explicit_step_names_its_stability_limit(capsys):
    """rk4 at 10 ms blows up on the paper's joint (C_DF / I = 1844 1/s); the hint said only 'try
    a smaller --dt', not how small, nor that the output interval had hidden it (exact PWM steps
    end at every sample: with 1 ms samples the same command runs 1 ms steps)."""
    rc, _, err = run(capsys, "simulate", "--strategy", "open-loop", "--voltage", "0:8:0,8:0:0", "--t-end", "20",
                     "--method", "rk4", "--dt", "0.01", "--pwm", "exact", "--output-interval", "0.1", "--no-progress")
    assert rc == 1 and "rk4 is stable only up to dt = 1.5 ms against this set's damping (1844 1/s; now 10 ms)" in err[0]


def test_json_times_carry_no_float_noise(here, capsys):
    assert run(capsys, "simulate", "--profile", "0:-25,reach:-55", "--t-end", "15", "--summary", "s.json",
               "--no-progress")[0] == 0
    text = (here / "s.json").read_text()
    s = json.loads(text)
    times = [seg[k] for seg in s["segments"] for k in ("start_s", "reached_s", "end_s") if seg[k] is not None]
    assert times and all(len(repr(t).replace(".", "").lstrip("0")) <= 13 for t in times), times
    assert "0000000000" not in text.split('"provenance"')[0] and "9999999999" not in text.split('"provenance"')[0]


# ---- re-running a recorded run --------------------------------------------------------------------
def test_from_a_summary_re_runs_byte_for_byte(here, capsys):
    run_options = ["--params", "authors2020", "--set", "M_SF_Nm=0.0123", "--strategy", "independent", "--profile",
                   "0:-25:upper,reach:-40", "--t-end", "6", "--dt", "5e-4", "--output-interval", "0.002", "--no-progress"]
    for fmt in ("csv", "parquet", "mat"):  # the first run, in every format
        assert run(capsys, "simulate", *run_options, "--out", f"a.{fmt}", "--summary", f"a_{fmt}.json")[0] == 0
    for source in ("a_csv.json", "a.csv", "a.parquet", "a.mat"):
        stem = "b_" + source.replace(".", "_")
        for fmt in ("csv", "parquet", "mat"):
            rc, _, err = run(capsys, "simulate", "--from", source, "--out", f"{stem}.{fmt}", "--summary",
                             f"{stem}.json", "--no-progress")
            assert rc == 0, err
            assert (here / f"{stem}.{fmt}").read_bytes() == (here / f"a.{fmt}").read_bytes(), (source, fmt)
        assert (here / f"{stem}.provenance.json").read_bytes() == (here / "a.provenance.json").read_bytes()
        a, b = (json.loads((here / n).read_text()) for n in ("a_csv.json", f"{stem}.json"))
        assert a.pop("wall_s") > 0 and b.pop("wall_s") > 0  # the loop's time on this machine: the one difference
        assert a == b


def test_a_scenario_run_again_records_its_scenario(here, capsys):
    assert run(capsys, "simulate", "--scenario", "fig12-extension-v1", "--t-end", "3", "--out", "a.csv",
               "--no-progress")[0] == 0
    assert run(capsys, "simulate", "--from", "a.csv", "--out", "b.csv", "--no-progress")[0] == 0
    assert (here / "b.provenance.json").read_bytes() == (here / "a.provenance.json").read_bytes()
    assert json.loads((here / "b.provenance.json").read_text())["scenario"] == "fig12-extension-v1"
    assert (here / "b.csv").read_bytes() == (here / "a.csv").read_bytes()


def test_mat_output_holds_every_signal_and_the_provenance(here, capsys):
    assert run(capsys, "simulate", *QUICK, "--out", "r.mat")[0] == 0
    assert run(capsys, "simulate", *QUICK, "--out", "r.csv")[0] == 0
    m = loadmat(here / "r.mat", squeeze_me=True)
    df = pd.read_csv(here / "r.csv")
    for c in df.columns[1:]:
        np.testing.assert_allclose(m[c]["signals"][()]["values"][()], df[c], rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(m["theta_deg"]["time"][()], df["t_s"], atol=1e-12)
    assert json.loads(str(m["provenance"]["run_json"][()]))["t_end_s"] == 1.0


# ---- the command line itself ------------------------------------------------------------------------
def test_help_lists_the_allowed_values(capsys):
    assert main(["simulate", "--help"]) == 0
    text = capsys.readouterr().out
    assert "<open-loop|independent|cooperative>" in text and f"<{'|'.join(INTEGRATORS)}>" in text and "<exact|averaged>" in text and "<str>" not in text
    assert main(["identify", "kinetics", "--help"]) == 0
    assert "<mean|row>" in capsys.readouterr().out


def test_every_command_is_mounted_explicitly():
    names = {c.name for c in app.registered_commands} | {g.name for g in app.registered_groups}
    assert names == {"simulate", "params", "scenarios", "reproduce", "sweep", "identify", "bench-controllers", "tune"}
    from smafinger.cli.identify import app as identify

    assert {c.callback.__name__ for c in identify.registered_commands} == {"kinetics", "joint", "actuator"}


def test_no_arguments_prints_the_help(capsys):
    assert main([]) == 0 and "Commands:" in capsys.readouterr().out
    assert main(["identify"]) == 0 and "kinetics" in capsys.readouterr().out


def test_ctrl_c_exits_130_with_one_line_at_once(tmp_path):
    """Ctrl-C in the middle of a run of 1e7 s (2 x 10^9 long steps: many minutes on any machine)
    is answered at once, not when the compiled loop ends.

    The child gets SIGINT's default disposition: a shell starts a background job (``cmd &``) with
    SIGINT ignored, and a process inherits that, as a command should (so it ran to its end when
    this suite ran in the background)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    proc = subprocess.Popen([sys.executable, "-m", "smafinger.cli", "simulate", "--profile", "0:-25", "--t-end",
                             "1e7", "--output-interval", "100", "--out", "r.csv", "--progress"],
                            cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        first = proc.stderr.readline()  # the first progress line: the run is under way
        assert first.startswith("simulating: "), first
        proc.send_signal(signal.SIGINT)
        t0 = time.monotonic()
        out, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert time.monotonic() - t0 < 60.0  # the run itself needs several minutes more
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("simulating: ")]
    assert proc.returncode == 130 and lines == ["smafinger: interrupted (Ctrl-C); no output was written"], err
    assert list(tmp_path.iterdir()) == []


def test_sweep_writes_a_matlab_table_with_provenance(tmp_path, capsys):
    spec = tmp_path / "s.toml"
    spec.write_text('[base]\nparams = "paper2010-table2"\nstrategy = "open-loop"\nvoltage = "0:8:0,2:0:0"\n'
                    't_end_s = 3.0\n[vary]\nh0_heating_W_m2K = [60.0, 70.0]\n')
    rc, out, err = run(capsys, "sweep", str(spec), "--out", str(tmp_path / "s.parquet"), "--mat",
                       str(tmp_path / "s.mat"), "--workers", "1")
    assert rc == 0, err
    table = pd.read_parquet(tmp_path / "s.parquet")
    m = loadmat(tmp_path / "s.mat", squeeze_me=True)
    assert list(m["sweep"]["h0_heating_W_m2K"][()]) == [60.0, 70.0]
    assert list(m["sweep"]["run_id"][()]) == table["run_id"].tolist()
    prov = json.loads(str(m["provenance"]["provenance_json"][()]))
    assert prov["base_parameters"]["name"] == "paper2010-table2"
    # the numerics as the runs resolve them (the long step: open loop, program steps 2 s apart)
    assert {k: prov["base_run_settings"][k] for k in ("dt_s", "method", "pwm")} == \
        {"dt_s": 0.005, "method": "exponential", "pwm": "averaged"}
    assert set(table["run_method"]) == {"exponential"} and set(table["run_pwm"]) == {"averaged"}
    meta = json.loads(pq.read_schema(tmp_path / "s.parquet").metadata[b"smafinger.sweep"])
    assert meta["provenance"] == prov


def test_a_parameter_file_without_name_source_or_base_is_complete_enough(here, capsys):
    from smafinger.parameters import get

    for mech in ("paper2010", "linear-bias-spring"):
        text = "\n".join(ln for ln in get(mech).to_toml().splitlines() if not ln.startswith(("name", "source")))
        (here / "p.toml").write_text(text + "\n")
        args = ["--profile", "0:-25"] if mech == "paper2010" else ["--strategy", "open-loop", "--voltage", "0:8"]
        rc, out, err = run(capsys, "simulate", "--params", "p.toml", *args, "--t-end", "0.5", "--summary", "s.json",
                           "--no-progress")
        assert rc == 0, err
        assert json.loads((here / "s.json").read_text())["provenance"]["run"]["parameters"]["name"] == "custom"
        assert run(capsys, "params", "p.toml")[1].splitlines()[2] == 'name = "custom"  # name of the set'


def test_a_sweep_of_another_mechanism_tabulates_its_own_columns(tmp_path, capsys):
    spec = tmp_path / "lin.toml"
    spec.write_text('[base]\nparams = "linear-bias-spring"\nstrategy = "open-loop"\nvoltage = "0:8,2:0"\n'
                    't_end_s = 3.0\n[vary]\nbias_spring_K_N_m = [100.0, 200.0]\n')
    rc, _, err = run(capsys, "sweep", str(spec), "--out", str(tmp_path / "t.parquet"), "--workers", "1")
    assert rc == 0, err
    table = pd.read_parquet(tmp_path / "t.parquet")
    assert len(table) == 2 and table["position_max_m"].notna().all() and table["theta_max_deg"].isna().all()


def test_a_changed_scenario_run_records_what_changed(here, capsys):
    """Found by review: `--scenario fig12-extension-v1 --set M_SF_Nm=0.02` was recorded as that scenario alone."""
    rc, _, _ = run(capsys, "simulate", "--scenario", "fig12-extension-v1", "--set", "M_SF_Nm=0.02", "--t-end", "1",
                   "--summary", "s.json")
    assert rc == 0
    prov = json.loads((here / "s.json").read_text())["provenance"]
    assert prov["scenario"] == "fig12-extension-v1"
    assert prov["scenario_changes"] == "--set M_SF_Nm=0.02 --t-end 1.0"
    rc, _, _ = run(capsys, "simulate", "--scenario", "fig12-extension-v1", "--t-end", "1", "--out", "u.mat")
    assert rc == 0  # a .mat file holds them too (CI caught a list refused there)


_FORKSERVER_CTRL_C = r"""
import os, sys, time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import forkserver
from smafinger.engine.forking import mp_context, start_forkserver

start_forkserver(2)
pid = forkserver._forkserver._forkserver_pid
print("started", flush=True)
try:
    time.sleep(60)
    sys.exit("no KeyboardInterrupt here")
except KeyboardInterrupt:
    pass
with ProcessPoolExecutor(1, mp_context=mp_context()) as ex:  # forked from the same forkserver
    assert ex.submit(os.getpid).result(timeout=60) != os.getpid()
print("same forkserver" if forkserver._forkserver._forkserver_pid == pid else "forkserver restarted", flush=True)
sys.exit(130)
"""


@pytest.mark.skipif("forkserver" not in __import__("multiprocessing").get_all_start_methods(),
                    reason="no forkserver on this platform")
def test_ctrl_c_while_the_forkserver_imports_leaves_it_alone(tmp_path):
    """Found by review: a Ctrl-C in the first ~1.5 s of a sweep (the forkserver, in the terminal's
    process group, still importing numba) killed the forkserver with a traceback of its imports.

    Here SIGINT goes to the whole process group 0.2 s after the forkserver is started: the client
    gets its KeyboardInterrupt, the forkserver nothing (no traceback), and it lives on to fork a
    worker."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    proc = subprocess.Popen([sys.executable, "-c", _FORKSERVER_CTRL_C], cwd=tmp_path, env=env, start_new_session=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        assert proc.stdout.readline() == "started\n"
        time.sleep(0.2)  # its imports take 1.5-2 s
        os.killpg(proc.pid, signal.SIGINT)
        out, err = proc.communicate(timeout=120)  # stderr ends when the forkserver is gone too
    finally:
        proc.kill()
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert proc.returncode == 130 and out == "same forkserver\n", (proc.returncode, out, err)


def test_a_ctrl_c_is_classified_without_importing_the_engine(monkeypatch):
    """A Ctrl-C landing while numba was half imported made classify's own imports of the engine
    raise: a traceback and exit status 1 instead of 130 (found by review)."""
    import sys

    from smafinger.cli.errors import EXIT_INTERRUPTED, classify

    monkeypatch.setitem(sys.modules, "smafinger.engine.pools", None)  # importing it raises ImportError
    monkeypatch.setitem(sys.modules, "smafinger.engine.run", None)
    assert classify(KeyboardInterrupt()) == (EXIT_INTERRUPTED, "smafinger: interrupted (Ctrl-C)")


def test_a_blow_up_in_the_python_api_says_what_to_change_in_its_terms():
    """smafinger.simulate's blow-up had no hint (only the command and sweeps added one), while
    numerics' docstring promised it names the extreme parameter (found by an API fuzz)."""
    from smafinger import SimulationError, simulate
    from smafinger.parameters import get

    p = get("paper2010-table2").replace(inertia_kg_m2=1e-9)
    with pytest.raises(SimulationError) as err:
        simulate(p, "open-loop", voltage="0:8:0,10:0:0", method="euler", t_end_s=20.0)
    assert str(err.value).startswith("numerical blow-up at t = ")
    assert str(err.value).endswith("use a smaller dt_s or method='exponential'; check inertia_kg_m2 = 1e-09 "
                                   "(48800x below paper2010's 4.88e-05)")
