"""Parametric sweeps: a TOML spec, many runs, one tidy table, resumable.

A sweep spec (see ``examples/sweep-fig8.toml`` and ``docs/sweeps.md``)::

    [base]                        # the run every point starts from
    params = "paper2010-table2"   # a named set or a .toml file (relative to the spec)
    strategy = "open-loop"
    voltage = "0:8:0,8:0:0"
    t_end_s = 20.0
    set = { C_DF_heating_Nms = 0.02 }   # optional fixed parameter overrides

    [sweep]
    mode = "grid"                 # grid | list | random | lhs
    # samples = 200, seed = 1     # random / lhs

    [vary.h0]                     # one varied name ...
    fields = ["h0_heating_W_m2K", "h0_cooling_W_m2K"]   # ... may set several fields
    start = 60.0
    stop = 70.0
    num = 21

How a sweep runs (:func:`run_sweep`):

1. its size is computed (no point is made yet) and a sweep above ``max_runs`` is refused
   with its size and estimated bytes;
2. the *check pass*: the workers build and validate every point's spec from the shared
   :class:`~smafinger.analysis.sweep_spec.SweepTemplate` and return its ``run_id`` (a hash
   of the run's canonical spec: unique, stable across reruns). A bad point or two points
   that are the same run refuse the sweep, naming the point, before anything is written;
3. the runs not already in ``OUT`` or ``OUT.parts/`` go to the workers in chunks, drawn
   lazily, a few per worker in flight; the rows come back and are saved as durable part
   files at least every ``save_interval_s``;
4. the parts are merged into ``OUT`` (and ``OUT.traces``) block by block, and removed.

The client's work per run is small (about 35 us: see ``benchmarks/bench_scale.py``),
so it keeps a large cluster busy.
"""

from __future__ import annotations

import json
import math
import time
import uuid
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Callable

import numpy as np

from ..engine import batch
from ..engine.run import RunSpec, SimulationError  # noqa: F401 (re-exported)
from .sweep_merge import Finished, write_table, write_traces
from .sweep_parse import load_spec, parse_spec
from .sweep_progress import Progress
from .sweep_rows import (METRIC_COLUMNS, MOTION_THRESHOLD_DEG, TRACE_COLUMNS, WARNINGS_SEPARATOR,  # noqa: F401
                         check_block, error_row, metrics_row, run_block)
from .sweep_size import SweepSize, SweepSizeError, check_size, max_t_end, sweep_size  # noqa: F401 (re-exported)
from .sweep_spec import (DEFAULT_MAX_RUNS, RUN_ID_SCHEMA, Run, SweepSpec, SweepSpecError, Vary,  # noqa: F401
                         canonical_run, run_id)
from .sweep_store import IdIndex, StoreError, clean_stale, parts_dir, preload_writer, traces_path, write_part

#: points per task of the check pass (a few ms of work each), and rows per part file at most
CHECK_BLOCK = 1024
PART_MAX_ROWS = 4096
#: sweeps this small are checked in this process (faster than starting a pool)
CHECK_HERE_MAX = 2000


def kept_runs(done: int, total: int, parts: Path) -> str:
    """What a sweep stopped part-way keeps, and how to go on (after Ctrl-C or a broken pool)."""
    return (f"after {done} of {total} runs; finished runs are saved in {parts} - run the same sweep again "
            "to resume")


class SweepInterrupted(KeyboardInterrupt):
    """The sweep was interrupted; what finished is saved (run it again to resume)."""

    def __init__(self, done: int, total: int, parts: Path):
        super().__init__(f"interrupted {kept_runs(done, total, parts)}")
        self.done, self.total, self.parts = done, total, parts


# ---------------------------------------------------------------------------------------
# the check pass
# ---------------------------------------------------------------------------------------
def _check_item(item):
    return check_block(*item)


@dataclass(frozen=True)
class Checked:
    ids: np.ndarray
    n_segments: int


