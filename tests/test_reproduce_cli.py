"""``smafinger reproduce`` and ``smafinger scenarios`` from the command line (in process)."""

from __future__ import annotations

import csv
import json

from smafinger.cli import main

QUICK = ["fig8-h0-60-upper-v1", "fig8-h0-70-upper-v1"]


def test_reproduce_only_two_scenarios_writes_every_output(tmp_path, capsys):
    out = tmp_path / "out"
    argv = ["reproduce", "--out", str(out), "--workers", "2", "--no-progress"]
    for n in QUICK:
        argv += ["--only", n]
    assert main(argv) == 0
    printed = "".join(capsys.readouterr().out.split())  # the console wraps the line holding the path
    assert "report.md" in printed

    png = out / "fig08-h0.png"
    assert png.exists() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in out.glob("*.png")) == ["fig08-h0.png"]

    for n in QUICK:
        path = out / "runs" / f"{n}.csv"
        with path.open() as f:
            rows = list(csv.reader(f))
        assert rows[0][:2] == ["t_s", "theta_deg"]
        assert len(rows) - 1 == 4001  # 40 s every 10 ms

    summary = json.loads((out / "summary.json").read_text())
    assert sorted(summary) == sorted(QUICK)
    for n in QUICK:
        entry = summary[n]
        assert entry["interlock_violations"] == 0
        assert entry["scenario"]["figure"] == "Fig. 8"
        assert entry["derived"]["range_deg"] > 5.0
        assert "segments" in entry
    # h0 = 60 moves further than h0 = 70
    assert summary[QUICK[0]]["derived"]["range_deg"] > summary[QUICK[1]]["derived"]["range_deg"]

    report = (out / "report.md").read_text()
    assert "| Figure | Claim | Paper | smafinger | Holds | Note |" in report
    assert "lower h0 -> larger range and earlier start of motion (upper wire)" in report
    assert "not run" in report  # Fig. 15 was not selected
    assert not (out / "investigation.json").exists()


def test_reproduce_glob_selection_serial(tmp_path):
    out = tmp_path / "o"
    assert main(["reproduce", "--out", str(out), "--only", "fig13-extension-*", "--workers", "1",
                 "--no-progress"]) == 0
    assert (out / "fig13.png").exists()
    assert sorted(p.stem for p in (out / "runs").glob("*.csv")) == [
        "fig13-extension-case1-v1", "fig13-extension-case2-v1"]
    assert "extension: return from -30 to -40 deg faster" in (out / "report.md").read_text()


def test_figures_and_csvs_written_by_workers_are_those_written_here(tmp_path):
    """The figures and CSVs go to the worker pool (paper/runner.py): the files are byte for byte
    those one process writes. Two figures (Fig. 8 and Fig. 13), so both workers draw."""
    only = [a for n in QUICK + ["fig13-extension-*"] for a in ("--only", n)]
    for workers in ("1", "2"):
        assert main(["reproduce", "--out", str(tmp_path / workers), "--workers", workers, "--no-progress",
                     *only]) == 0
    names = sorted(p.relative_to(tmp_path / "1") for p in (tmp_path / "1").rglob("*.*")
                   if p.suffix in (".png", ".csv"))
    assert len([n for n in names if n.suffix == ".png"]) == 2 and len(names) == 6
    for name in names:
        assert (tmp_path / "2" / name).read_bytes() == (tmp_path / "1" / name).read_bytes(), name


def test_reproduce_unknown_scenario_is_a_usage_error(tmp_path, capsys):
    assert main(["reproduce", "--out", str(tmp_path / "x"), "--only", "fig99-v1"]) == 2
    err = capsys.readouterr().err
    assert "unknown scenario 'fig99-v1'" in err and "fig15-cooperative-v1" in err
    assert not (tmp_path / "x").exists()


def test_scenarios_lists_names_and_figures(capsys):
    assert main(["scenarios"]) == 0
    out = capsys.readouterr().out
    assert "fig15-independent-v1" in out and "Fig. 15" in out
    assert "authors2020-profile2-v1" in out
    assert main(["scenarios", "-v"]) == 0
    assert "friction_sticking=initial-only" in capsys.readouterr().out


def test_simulate_runs_a_named_scenario(tmp_path, capsys):
    csv_path = tmp_path / "r.csv"
    assert main(["simulate", "--scenario", "fig12-extension-v1", "--out", str(csv_path), "--no-progress"]) == 0
    assert csv_path.exists()
    assert "interlock violations 0" in capsys.readouterr().out


def test_a_second_reproduce_replaces_the_first_whole(tmp_path, capsys):
    """Found by review: the README's two commands into one folder left the first's 56 CSVs and its
    figures beside the second's summary. A reproduce now replaces its folder whole."""
    out = tmp_path / "out"
    assert main(["reproduce", "--out", str(out), "--only", "fig8-h0-6*", "--workers", "1", "--no-progress"]) == 0
    assert len(list((out / "runs").glob("*.csv"))) == 4  # h0 60 and 65, each wire
    assert main(["reproduce", "--out", str(out), "--only", QUICK[1], "--workers", "1", "--no-progress"]) == 0
    assert sorted(p.name for p in (out / "runs").glob("*.csv")) == [f"{QUICK[1]}.csv"]
    assert list(json.loads((out / "summary.json").read_text())) == [QUICK[1]]
    assert sorted(p.name for p in out.iterdir()) == ["fig08-h0.png", "report.md", "runs", "summary.json"]


