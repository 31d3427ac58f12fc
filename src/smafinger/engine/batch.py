"""Batch engine: many runs in one call, in parallel, each bit-identical to the run made alone.

Every run is an ordinary :func:`~smafinger.engine.run.run_spec` call; the batch engine only
decides *where* it happens (:mod:`.pools`: this process, local worker processes, or a Dask
cluster) and keeps the client lean:

- runs travel in *chunks* (several runs per task) so that each task carries enough work to
  hide the scheduling cost;
- :func:`iter_batch` draws its runs lazily and yields each outcome as it finishes, with
  only a few chunks per worker in flight, so a batch of any size runs in bounded memory
  (write each result away as it comes);
- ``reduce`` runs in the worker, so only what it returns travels back: :class:`Compact`
  keeps chosen signals, decimated, in float32 (:func:`compact_signals`).

A run never depends on which worker, chunk or order it ran in: the kernel is deterministic
and has no shared state, so its output is bit-identical to the same run made alone.

>>> from smafinger.engine.batch import run_batch, specs_product
>>> specs = specs_product(["paper2010", "authors2020"], profiles=["0:-25", "0:-55"],
...                       strategy="cooperative", t_end_s=10.0)
>>> results = run_batch(specs, workers=2)  # doctest: +SKIP
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any, Callable, Iterator, Sequence

import numpy as np

from ..values import one_or_many
from .dask_pool import DaskPool, check_scheduler  # noqa: F401 (distributed itself is imported on use)
from .pools import (CONNECT_TIMEOUT_S, BatchError, DistributedMissing, LocalPool, SchedulerError,  # noqa: F401
                    SerialPool, Task, available_cores, build_spec, is_warm, make_pool, run_chunk, start_forkserver,
                    warm_up)
from .run import RunSpec, make_spec
from .signals import every_signal

#: signals kept in float64 by :func:`compact_signals`: time is the join key of every trace
#: (float32 cannot hold 0.1 s steps exactly and resolves only 61 us at t = 1000 s). Every
#: other signal is a physical quantity whose float32 rounding (6e-8 relative: 5e-6 deg at
#: 90 deg, 2e-5 K at 300 degC, 30 Pa at 5e8 Pa) is far below the model's own accuracy.
FLOAT64_SIGNALS = ("t_s",)


# ---------------------------------------------------------------------------------------
# items and chunks
# ---------------------------------------------------------------------------------------
def as_spec(item: RunSpec | dict) -> RunSpec:
    """A :class:`RunSpec` from a spec or from :func:`make_spec` keyword arguments."""
    if isinstance(item, RunSpec):
        return item
    if isinstance(item, dict):
        return make_spec(**item)
    raise TypeError(f"a batch item must be a RunSpec or a dict of make_spec arguments, not {type(item).__name__}")


def specs_product(params: Iterable = ("paper2010",), profiles: Iterable | None = None,
                  voltages: Iterable | None = None, **common) -> list[RunSpec]:
    """Every combination of parameter sets and profiles (or voltage programs), validated.

    Each of ``params``, ``profiles`` and ``voltages`` is a list of values, or one value (a
    name, a path, a set, a profile text or object). ``common`` holds the other
    :func:`make_spec` arguments (strategy, t_end_s, ...).
    """
    params = one_or_many(params)
    second = [("profile", p) for p in one_or_many(profiles)] if profiles is not None else []
    second += [("voltage", v) for v in one_or_many(voltages)] if voltages is not None else []
    if not second:
        second = [(None, None)]
    specs = []
    for p in params:
        for name, value in second:
            kw = dict(common)
            if name is not None:
                kw[name] = value
            specs.append(make_spec(params=p, **kw))
    return specs


def chunked(tasks: Iterable, size: int) -> Iterator[list]:
    """Consecutive lists of ``size`` items (the last may be shorter), drawn lazily."""
    size = max(1, int(size))
    it = iter(tasks)
    while True:
        chunk = list(itertools.islice(it, size))
        if not chunk:
            return
        yield chunk


def auto_chunk_size(n_tasks: int, slots: int, per_slot: int = 4, lo: int = 1, hi: int = 64) -> int:
    """Runs per task: about ``per_slot`` tasks per worker slot, within [lo, hi].

    A task's hand-over costs about 1.5 ms when both cores are busy (the result pickled, the
    next task sent), as much as a few long-step runs: on 2 cores the Fig. 8 sweep (231 runs)
    ran 1.52-1.67x faster in parallel with 8 runs per task (16 tasks per slot), 1.90-1.98x
    with 29 (4 per slot), against 1.89x for the two processes' compute alone. Four tasks per
    slot still leave room to balance the end of a batch: the last task idles a worker for a
    quarter of its share at most.
    """
    if n_tasks <= 0:
        return 1
    return max(lo, min(hi, math.ceil(n_tasks / (max(1, slots) * per_slot))))


# ---------------------------------------------------------------------------------------
# compact outputs
# ---------------------------------------------------------------------------------------
def compact_signals(result, names: Sequence[str] | None = None, every: int = 1) -> dict[str, np.ndarray]:
    """Signals of one result, every ``every``-th sample, float32 except :data:`FLOAT64_SIGNALS`.

    ``names``: exported signal names (default: every column of ``result.to_pandas()``).
    """
    every = int(every)
    if every < 1:
        raise ValueError(f"every = {every!r} must be >= 1")
    if names is None:
        names = list(result.to_pandas().columns)
    out = {}
    for n in names:
        x = np.asarray(result.signal(n))[::every]
        out[n] = np.ascontiguousarray(x, dtype=np.float64 if n in FLOAT64_SIGNALS else np.float32)
    return out


@dataclass(frozen=True)
class CompactResult:
    """What :class:`Compact` keeps of a run: its spec, its summary (metrics computed at full
    resolution, before decimation) and some signals, decimated, mostly float32."""

    spec: RunSpec
    summary: dict
    signals: dict
    every: int

    def signal(self, name: str) -> np.ndarray:
        try:
            return self.signals[name]
        except KeyError:
            raise KeyError(f"signal {name!r} was not kept (kept: {', '.join(self.signals)})") from None

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in self.signals.values())

    def to_pandas(self):
        import pandas as pd

        return pd.DataFrame(self.signals)


@dataclass(frozen=True)
class Compact:
    """A ``reduce`` for :func:`run_batch`: keep ``signals`` (default: all) every ``every``-th
    sample as float32 (time as float64), plus the run's summary.

    A 20 s run at 1 ms output keeps 20,001 samples per signal: 80 kB per float32 signal
    instead of the result's full float64 table.

    With ``check_step`` the worker also runs each spec at half its step
    (:func:`smafinger.step_check.with_step_check`, about twice the run's time): the summary gets
    ``step_check`` and, over the budget, its warning. A compact result cannot be checked
    afterwards: it keeps too little of the run.
    """

    signals: tuple[str, ...] | None = None
    every: int = 1
    check_step: bool = False

    def __post_init__(self):
        from ..results import sample_stride

        object.__setattr__(self, "every", sample_stride(self.every))
        if not isinstance(self.check_step, bool):
            raise TypeError(f"check_step = {self.check_step!r} must be True or False")

    def __call__(self, result) -> CompactResult:
        if self.check_step:
            from ..step_check import API_REMEDY, with_step_check

            result = with_step_check(result, remedy=API_REMEDY)
        return CompactResult(result.spec, result.summary(), compact_signals(result, self.signals, self.every),
                             int(self.every))


# ---------------------------------------------------------------------------------------
# one-call API
# ---------------------------------------------------------------------------------------
def iter_batch(runs: Iterable, *, workers: int | None = None, scheduler=None, reduce: Callable | None = None,
               chunk_size: int | None = None, pool=None, connect_timeout_s: float = CONNECT_TIMEOUT_S,
               record: str = "all") -> Iterator[tuple[int, bool, Any]]:
    """Run many simulations; yield ``(index, ok, value)`` for each as it finishes.

    ``runs`` is drawn lazily (a generator of specs is fine) and only a few chunks per worker
    are in flight, so memory stays bounded whatever the batch size: store each value as it
    comes. ``value`` is ``reduce(result)`` (the result itself without ``reduce``) when ``ok``,
    else the exception. Items are :class:`RunSpec`, :func:`make_spec` keyword dicts
    (validated here, as they are drawn) or recipes with a ``build()`` method (built in the
    worker). Other arguments as in :func:`run_batch`.
    """
    every_signal(record)  # a bad value is refused here, before any pool is made
    own = pool is None
    if own:
        pool = make_pool(workers, scheduler, connect_timeout_s)
    try:
        if chunk_size is None:
            n = len(runs) if hasattr(runs, "__len__") else 0
            chunk_size = auto_chunk_size(n, pool.slots) if n else 8
        items = ((i, r if not isinstance(r, dict) else as_spec(r)) for i, r in enumerate(runs))
        for outcomes in pool.map_chunks(chunked(items, chunk_size), reduce, record):
            yield from outcomes
    except BaseException:
        if own:
            pool.close(cancel=True)
        raise
    if own:
        pool.close()


def run_batch(runs: Iterable[RunSpec | dict], *, workers: int | None = None, scheduler=None,
              reduce: Callable | None = None, chunk_size: int | None = None,
              errors: str = "raise", pool=None, connect_timeout_s: float = CONNECT_TIMEOUT_S,
              record: str = "all", on_progress: Callable[[int, int], None] | None = None) -> list:
    """Run many simulations in parallel; the results in input order.

    Parameters
    ----------
    runs : iterable of RunSpec or dict
        Validated specs (:func:`~smafinger.engine.run.make_spec`) or its keyword arguments
        (all validated before anything runs).
    workers : int, optional
        Local worker processes (default: every available core; 1: in this process).
    scheduler : str or distributed.Client, optional
        Run on this Dask cluster instead (one you trust: its workers run pickled code).
    reduce : callable, optional
        Applied to each :class:`~smafinger.results.SimulationResult` in the worker, so that
        only what it returns travels back (must be picklable: a module-level function, a
        ``functools.partial`` of one, or :class:`Compact`). Default: the whole result.
    chunk_size : int, optional
        Runs per task (default: about 4 tasks per worker, at most 64 runs).
    errors : {"raise", "return"}
        A failed run raises :class:`BatchError` (after the others finished), or its
        exception is returned in its place.
    pool : optional
        A pool from :func:`make_pool` to reuse (kept open), e.g. in a loop of batches.
    connect_timeout_s : float
        Time allowed to reach the Dask scheduler.
    record : {"all", "metrics"}
        The signals each run records: every one, or only those its metrics read (the results
        then have only those; :func:`~smafinger.engine.run.run_spec`). ``"metrics"`` writes
        about a third as much: for a ``reduce`` that needs no other signal.
    on_progress : callable, optional
        Called as ``on_progress(done, total)`` after each run's outcome arrives (they arrive a
        task, a chunk of runs, at a time).

    All results are held in the returned list: for large batches use :func:`iter_batch`
    (bounded memory) or a ``reduce``.
    """
    if errors not in ("raise", "return"):
        raise ValueError(f"errors = {errors!r} is not one of raise, return")
    specs = [as_spec(r) for r in runs]
    if not specs:
        return []
    out: list[Any] = [None] * len(specs)
    failed: list[tuple[int, Exception]] = []
    outcomes = iter_batch(specs, workers=workers, scheduler=scheduler, reduce=reduce, chunk_size=chunk_size,
                          pool=pool, connect_timeout_s=connect_timeout_s, record=record)
    for done, (i, ok, value) in enumerate(outcomes, start=1):
        out[i] = value
        if not ok:
            failed.append((i, value))
        if on_progress is not None:
            on_progress(done, len(specs))
    if failed and errors == "raise":
        i, exc = min(failed, key=lambda x: x[0])
        raise BatchError(f"{len(failed)} of {len(specs)} runs failed; first: run {i}: "
                         f"{type(exc).__name__}: {exc}") from exc
    return out


def __getattr__(name: str):
    if name == "WarmUpPlugin":  # created on first use (distributed is optional)
        from . import dask_pool

        return dask_pool.WarmUpPlugin
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["run_batch", "iter_batch", "run_chunk", "make_pool", "SerialPool", "LocalPool", "DaskPool",
           "BatchError", "SchedulerError", "DistributedMissing", "specs_product", "as_spec", "warm_up",
           "start_forkserver", "available_cores", "auto_chunk_size", "chunked", "Compact", "CompactResult",
           "compact_signals", "check_scheduler", "FLOAT64_SIGNALS"]
