"""The controller bench end to end (``--quick``), its bad-input errors, and the paper's PWM-PID
through the controller interface bit-identical to the default run."""

import json
from pathlib import Path

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


# --- --out: checked before any run, written all or nothing, an earlier bench's files replaced ----------------
# (found by review: --out /proc/x ran every run and then failed; a folder holding a file 'figures' was left
# half-written; a second bench kept the first's figures of mechanisms it did not run)

QUICK = ["bench-controllers", "--quick", "--workers", "1"]


def _tree(folder):
    """Every file under ``folder`` (hidden ones included) with its bytes."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture
def no_runs(monkeypatch):
    """run_bench replaced by a recorder: a test that wants no run sees the list stay empty."""
    import smafinger.bench.runner as bench_runner

    calls = []
    monkeypatch.setattr(bench_runner, "run_bench", lambda *a, **k: calls.append(a) or pytest.fail("a run started"))
    return calls


@pytest.mark.parametrize("case", ["a file", "missing parent", "cannot be made", "a file named figures"])
def test_a_bad_out_is_refused_before_any_run(tmp_path, no_runs, case):
    import os

    if case == "a file":
        out = tmp_path / "bench.csv"
        out.write_text("mine")
    elif case == "missing parent":
        out = tmp_path / "nope" / "bench"
    elif case == "cannot be made":  # as root os.access says yes; only making it tells
        if not os.path.isdir("/proc/self"):
            pytest.skip("needs Linux /proc")
        out = Path("/proc/smafinger-bench-never")
    else:
        out = tmp_path / "bw"
        out.mkdir()
        (out / "figures").write_text("mine")
    before = (sorted(tmp_path.rglob("*")), _tree(tmp_path))
    r = runner.invoke(app, [*QUICK, "--out", str(out)])
    assert r.exit_code == 2, r.output
    lines = [x for x in r.output.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"smafinger: error: --out {out}: "), lines
    assert no_runs == [] and (sorted(tmp_path.rglob("*")), _tree(tmp_path)) == before  # nothing made
    assert not Path("/proc/smafinger-bench-never").exists()


@pytest.mark.parametrize("name, shown", [("notes.txt", "notes.txt"), ("figures/holiday.png", "figures/holiday.png"),
                                         ("figures/joint-fig99.png", "figures/joint-fig99.png"),
                                         ("runs/x.csv", "runs")])
def test_a_folder_holding_files_the_bench_does_not_write_is_refused(tmp_path, no_runs, name, shown):
    """By exact names: a PNG in figures/ that no bench task draws is the user's, never deleted."""
    out = tmp_path / "mine"
    (out / name).parent.mkdir(parents=True, exist_ok=True)
    (out / name).write_text("mine")
    (out / "controllers.csv").write_text("an earlier bench's")
    before = _tree(out)
    r = runner.invoke(app, [*QUICK, "--out", str(out)])
    assert r.exit_code == 2, r.output
    assert f"--out {out}: holds {shown}, which bench-controllers does not write" in r.output
    assert no_runs == [] and _tree(out) == before


