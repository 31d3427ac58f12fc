"""The controller bench end to end (``--quick``), its bad-input errors, and the paper's PWM-PID
through the controller interface bit-identical to the default run."""

import json

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from smafinger.bench.presets import QUICK_CONTROLLERS
from smafinger.bench.tasks import select_tasks
from smafinger.cli import app
from smafinger.control.params import PaperPID
from smafinger.engine.run import make_spec, run_spec

runner = CliRunner()


def test_quick_bench_writes_every_output(tmp_path):
    out = tmp_path / "bench"
    r = runner.invoke(app, ["bench-controllers", "--out", str(out), "--quick", "--workers", "1"])
    assert r.exit_code == 0, r.output
    rows = pd.read_csv(out / "controllers.csv")
    tasks = select_tasks(quick=True)
    assert len(rows) == len(tasks) * len(QUICK_CONTROLLERS) * 2  # every controller x strategy x task
    assert set(rows["controller"]) == set(QUICK_CONTROLLERS)
    assert (rows["interlock_violations"] == 0).all() and rows["peak_T_C"].notna().all()
    assert rows.loc[rows["kind"] == "sine", "gain"].between(0.0, 2.0).all()
    md = (out / "controllers.md").read_text()
    assert "| controller | strategy |" in md and "## Goals of issue 15" in md and "| controller |" in r.output
    json.loads((out / "goals.json").read_text())
    figs = {p.name for p in (out / "figures").iterdir()}
    assert {f"{t.mechanism}-{t.name}.png" for t in tasks} <= figs
    assert "linear-bias-spring-bandwidth.png" in figs
    bw = pd.read_csv(out / "bandwidth.csv")
    assert set(bw["controller"]) == set(QUICK_CONTROLLERS)


def test_figures_drawn_on_two_workers_are_the_same_files(tmp_path):
    """The runs and the figures on a pool of two (figures drawn in the workers, most runs first,
    written here in task order): every file byte for byte what one process writes."""
    outs = {}
    for w in ("1", "2"):
        outs[w] = tmp_path / f"w{w}"
        r = runner.invoke(app, ["bench-controllers", "--out", str(outs[w]), "--quick", "--workers", w])
        assert r.exit_code == 0, r.output
    files = sorted(p.relative_to(outs["1"]) for p in outs["1"].rglob("*") if p.is_file())
    assert sorted(p.relative_to(outs["2"]) for p in outs["2"].rglob("*") if p.is_file()) == files
    assert sum(f.suffix == ".png" for f in files) == len(select_tasks(quick=True)) + 1  # + the bandwidth figure
    for f in files:
        assert (outs["1"] / f).read_bytes() == (outs["2"] / f).read_bytes(), f


def test_progress_counts_the_runs_then_the_figures(tmp_path, monkeypatch):
    """--progress: the runs, then the figures, counted to the end (plain lines, as in a log)."""
    import io

    from rich.console import Console

    import smafinger.cli.bench as cli_bench
    from smafinger.progress import Display

    buf = io.StringIO()
    monkeypatch.setattr(cli_bench, "progress_display",
                        lambda flag: Display("lines" if flag else "off", Console(file=buf, width=200), 1e-9))
    r = runner.invoke(app, ["bench-controllers", "--out", str(tmp_path / "b"), "--quick", "--workers", "1",
                            "--progress"])
    assert r.exit_code == 0, r.output
    lines = buf.getvalue().splitlines()
    tasks = select_tasks(quick=True)
    n_runs, n_figs = len(tasks) * len(QUICK_CONTROLLERS) * 2, len(tasks) + 1
    runs = [ln for ln in lines if ln.startswith("bench-controllers: ")]
    figs = [ln for ln in lines if ln.startswith("figures: ")]
    assert runs[-1].startswith(f"bench-controllers: {n_runs}/{n_runs} runs (100%)"), runs
    assert figs[-1].startswith(f"figures: {n_figs}/{n_figs} figures (100%)"), figs
    assert lines.index(runs[-1]) < lines.index(figs[0])


@pytest.mark.parametrize("args, names", [
    (["--controller", "pi"], "--controller 'pi'"),
    (["--strategy", "solo"], "--strategy 'solo'"),
    (["--task", "fig99"], "task 'fig99'"),
    (["--workers", "0"], "--workers 0"),
])
def test_bad_input_is_one_line_exit_2_and_nothing_written(tmp_path, args, names):
    out = tmp_path / "never"
    r = runner.invoke(app, ["bench-controllers", "--out", str(out), *args])
    assert r.exit_code == 2
    lines = [x for x in r.output.splitlines() if x.strip()]
    assert len(lines) == 1 and names in lines[0]
    assert not out.exists()


def test_paper_pid_through_the_interface_is_bit_identical():
    base = make_spec("paper2010", "cooperative", "0:-25,5:-55", t_end_s=8.0)
    via = make_spec("paper2010", "cooperative", "0:-25,5:-55", t_end_s=8.0, controller=PaperPID())
    a, b = run_spec(base), run_spec(via)
    for name in a.column_names:
        np.testing.assert_array_equal(a.signal(name), b.signal(name), err_msg=name)


class ChainPID(PaperPID):
    """The paper's PID law as a :class:`~smafinger.control.chain.ControlChain` (position sensor, no shaping)."""

    def record(self, p, base):
        from smafinger.control.chain import Law, PIDGains
        from smafinger.control.params import chain

        return chain(p, self.sensors, Law.PID, pid=PIDGains(*self._gains(base)))


@pytest.mark.parametrize("strategy", ["independent", "cooperative"])
def test_the_chain_with_the_pid_law_is_the_paper_pid_bit_for_bit(strategy):
    a = run_spec(make_spec("paper2010", strategy, "0:-25,6:-55,12:-40", t_end_s=16.0))
    b = run_spec(make_spec("paper2010", strategy, "0:-25,6:-55,12:-40", t_end_s=16.0, controller=ChainPID()))
    for name in a.column_names:
        np.testing.assert_array_equal(a.signal(name), b.signal(name), err_msg=name)
