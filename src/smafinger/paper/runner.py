"""``smafinger reproduce``: run the paper's scenarios, draw its figures, check its claims.

:func:`reproduce` runs every scenario of :mod:`.scenarios` (or a selection) on a pool of
worker processes, then writes into the output directory (the figures and CSVs on a pool too):

- one PNG per figure (``fig07-cdf.png``, ``fig08-h0.png``, ...);
- ``runs/NAME.csv``: the signals of every run every :data:`EVERY` output samples (10 ms),
  and ``runs/NAME.provenance.json`` (the run's definition; ``samples_every`` says the
  thinning);
- ``summary.json``: per scenario, its definition, ``result.summary()``, its figure
  metrics (``derived``), both computed in the worker from the full 1 ms output, and its
  ``provenance`` (:mod:`smafinger.provenance`, exact);
- ``investigation.json``: the Fig. 15 readings of smafinger 0.1 and the studies' tables
  (:mod:`.studies`, :mod:`.issue10`), when both v1 on-reach Fig. 15 scenarios ran;
- ``report.md``: each claim beside smafinger's value and verdict (:mod:`.report`).

Each file is written atomically; JSON numbers are rounded to :data:`JSON_DIGITS`
significant digits, except in the provenance (exact: a run can be made again).
"""

from __future__ import annotations

import fnmatch
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable

from .. import outdir
from ..engine.run import RunSpec
from ..files import JSON_DIGITS, json_ready, write_json  # noqa: F401  (json_ready re-exported)
from ..outdir import STAGE_PREFIX, OwnFiles  # noqa: F401  (STAGE_PREFIX re-exported)
from ..results import SimulationResult
from ..values import one_or_many
from . import investigation as inv
from . import scenarios as scn
from .claim import Outcome
from .derived import Derivation, Run, derive
from .issue10 import study_tables
from .report import write_report

#: keep every EVERY-th output sample (1 ms) in the CSVs and the figures (10 ms)
EVERY = 10


@dataclass(frozen=True)
class _ThinAndDerive:
    """Worker side: a run's figure metrics computed at full resolution (every derivation
    named for its spec), then the result thinned to every ``every``-th sample, its metrics
    kept (small to send back and to store)."""

    every: int
    derivations: tuple[tuple[RunSpec, Derivation | None], ...]

    def __call__(self, result: SimulationResult) -> tuple[SimulationResult, dict]:
        named = {d for spec, d in self.derivations if spec == result.spec}
        if not named:
            raise LookupError("no figure metrics are named for this run's spec")
        derived = {d: derive(d, result) for d in named}
        thin = result.decimated(self.every)  # metrics kept at full resolution
        return thin, derived


def run_tasks(tasks: list[tuple[str, RunSpec]], workers: int | None = None,
              on_done: Callable[[str], None] | None = None,
              derivations: dict[str, Derivation | None] | None = None) -> dict[str, Run]:
    """Run ``(key, spec)`` tasks on a pool; a failed run is kept with its error.

    ``derivations`` names each key's figure metrics (default: none), computed in the worker
    from the full-resolution output like ``summary``.
    """
    from ..engine.batch import chunked, make_pool

    named = derivations or {}
    specs = dict(tasks)
    reduce = _ThinAndDerive(EVERY, tuple((spec, named.get(key)) for key, spec in tasks))
    out: dict[str, Run] = {}
    with make_pool(workers) as pool:
        # longest runs first, one run per task: the pool stays busy to the end
        order = sorted(tasks, key=lambda kv: -kv[1].t_end_s)
        for outcomes in pool.map_chunks(chunked(order, 1), reduce):
            for key, ok, value in outcomes:
                if ok:
                    thin, derived = value
                    out[key] = Run(key, specs[key], thin, thin.summary(), derived[named.get(key)])
                else:
                    out[key] = Run(key, specs[key], None, None, error=f"{type(value).__name__}: {value}")
                if on_done is not None:
                    on_done(key)
    return {k: out[k] for k, _ in tasks}