def check_points(spec: SweepSpec, template, points, pool, traces_interval_s: float | None = None) -> Checked:
    """Every point's run id, validated in ``pool``'s workers (with ``traces_interval_s``, its
    traces' sampling too; with ``spec.check_step``, that its step can be checked); refuses a bad
    or repeated point."""
    n = points.n
    ids = np.zeros(n, dtype="S16")
    block = max(16, min(CHECK_BLOCK, math.ceil(n / (4 * pool.slots))))
    items = ((template, a, cols, traces_interval_s, spec.check_step) for a, cols in points.blocks(block))
    n_seg = 0
    for res in pool.map_tasks(_check_item, items):
        if res.error is not None:
            point, values, msg = res.error
            raise spec.point_error(point, values, msg)
        ids[res.start:res.start + len(res.ids)] = res.ids
        n_seg = max(n_seg, res.n_segments)
    order = np.argsort(ids, kind="stable")
    same = np.flatnonzero(ids[order][1:] == ids[order][:-1])
    if same.size:
        second = order[1:][same]
        j = int(second.min())
        first = int(order[same[np.argmin(second)]])
        vals = points.block(j, j + 1)
        raise spec.duplicate_error(first, j, {k: v[0] for k, v in vals.items()})
    return Checked(ids, n_seg)


# ---------------------------------------------------------------------------------------
# the run pass
# ---------------------------------------------------------------------------------------
def _run_item(item, traces_interval_s, row, check_step=False):
    template, pts, ids, cols = item
    return run_block(template, pts, ids, cols, traces_interval_s, row, check_step)


def _run_items(template, points, ids: np.ndarray, todo: np.ndarray, size: int):
    """Chunks of ``size`` points still to run, in point order, made lazily."""
    buf_p: list[int] = []
    buf_c: dict[str, list] = {name: [] for name in points.names}

    def take():
        k = min(size, len(buf_p))
        item = (template, buf_p[:k], [i.decode() for i in ids[buf_p[:k]].tolist()],
                {name: col[:k] for name, col in buf_c.items()})
        del buf_p[:k]
        for col in buf_c.values():
            del col[:k]
        return item

    for a, cols in points.blocks(CHECK_BLOCK):
        sel = np.flatnonzero(todo[a:a + CHECK_BLOCK]).tolist()
        buf_p.extend(a + k for k in sel)
        for name, col in cols.items():
            buf_c[name].extend(col[k] for k in sel)
        while len(buf_p) >= size:
            yield take()
    while buf_p:
        yield take()


@dataclass
class SweepReport:
    out: Path
    traces_out: Path | None
    total: int
    resumed: int
    ran: int
    failed: int
    wall_s: float
    backend: str
    #: failed runs in the whole table (this invocation's and resumed ones)
    failed_total: int = 0
    #: runs in the whole table with warnings (their ``warnings`` column)
    flagged_total: int = 0
    #: the client's own time in the run pass, per run that ran (s)
    client_s_per_run: float = math.nan
    #: with ``check_step``: finished ``ok`` rows not step-checked (made by a pass without it)
    unchecked_total: int = 0


class _Saver:
    """Buffers finished rows and writes them as a part at least every ``interval_s``."""

    def __init__(self, pdir: Path, interval_s: float, traces_interval_s: float | None):
        self.pdir, self.interval_s, self.traces_interval_s = pdir, interval_s, traces_interval_s
        self.traces = traces_interval_s is not None
        self.rows: list[dict] = []
        self.trs: list[dict] = []
        self.last = time.monotonic()

    def add(self, block) -> None:
        self.rows.extend(block.rows)
        if block.traces is not None:
            self.trs.append(block.traces)
        if time.monotonic() - self.last >= self.interval_s or len(self.rows) >= PART_MAX_ROWS:
            self.flush()

    def flush(self) -> None:
        if self.rows:
            tr = None
            if self.traces:
                tr = {c: np.concatenate([t[c] for t in self.trs]) for c in self.trs[0]} if self.trs else None
            write_part(self.pdir, self.rows, tr if tr is not None else (_empty_traces() if self.traces else None),
                       self.traces_interval_s)
        self.rows, self.trs, self.last = [], [], time.monotonic()


def _empty_traces() -> dict:
    cols = {"run_id": np.zeros(0, dtype=object), "point": np.zeros(0, dtype=np.int64)}
    cols.update({c: np.zeros(0, np.float64 if c == "t_s" else np.float32) for c in TRACE_COLUMNS})
    return cols


