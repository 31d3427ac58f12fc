"""Run command lines in a worker process, with a time limit, and judge each outcome.

The worker (a spawned process that imports smafinger once) runs ``smafinger.cli.main(argv)``
in the case's own folder with stdout and stderr captured; an exception escaping ``main`` is
sent back as a traceback. A case that takes longer than the time limit is a hang: the worker
is killed and a new one started.

The rule every outcome must follow (:func:`judge`):

- exit 0: stderr holds only ``smafinger: ...`` lines (warnings, a sweep's failed-run count)
  and a sweep's progress lines;
  every requested output exists and is readable (CSV, Parquet, MATLAB, JSON, TOML, figure);
  no temporary file is left;
- exit 2: exactly one line ``smafinger: error: ...``; nothing written;
- exit 1 only for ``smafinger: simulation failed: ...`` (a valid but extreme run that blew
  up), one line, nothing written; exit 3 only for a sweep whose runs all failed;
- never a traceback, never a hang.
"""

from __future__ import annotations

import io
import multiprocessing as mp
import os
import shutil
import traceback
from collections import Counter
from contextlib import redirect_stderr, redirect_stdout
from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class Case:
    """A command line and the input files it needs (name -> text; ``None``: a folder)."""

    argv: list[str]
    inputs: dict[str, str | None] = field(default_factory=dict)
    #: outputs a successful run must have written
    outputs: tuple[str, ...] = ()


@dataclass
class Outcome:
    rc: int | None
    stdout: str
    stderr: str
    traceback: str | None
    new_files: list[str]
    hang: bool = False

    @property
    def err_lines(self) -> list[str]:
        return [ln for ln in self.stderr.splitlines() if ln.strip()]


def _serve(conn) -> None:  # the worker process
    os.environ.setdefault("MPLBACKEND", "Agg")
    from smafinger.cli import main

    while True:
        msg = conn.recv()
        if msg is None:
            return
        argv, cwd = msg
        out, err = io.StringIO(), io.StringIO()
        tb, rc = None, None
        os.chdir(cwd)
        try:
            with redirect_stdout(out), redirect_stderr(err):
                rc = main(argv)
        except BaseException:  # noqa: BLE001 - the very thing the fuzz looks for
            tb = traceback.format_exc()
        conn.send((rc, out.getvalue(), err.getvalue(), tb))


class Runner:
    """Runs :class:`Case` s one at a time in a worker process (see the module docstring)."""

    def __init__(self, base: Path, timeout_s: float):
        self.base, self.timeout_s = base, timeout_s
        self.counts: Counter = Counter()
        self.n = 0
        self._proc = self._conn = None

    def _start(self) -> None:
        ctx = mp.get_context("spawn")
        self._conn, child = ctx.Pipe()
        self._proc = ctx.Process(target=_serve, args=(child,), daemon=True)
        self._proc.start()
        child.close()

    def close(self) -> None:
        if self._proc is not None:
            try:
                self._conn.send(None)
                self._proc.join(5)
            except (OSError, EOFError):
                pass
            if self._proc.is_alive():
                self._proc.kill()
            self._proc = None

    def run(self, case: Case) -> Outcome:
        if self._proc is None or not self._proc.is_alive():
            self._start()
        self.n += 1
        folder = self.base / f"case{self.n}"
        folder.mkdir()
        for name, text in case.inputs.items():
            if text is None:
                (folder / name).mkdir(parents=True, exist_ok=True)
            else:
                (folder / name).parent.mkdir(parents=True, exist_ok=True)
                (folder / name).write_text(text)
        before = _listing(folder)
        self._conn.send((case.argv, str(folder)))
        if self._conn.poll(self.timeout_s):
            rc, out, err, tb = self._conn.recv()
            outcome = Outcome(rc, out, err, tb, [])
        else:
            self._proc.kill()
            self._proc.join()
            self._proc = None
            outcome = Outcome(None, "", "", None, [], hang=True)
        outcome.new_files = sorted(set(_listing(folder)) - set(before))
        self._check_outputs(case, folder, outcome)
        shutil.rmtree(folder, ignore_errors=True)
        return outcome

    def _check_outputs(self, case: Case, folder: Path, outcome: Outcome) -> None:
        """Read every requested output of a successful run (a problem goes into ``traceback``)."""
        if outcome.rc != 0:
            return
        for name in case.outputs:
            try:
                _read(folder / name)
            except Exception:  # noqa: BLE001 - any failure to read is reported
                outcome.traceback = f"output {name} unreadable:\n{traceback.format_exc()}"
                return


def _listing(folder: Path) -> list[str]:
    return [str(p.relative_to(folder)) for p in folder.rglob("*")]


def _read(path: Path) -> None:
    """Read an output the way its users would; raises if it is not sane."""
    import json
    import tomllib

    suffix = path.suffix.lower()
    if suffix == ".csv":
        import pandas as pd

        df = pd.read_csv(path)
        assert df.columns[0] == "t_s" and len(df) >= 1 and df["t_s"].is_monotonic_increasing
        assert json.loads(path.with_suffix(".provenance.json").read_text())["run_sha256"]
    elif suffix in (".parquet", ".pq"):
        import pyarrow.parquet as pq

        assert pq.read_table(path).num_rows >= 1
    elif suffix == ".mat":
        from scipy.io import loadmat

        assert "provenance" in loadmat(path)
    elif suffix == ".json":
        doc = json.loads(path.read_text())
        assert isinstance(doc, dict) and doc
    elif suffix == ".toml":
        assert tomllib.loads(path.read_text())
    elif suffix in (".png", ".pdf", ".svg"):
        assert path.stat().st_size > 1000
    else:
        raise AssertionError(f"unexpected output {path.name}")


def judge(case: Case, o: Outcome) -> str:
    """The outcome's kind (``run``, ``refused``, ``blow-up``, ``runs-failed``); AssertionError
    naming the case if it breaks the rule of the module docstring."""
    where = f"\ncommand: smafinger {' '.join(map(repr, case.argv))}\nstdout: {o.stdout[-2000:]}\nstderr: {o.stderr[-3000:]}"
    assert not o.hang, f"hang (no answer in the time limit){where}"
    assert o.traceback is None, f"{o.traceback}{where}"
    assert "Traceback (most recent call last)" not in o.stderr, f"traceback on stderr{where}"
    temporaries = [f for f in o.new_files if f.endswith(".tmp") or ".tmp" in Path(f).name]
    assert not temporaries, f"temporaries left: {temporaries}{where}"
    lines = o.err_lines
    if o.rc == 3 and case.argv[0] == "sweep":
        assert any("every run failed" in ln or "runs failed" in ln for ln in lines), where
        return "runs-failed"
    if o.rc == 0:
        said = ("smafinger: ",) + (("sweep ", "running ") if case.argv[0] == "sweep" else ())  # a sweep's log lines
        assert all(ln.startswith(said) for ln in lines), f"unexpected stderr{where}"
        missing = [n for n in case.outputs if n not in o.new_files]
        assert not missing, f"outputs missing: {missing}{where}"
        return "run"
    assert not o.new_files, f"exit {o.rc} but files written: {o.new_files}{where}"
    if o.rc == 2:
        assert len(lines) == 1 and lines[0].startswith("smafinger: error: ") and len(lines[0]) > 20, \
            f"a refusal must be one line 'smafinger: error: ...'{where}"
        assert "internal error" not in lines[0], where
        return "refused"
    if o.rc == 1:
        assert len(lines) == 1 and lines[0].startswith("smafinger: simulation failed: "), f"exit 1{where}"
        return "blow-up"
    raise AssertionError(f"exit status {o.rc}{where}")