def select(only: Iterable[str] | None) -> list[scn.Scenario]:
    """Scenarios named (or matched by a glob pattern) in ``only``; all of them if empty."""
    if not only:
        return scn.all_scenarios()
    chosen: list[str] = []
    for pat in one_or_many(only):
        if any(c in pat for c in "*?["):
            hits = [n for n in scn.names() if fnmatch.fnmatchcase(n, pat)]
            if not hits:
                raise ValueError(f"--only {pat!r} matches no scenario (see 'smafinger scenarios')")
        else:
            scn.get(pat)  # ValueError naming the known ones
            hits = [pat]
        chosen += [h for h in hits if h not in chosen]
    return [scn.get(n) for n in scn.names() if n in chosen]


@dataclass
class ReproduceOutput:
    out_dir: Path
    runs: dict[str, Run]
    claims: list[Outcome]
    investigation: list[dict] | None
    figures: list[Path]
    wall_s: float
    failed: list[str] = field(default_factory=list)


def _simulate(tasks: list[tuple[str, RunSpec]], workers: int, progress,
              derivations: dict[str, Derivation | None]) -> dict[str, Run]:
    """:func:`run_tasks` with a progress display (``progress``: a flag or a
    :class:`~smafinger.progress.Display`)."""
    from ..progress import Display

    display = progress if isinstance(progress, Display) else Display.auto(bool(progress))
    if not display.enabled:
        return run_tasks(tasks, workers, derivations=derivations)
    task = display.task("reproduce", len(tasks), "runs")
    try:
        return run_tasks(tasks, workers, lambda key: task.update(advance=1, note=key), derivations)
    finally:
        if display is not progress:
            display.stop()


def _write_summary(out_dir: Path, runs: dict[str, Run]) -> None:
    """``summary.json``: per run its definition, summary and figure metrics (numbers rounded),
    and its provenance (exact)."""
    from ..provenance import provenance

    summary: dict[str, Any] = {}
    for name, r in runs.items():
        entry: dict[str, Any] = json_ready({"scenario": r.scenario.definition()})
        if r.ok:
            entry.update(json_ready(r.summary))
            entry["derived"] = json_ready(r.derived)
            entry["provenance"] = provenance(r.spec, scenario=name)
        else:
            entry["error"] = r.error
        summary[name] = entry
    write_json(out_dir / "summary.json", summary, digits=None)


@dataclass(frozen=True)
class _FigureFile:
    """A figure's PNG from its runs; the figure is looked up by its key in the worker (its
    claims hold lambdas, which do not pickle)."""

    key: str
    runs: list[Run]
    path: Path

    def write(self) -> None:
        f = scn.figure(self.key)
        f.plot(self.runs, f.title, self.path)


@dataclass(frozen=True)
class _RunCsv:
    """A run's CSV (every :data:`EVERY`-th sample) and its provenance sidecar."""

    name: str
    run: Run
    path: Path

    def write(self) -> None:
        from ..export import add_signals
        from ..files import Outputs

        out = Outputs()
        add_signals(out, self.run.result, self.path, scenario=self.name, samples_every=EVERY)
        out.commit()


def _write_files(out_dir: Path, runs: dict[str, Run], workers: int) -> list[Path]:
    """Every figure with a successful run (``KEY.png``) and every successful run's
    ``runs/NAME.csv`` with its provenance sidecar, written on ``workers`` processes (figures
    first, those with the most runs first: the pool stays busy to the end). Returns the
    figures' paths, in figure order."""
    from ..engine.batch import make_pool

    figures = []
    for f in scn.FIGURES:
        sel = [runs[s.name] for s in f.scenarios if s.name in runs]
        if any(r.ok for r in sel):
            figures.append(_FigureFile(f.key, sel, out_dir / f"{f.key}.png"))
    csvs = [_RunCsv(name, r, out_dir / "runs" / f"{name}.csv") for name, r in runs.items() if r.ok]
    jobs = sorted(figures, key=lambda job: -len(job.runs)) + csvs
    with make_pool(max(1, min(workers, len(jobs)))) as pool:
        for _ in pool.map_tasks(_write_file, jobs):
            pass
    return [job.path for job in figures]


def _write_file(job: _FigureFile | _RunCsv) -> None:
    """Worker side of :func:`_write_files`: one file (and a CSV's sidecar)."""
    job.write()


def own_files() -> tuple[frozenset[str], frozenset[str]]:
    """The names a reproduce writes: (in its folder, in its ``runs/``). Exact names, so that a
    file of the user's that merely looks like one (``holiday.png``) is never taken for it."""
    top = {"summary.json", "report.md", "investigation.json"} | {f"{f.key}.png" for f in scn.FIGURES}
    runs = {f"{n}{suffix}" for n in scn.names() for suffix in (".csv", ".provenance.json")}
    return frozenset(top), frozenset(runs)