def run_sweep(spec: SweepSpec | str | Path, out: str | Path | None = None, *, workers: int | None = None,
              scheduler=None, traces: bool = False, progress: bool = False, console=None,
              chunk_size: int | None = None, on_progress: Callable[[int, int], None] | None = None,
              max_runs: int = DEFAULT_MAX_RUNS, connect_timeout_s: float = batch.CONNECT_TIMEOUT_S,
              progress_interval_s: float = 10.0) -> SweepReport:
    """Run a sweep (resuming one that was interrupted) and write its table to ``out``.

    ``scheduler``: a Dask scheduler address (``tcp://HOST:PORT``, a cluster you trust: its
    workers run pickled code) or ``Client``; without it the runs go to ``workers`` local
    processes (default: every core). ``progress``: a live bar on ``console``; otherwise, with
    a ``console``, a plain progress line every ``progress_interval_s``. ``on_progress(done,
    total)`` is called after each finished chunk. Sweeps above ``max_runs`` runs are refused
    before anything is made. Returns a :class:`SweepReport`.
    """
    t_start = time.perf_counter()
    if scheduler is None:
        batch.start_forkserver(workers)  # local workers start warm from it, given the time
    if not isinstance(spec, SweepSpec):
        spec = load_spec(spec, max_runs=max_runs)
    out = Path(out) if out is not None else Path(f"{spec.name}.parquet")
    if out.suffix.lower() not in (".parquet", ".pq"):
        raise SweepSpecError(f"--out {out}: the results file must end in .parquet")
    if out.parent and not out.parent.is_dir():
        raise SweepSpecError(f"--out {out}: folder {out.parent} does not exist")
    if workers is not None and workers < 1:
        raise SweepSpecError(f"--workers {workers}: must be >= 1")
    check_size(spec, out, traces, max_runs)
    traced = spec.traces_interval_s if traces else None  #: the traces' interval, None without traces
    template = spec.template()
    points = spec.point_source()
    total = points.n
    pdir = parts_dir(out)
    pool = None
    say = Progress(console, progress, progress_interval_s, spec.name)
    try:
        if scheduler is not None or total > CHECK_HERE_MAX:
            pool = batch.make_pool(workers, scheduler, connect_timeout_s)
            say.watch(pool)
        checked = check_points(spec, template, points, pool or batch.SerialPool(), traced)
        clean_stale(out)
        index = IdIndex(checked.ids)
        try:
            finished = Finished(out, pdir, index, traced)
        except StoreError as exc:
            raise SweepSpecError(str(exc)) from None
        done0 = int(finished.done.sum())
        say.line(f"sweep {spec.name}: {total} runs" + (f", {done0} already done" if done0 else ""))
        todo = ~finished.done
        ran, failed, backend, client_s = total - done0, 0, "nothing left to run", math.nan
        if ran:
            if pool is None:
                pool = batch.make_pool(workers, scheduler, connect_timeout_s)
                say.watch(pool)
            say.pool(pool)  # after the check pass: a bad point's error stays one line
            backend = pool.describe()
            say.line(f"running {ran} runs on {backend}")
            size = chunk_size or spec.chunk_size or batch.auto_chunk_size(ran, pool.slots)
            fn = partial(_run_item, traces_interval_s=traced, row=metrics_row, check_step=spec.check_step)
            preload_writer()  # pandas' import (pyarrow's) overlaps the wait for the first rows
            failed, client_s = _run_pass(spec, pool, fn, _run_items(template, points, checked.ids, todo, size),
                                         _Saver(pdir, spec.save_interval_s, traced), say, done0, total, on_progress)
    finally:
        if pool is not None:
            pool.close(cancel=True)
    finished = Finished(out, pdir, index, traced)
    if not finished.done.all():
        raise RuntimeError(f"internal error: {int((~finished.done).sum())} runs have no result after the sweep")
    failed_total, flagged_total = finished.failed_count(), finished.flagged_count()
    unchecked = finished.unchecked_count() if spec.check_step else 0
    _merge(spec, out, pdir, finished, points, checked, traces, template, unchecked)
    return SweepReport(out=out, traces_out=traces_path(out) if traces else None, total=total,
                       resumed=done0, ran=ran, failed=failed, wall_s=time.perf_counter() - t_start,
                       backend=backend, failed_total=failed_total, flagged_total=flagged_total,
                       client_s_per_run=client_s, unchecked_total=unchecked)