def test_a_folder_holding_other_files_is_refused_before_any_run(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    assert main(["reproduce", "--out", str(out), "--only", QUICK[0], "--no-progress"]) == 2
    assert "--out " + str(out) + ": holds notes.txt, which reproduce does not write" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_an_interrupted_reproduce_leaves_the_folder_as_it_was(tmp_path, capsys, monkeypatch):
    """Found by review: Ctrl-C while writing left a summary.json without its report.md."""
    from smafinger.paper import runner

    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text("{}")  # an earlier reproduce's

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "_write_files", interrupted)
    assert main(["reproduce", "--out", str(out), "--only", QUICK[0], "--workers", "1", "--no-progress"]) == 130
    assert "no output was written; --out is as it was" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["out", "summary.json"]  # its hidden folder removed
    assert (out / "summary.json").read_text() == "{}"


def test_investigate_without_the_scenarios_it_reads_is_refused(tmp_path, capsys):
    """Found by review: with only the two v1 on-reach runs (the old default's trigger) its tables said
    'never' (not completed) for every study run that was not selected, and drew findings from them."""
    argv = ["reproduce", "--out", str(tmp_path / "x"), "--no-progress", "--only", "fig15-independent-v1",
            "--only", "fig15-cooperative-v1"]
    assert main(argv + ["--investigate"]) == 2
    assert "--investigate needs the scenarios its tables read; not selected: fig12-extension-v1" in \
        capsys.readouterr().err
    assert not (tmp_path / "x").exists()
    from smafinger.paper.runner import check_investigate

    assert check_investigate(["fig15-independent-v1", "fig15-cooperative-v1"], None) is False  # was True


def test_a_dead_worker_leaves_nothing_and_says_so(tmp_path, capsys, monkeypatch):
    """Found by review: 'finished runs are kept' was printed and nothing was kept."""
    from smafinger.engine.pools import BatchError
    from smafinger.paper import runner

    def dies(*args, **kwargs):
        raise BatchError("a worker process died (killed)")

    monkeypatch.setattr(runner, "_simulate", dies)
    assert main(["reproduce", "--out", str(tmp_path / "o"), "--only", QUICK[0], "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert "a worker process died (killed); no output was written" in err and "kept" not in err
    assert list(tmp_path.iterdir()) == []


def test_only_exact_names_of_a_reproduce_are_replaced(tmp_path, capsys):
    """Found by review: any *.png or runs/*.csv counted as a reproduce's, and the whole folder was
    replaced, deleting them."""
    for folder, name in ((tmp_path / "a", "holiday.png"), (tmp_path / "b", "runs/my-measurements.csv")):
        (folder / "runs").mkdir(parents=True)
        (folder / name).write_text("mine")
        (folder / "summary.json").write_text("{}")
        assert main(["reproduce", "--out", str(folder), "--only", QUICK[0], "--no-progress"]) == 2
        assert f"holds {name}, which reproduce does not write" in capsys.readouterr().err
        assert (folder / name).read_text() == "mine"


def test_the_current_folder_and_a_symlink_can_take_a_reproduce(tmp_path, capsys, monkeypatch):
    """Found by review: --out . staged its files in ./..partial-PID, refused them at the end and
    lost the runs; a symlinked --out was replaced by a real folder."""
    here = tmp_path / "here"
    here.mkdir()
    monkeypatch.chdir(here)
    argv = ["reproduce", "--only", QUICK[0], "--workers", "1", "--no-progress", "--out"]
    assert main(argv + ["."]) == 0 and main(argv + ["."]) == 0
    assert sorted(p.name for p in here.iterdir()) == ["fig08-h0.png", "report.md", "runs", "summary.json"]
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    assert main(argv + [str(tmp_path / "link")]) == 0 and main(argv + [str(tmp_path / "link")]) == 0
    assert (tmp_path / "link").is_symlink() and (tmp_path / "real" / "summary.json").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["here", "link", "real"]


def test_a_failure_while_moving_the_outputs_in_puts_the_earlier_ones_back(tmp_path, capsys, monkeypatch):
    """Found by review: a runs/ the process could not write left --out without its summary,
    report and figures, the new outputs stranded in the hidden folder."""
    from pathlib import Path

    out = tmp_path / "out"
    argv = ["reproduce", "--out", str(out), "--only", QUICK[0], "--workers", "1", "--no-progress"]
    assert main(argv) == 0
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    real = Path.rename

    def fails_in_runs(self, target):
        if Path(target).parent == out / "runs" and ".partial-" in str(self) and ".old" not in str(self):
            raise PermissionError(13, "Permission denied (simulated)", str(target))
        return real(self, target)

    monkeypatch.setattr(Path, "rename", fails_in_runs)
    assert main(argv) == 1
    assert "the outputs could not be moved into place" in capsys.readouterr().err
    monkeypatch.setattr(Path, "rename", real)
    after = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert after == before and sorted(p.name for p in out.iterdir()) == sorted(
        p.name for p in out.iterdir() if not p.name.startswith("."))  # no hidden folder left


def test_ctrl_c_after_the_outputs_are_in_place_says_so(tmp_path, capsys, monkeypatch):
    import importlib

    cli_reproduce = importlib.import_module("smafinger.cli.reproduce")

    def interrupted(res):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli_reproduce, "_print", interrupted)
    out = tmp_path / "out"
    assert main(["reproduce", "--out", str(out), "--only", QUICK[0], "--workers", "1", "--no-progress"]) == 130
    assert f"interrupted (Ctrl-C) after the outputs were written to {out}" in capsys.readouterr().err
    assert (out / "summary.json").exists()