def _own() -> OwnFiles:
    """:func:`own_files` for :mod:`smafinger.outdir` (its rule for ``--out``)."""
    top, runs = own_files()
    return OwnFiles("reproduce", "a reproduce", top, {"runs": runs})


def check_out_dir(out_dir: str | Path) -> None:
    """:class:`~smafinger.files.OutputError` (bad input) unless ``out_dir`` can take a reproduce:
    new (its parent a writable folder), or a writable folder that is empty or holds only what
    a reproduce writes (:func:`own_files`); the rule is :func:`smafinger.outdir.check_out_dir`."""
    outdir.check_out_dir(out_dir, _own())


def check_investigate(names: Iterable[str], investigate: bool | None) -> bool:
    """Whether to run the Fig. 15 investigation with the scenarios ``names``: by default when
    every scenario its tables read is among them (:func:`.investigation.needed_scenarios`);
    asked for without them, ValueError naming the missing ones (found by review: its tables
    said ``never``, not completed, for the runs that were not selected, and drew findings)."""
    missing = [n for n in inv.needed_scenarios() if n not in set(names)]
    if investigate is None:
        return not missing
    if investigate and missing:
        raise ValueError(f"--investigate needs the scenarios its tables read; not selected: {', '.join(missing)} "
                         f"(run them all: no --only)")
    return investigate


def reproduce(out_dir: str | Path, only: Iterable[str] | None = None, workers: int | None = None,
              progress=False, investigate: bool | None = None) -> ReproduceOutput:
    """Run the scenarios and write figures, CSVs, summary.json, investigation.json and
    report.md into ``out_dir``.

    ``only``: scenario names or glob patterns (default: all). ``investigate``: run the Fig. 15
    readings and studies (default: when every scenario they read is selected,
    :func:`check_investigate`). ``progress``: a flag or a :class:`~smafinger.progress.Display`.

    All or nothing: the outputs are written into a hidden folder inside ``out_dir``
    (:data:`STAGE_PREFIX`) and moved into place at the end, after what an earlier reproduce
    wrote there is removed (:func:`check_out_dir` refuses a folder holding anything else), so
    no file of an earlier run stays beside the new ones. Interrupted or failed before that, the
    hidden folder is removed and ``out_dir`` is as it was (a folder it made is removed too).
    """
    from ..engine.batch import available_cores

    t0 = time.perf_counter()
    out_dir = Path(out_dir)
    chosen = select(only)  # before anything is written: a bad name leaves no directory
    check_out_dir(out_dir)
    names = [s.name for s in chosen]
    investigate = check_investigate(names, investigate)
    tasks = [(s.name, s.spec()) for s in chosen] + (inv.tasks(names) if investigate else [])
    n_workers = max(1, min(workers or available_cores(), len(tasks)))
    with outdir.staged(out_dir, _own()) as stage:  # all or nothing, out_dir as it was on any failure
        (stage / "runs").mkdir()
        derivations = inv.derivations() if investigate else {}
        derivations.update({s.name: s.derive for s in chosen})
        runs = _simulate(tasks, n_workers, progress, derivations)
        for s in chosen:
            runs[s.name].scenario = s
        scen_runs = {n: runs[n] for n in names}
        _write_summary(stage, scen_runs)
        figures = _write_files(stage, scen_runs, n_workers)
        rows = inv.table(runs) if investigate else None
        tables = study_tables(runs) if investigate else None
        if rows is not None:
            write_json(stage / "investigation.json", {"readings": rows, "studies": tables})
        outcomes = [c.evaluate(scen_runs) for c in scn.claims()]
        wall = time.perf_counter() - t0
        write_report(stage / "report.md", outcomes, rows, runs, figures, wall, n_workers, tables)
    figures = [out_dir / p.relative_to(stage) for p in figures]
    return ReproduceOutput(out_dir, runs, outcomes, rows, figures, wall, [k for k, r in runs.items() if not r.ok])


__all__ = ["reproduce", "check_out_dir", "check_investigate", "own_files", "STAGE_PREFIX", "run_tasks", "select",
           "json_ready", "ReproduceOutput", "Run", "EVERY", "JSON_DIGITS"]