def _run_pass(spec, pool, fn, items, saver, say, done, total, on_progress) -> tuple[int, float]:
    """Run the chunks, saving rows as they come; returns (failed runs, client s per run)."""
    failed, ran, busy = 0, 0, 0.0
    say.start(total, done)
    try:
        for block in pool.map_tasks(fn, items):
            t0 = time.perf_counter()
            saver.add(block)
            n = len(block.rows)
            done, ran, failed = done + n, ran + n, failed + block.failed
            say.update(done, failed, pool)
            busy += time.perf_counter() - t0
            if on_progress:
                on_progress(done, total)
        saver.flush()
    except KeyboardInterrupt:
        say.stop()
        saver.flush()
        raise SweepInterrupted(done, total, saver.pdir) from None
    except batch.BatchError as exc:  # the pool broke: what finished is saved, as after Ctrl-C
        say.stop()
        saver.flush()
        raise batch.BatchError(f"{exc}; {kept_runs(done, total, saver.pdir)}") from None
    except BaseException:
        say.stop()
        saver.flush()
        raise
    say.stop()
    return failed, busy / ran if ran else math.nan


def _merge(spec, out: Path, pdir: Path, finished: Finished, points, checked: Checked, traces: bool,
           template, unchecked: int = 0) -> None:
    """Write ``OUT`` (and its traces) from the finished rows, with their provenance
    (:mod:`.sweep_provenance`), then remove the parts. ``unchecked``: with ``check_step``, the
    finished rows made without it (in the metadata as ``step_unchecked``)."""
    from .. import __version__
    from .sweep_provenance import sweep_provenance

    canonical = json.loads(json.dumps(spec.canonical(), default=str))
    meta = finished.out_meta or {}
    unchanged = (finished.n_parts == 0 and meta.get("spec") == canonical
                 and (not traces or meta.get("traces")) and meta.get("step_unchecked", 0) == unchecked)
    if not unchanged:
        varied = [v.name for v in spec.vary]
        merge = uuid.uuid4().hex  # in both files: the traces' points are the table's (sweep_merge.same_merge)
        if traces:
            samples = max(1, round(max_t_end(spec) / spec.traces_interval_s) + 1)
            write_traces(traces_path(out), finished, samples,
                         {"varied": [], "of": out.name, "interval_s": spec.traces_interval_s, "version": __version__,
                          "merge": merge})
        write_table(out, finished, points, varied, checked.n_segments,
                    {"varied": varied, "spec": canonical, "version": __version__, "traces": traces, "merge": merge,
                     "motion_threshold_deg": MOTION_THRESHOLD_DEG, "provenance": sweep_provenance(template),
                     **({"step_unchecked": unchecked} if spec.check_step else {})})
    if pdir.is_dir():
        for f in pdir.iterdir():
            try:
                f.unlink()
            except OSError:
                pass
        try:
            pdir.rmdir()
        except OSError:
            pass


def read_results(path: str | Path, with_timing: bool = True):
    """A sweep table as a pandas DataFrame (``with_timing=False`` drops ``wall_s``)."""
    import pandas as pd

    df = pd.read_parquet(path)
    if not with_timing and "wall_s" in df.columns:
        df = df.drop(columns=["wall_s"])
    return df


__all__ = ["SweepSpec", "SweepSpecError", "SweepSizeError", "SweepInterrupted", "SweepReport", "SweepSize",
           "Vary", "Run", "load_spec", "parse_spec", "run_sweep", "run_id", "canonical_run", "metrics_row",
           "read_results", "parts_dir", "traces_path", "sweep_size", "check_size", "METRIC_COLUMNS",
           "TRACE_COLUMNS", "DEFAULT_MAX_RUNS"]