def test_a_second_bench_leaves_no_file_of_the_first(tmp_path):
    out = tmp_path / "bq4"
    assert runner.invoke(app, [*QUICK, "--out", str(out)]).exit_code == 0
    first = {p.name for p in (out / "figures").iterdir()}
    r = runner.invoke(app, [*QUICK, "-m", "joint", "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in (out / "figures").iterdir()) == ["joint-fig12-extension.png"]
    assert set(pd.read_csv(out / "controllers.csv")["mechanism"]) == {"joint"}
    assert pd.read_csv(out / "bandwidth.csv").empty  # the slider's sine is gone with its rows
    r = runner.invoke(app, [*QUICK, "-m", "joint", "--no-figures", "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in out.iterdir()) == ["bandwidth.csv", "controllers.csv", "controllers.md",
                                                     "goals.json"]  # no figures/, no hidden folder
    from smafinger.bench.report import figure_names

    assert first == figure_names(select_tasks(quick=True))  # the names own_files lists are those drawn


def test_the_bench_owns_a_figure_name_for_every_task():
    from smafinger.bench.report import own_files
    from smafinger.bench.tasks import ALL_TASKS

    names = own_files().folders["figures"]
    assert {f"{t.mechanism}-{t.name}.png" for t in ALL_TASKS} < names
    assert names - {f"{t.mechanism}-{t.name}.png" for t in ALL_TASKS} == {"joint-bandwidth.png",
                                                                           "linear-bias-spring-bandwidth.png"}


def _earlier_bench(out):
    """A folder as an earlier bench left it (its own names, recognisable bytes)."""
    (out / "figures").mkdir(parents=True)
    for name in ("controllers.csv", "bandwidth.csv", "controllers.md", "goals.json",
                 "figures/linear-bias-spring-cycle.png"):
        (out / name).write_text(f"earlier {name}")
    return _tree(out)


def test_ctrl_c_while_writing_leaves_out_as_it_was(tmp_path, monkeypatch):
    """Interrupted after some files were written (goals.json comes after the CSVs): the earlier
    bench's files untouched, no hidden folder left; a folder the bench made is removed."""
    import smafinger.bench.report as report

    class Interrupted:
        @staticmethod
        def dumps(*args, **kwargs):
            raise KeyboardInterrupt

    monkeypatch.setattr(report, "json", Interrupted)
    out = tmp_path / "out"
    before = _earlier_bench(out)
    r = runner.invoke(app, [*QUICK, "--out", str(out)])
    assert r.exit_code == 130, r.output
    assert "interrupted (Ctrl-C); no output was written" in r.output
    assert _tree(out) == before and [p.name for p in out.iterdir() if p.name.startswith(".")] == []
    new = tmp_path / "new"
    assert runner.invoke(app, [*QUICK, "--out", str(new)]).exit_code == 130
    assert not new.exists()


def test_a_failure_while_moving_the_outputs_in_puts_the_earlier_ones_back(tmp_path, monkeypatch):
    real = Path.rename
    out = tmp_path / "out"
    before = _earlier_bench(out)

    def fails_in_figures(self, target):
        if Path(target).parent == out / "figures" and ".partial-" in str(self) and ".old" not in str(self):
            raise PermissionError(13, "Permission denied (simulated)", str(target))
        return real(self, target)

    monkeypatch.setattr(Path, "rename", fails_in_figures)
    r = runner.invoke(app, [*QUICK, "--out", str(out)])
    monkeypatch.setattr(Path, "rename", real)
    assert r.exit_code == 1, r.output
    assert f"--out {out}: the outputs could not be moved into place" in r.output
    assert _tree(out) == before and [p.name for p in out.iterdir() if p.name.startswith(".")] == []


@pytest.mark.parametrize("where", ["printing", "teardown"])
def test_ctrl_c_after_the_outputs_are_in_place_says_so(tmp_path, monkeypatch, where):
    """A Ctrl-C once the files were moved in, while the result was printed or while the pool and
    the progress display closed, said "no output was written" (the teardown: found by review)."""
    import contextlib

    import smafinger.cli.bench as cli_bench

    if where == "printing":
        def say(msg):
            if msg.startswith("written to"):
                raise KeyboardInterrupt

        monkeypatch.setattr(cli_bench, "_say", say)
    else:
        real = cli_bench.progress_display

        @contextlib.contextmanager
        def interrupted_on_close(progress):
            with real(progress) as display:
                yield display
            raise KeyboardInterrupt  # the teardown, once the body (the runs and the files) is done

        monkeypatch.setattr(cli_bench, "progress_display", interrupted_on_close)
    out = tmp_path / "out"
    r = runner.invoke(app, [*QUICK, "--no-figures", "--out", str(out)])
    assert r.exit_code == 130
    assert f"interrupted (Ctrl-C) after the outputs were written to {out}" in r.output
    assert (out / "goals.json").exists()


@pytest.mark.parametrize("value, ok", [(np.float32(300.0), True), (np.int64(300), True), (300, True),
                                       (np.True_, False), ("300", False), (10 ** 400, False)])
def test_a_controllers_numbers_are_checked_as_a_sets_are(value, ok):
    """np.float32 was refused as "not a number" by a controller while a parameter set took it
    (found by an API fuzz); an int beyond any float is out of range, not an OverflowError."""
    from smafinger.parameters import ParameterError

    if ok:
        pid = PaperPID(K_V_s_per_q=value)
        assert pid.K_V_s_per_q == 300.0 and type(pid.K_V_s_per_q) is float
    else:
        with pytest.raises(ParameterError, match="pid.*: K_V_s_per_q(:| =) "):
            PaperPID(K_V_s_per_q=value)
