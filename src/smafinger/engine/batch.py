"""Batch engine: many runs in one call, in parallel, each bit-identical to the run made alone.

Every run is an ordinary :func:`~smafinger.engine.run.run_spec` call; the batch engine only
decides *where* it happens:

- ``workers=1``: one after the other in this process;
- ``workers=N`` (default: every core this process may use): ``N`` worker processes
  (:class:`concurrent.futures.ProcessPoolExecutor`, started with ``forkserver`` where
  available, else ``spawn``), each warmed up once (numba's compiled kernel loaded from its
  on-disk cache) before its first task;
- :class:`DaskPool`: the workers of an existing ``dask.distributed`` cluster (optional extra,
  ``pip install smafinger[distributed]``; imported only when used), warmed up once per
  worker by a worker plugin.

Runs travel in *chunks* (several runs per task) so that each task carries enough work to
hide the scheduling cost. A run never depends on which worker, chunk or order it ran in:
the kernel is deterministic and has no shared state, so its output is bit-identical to the
same run made alone.

>>> from smafinger.engine.batch import run_batch, specs_product
>>> specs = specs_product(["paper2010", "authors2020"], profiles=["0:-25", "0:-55"],
...                       strategy="cooperative", t_end_s=10.0)
>>> results = run_batch(specs, workers=2)  # doctest: +SKIP
"""

from __future__ import annotations

import math
import os
import signal
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Any, Callable, Iterable, Iterator, Sequence

from .run import RunSpec, make_spec, run_spec

#: a task: (key, spec); a chunk: a list of tasks; a task's outcome: (key, ok, value)
Task = tuple[Any, RunSpec]
Outcome = tuple[Any, bool, Any]

_WARM = False


class BatchError(RuntimeError):
    """A batch could not be completed (a run failed with ``errors="raise"``, a pool broke)."""


class DistributedMissing(ImportError):
    """``dask.distributed`` is needed (``--scheduler``) but not installed."""


# ---------------------------------------------------------------------------------------
# worker side
# ---------------------------------------------------------------------------------------
def warm_up() -> bool:
    """Load (or compile) the numba kernel in this process, once: a 2 ms run.

    Returns True if this call did the work, False if the process was already warm.
    """
    global _WARM
    if _WARM:
        return False
    run_spec(make_spec("paper2010", "cooperative", "0:-30", t_end_s=0.002))
    _WARM = True
    return True


def is_warm() -> bool:
    return _WARM


def _init_local_worker() -> None:
    # Ctrl-C goes to the whole process group: let only the parent handle it, so that it can
    # save what is done and stop the pool cleanly.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    warm_up()


def run_chunk(tasks: Sequence[Task], reduce: Callable | None = None) -> list[Outcome]:
    """Run a chunk of tasks here; the worker-side function of every backend.

    Each outcome is ``(key, True, value)`` with ``value = reduce(result)`` (the
    :class:`~smafinger.results.SimulationResult` itself without ``reduce``), or
    ``(key, False, exception)`` if the run (or ``reduce``) raised.
    """
    warm_up()
    out: list[Outcome] = []
    for key, spec in tasks:
        try:
            res = run_spec(spec)
            out.append((key, True, reduce(res) if reduce is not None else res))
        except Exception as exc:  # noqa: BLE001 - reported per run, the batch goes on
            out.append((key, False, exc))
    return out


# ---------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------
def available_cores() -> int:
    """Cores this process may run on (affinity-aware)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


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

    ``common`` holds the other :func:`make_spec` arguments (strategy, t_end_s, ...).
    """
    params = list(params)
    second = [("profile", p) for p in profiles] if profiles is not None else []
    second += [("voltage", v) for v in voltages] if voltages is not None else []
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


def chunked(tasks: Sequence[Task], size: int) -> list[list[Task]]:
    size = max(1, int(size))
    return [list(tasks[i:i + size]) for i in range(0, len(tasks), size)]


def auto_chunk_size(n_tasks: int, slots: int, per_slot: int = 16, lo: int = 1, hi: int = 64) -> int:
    """Runs per task: about ``per_slot`` tasks per worker slot, within [lo, hi].

    Many small tasks balance the end of a batch: with a run at about 7 ms, 16 tasks per
    slot keep a task near 50 ms (scheduling costs well under 1 ms locally and a few ms on
    Dask) while the last task leaves a worker idle for only that long.
    """
    if n_tasks <= 0:
        return 1
    return max(lo, min(hi, math.ceil(n_tasks / (max(1, slots) * per_slot))))


def _mp_context():
    import multiprocessing as mp

    methods = mp.get_all_start_methods()
    if "forkserver" in methods:
        ctx = mp.get_context("forkserver")
        # import numpy, numba and the engine once in the server; workers fork from it
        ctx.set_forkserver_preload(["smafinger.engine.batch"])
        return ctx
    return mp.get_context("spawn")  # pragma: no cover - Windows / macOS fallback


# ---------------------------------------------------------------------------------------
# pools
# ---------------------------------------------------------------------------------------
class SerialPool:
    """Runs the chunks one after the other in this process."""

    slots = 1

    def map_chunks(self, chunks: Iterable[list[Task]], reduce: Callable | None = None) -> Iterator[list[Outcome]]:
        for c in chunks:
            yield run_chunk(c, reduce)

    def close(self, cancel: bool = False) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close(cancel=exc[0] is not None)


class LocalPool(SerialPool):
    """A pool of worker processes on this machine (kept alive until :meth:`close`)."""

    def __init__(self, workers: int | None = None):
        self.slots = available_cores() if workers is None else workers
        if self.slots < 1:
            raise ValueError(f"workers = {workers!r} must be >= 1")
        # compile here first if numba's disk cache is stale: the workers then load it
        # instead of compiling all at once
        warm_up()
        self._ex = ProcessPoolExecutor(max_workers=self.slots, mp_context=_mp_context(),
                                       initializer=_init_local_worker)

    def start(self) -> "LocalPool":
        """Start and warm up every worker now (otherwise it happens with the first tasks)."""
        list(self._ex.map(_noop, range(self.slots)))
        return self

    def map_chunks(self, chunks, reduce=None):
        """Yield each chunk's outcomes as soon as it finishes (completion order)."""
        from concurrent.futures.process import BrokenProcessPool

        pending = {self._ex.submit(run_chunk, c, reduce) for c in chunks}
        try:
            while pending:
                done, pending = wait(pending, return_when=FIRST_COMPLETED)
                for f in done:
                    try:
                        yield f.result()
                    except BrokenProcessPool as exc:
                        raise BatchError(f"a worker process died ({exc}); finished runs are kept") from None
        finally:
            for f in pending:
                f.cancel()

    def close(self, cancel: bool = False) -> None:
        self._ex.shutdown(wait=True, cancel_futures=cancel)


def _noop(_):
    return os.getpid()


def _import_distributed():
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise DistributedMissing(
            "a Dask scheduler needs dask.distributed, which is not installed: "
            "pip install 'smafinger[distributed]'"
        ) from None
    return distributed


def __getattr__(name: str):
    # The worker plugin subclasses distributed.WorkerPlugin, so it is created on first use
    # (distributed stays an optional import); it is cached here so that pickles of it
    # resolve to the same class on the workers.
    if name == "WarmUpPlugin":
        distributed = _import_distributed()

        class WarmUpPlugin(distributed.WorkerPlugin):
            """Loads the numba kernel once per worker, when the worker starts."""

            name = "smafinger-warm-up"

            def setup(self, worker):  # noqa: D401
                warm_up()

        WarmUpPlugin.__module__ = __name__
        WarmUpPlugin.__qualname__ = "WarmUpPlugin"
        globals()["WarmUpPlugin"] = WarmUpPlugin
        return WarmUpPlugin
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _worker_info() -> dict:
    import smafinger

    return {"version": smafinger.__version__, "warm": is_warm(), "pid": os.getpid()}


class DaskPool(SerialPool):
    """Runs chunks on a ``dask.distributed`` cluster.

    ``address``: the scheduler (``tcp://HOST:PORT``) or an existing ``Client``. Every worker
    must be able to import the same version of smafinger. A worker lost mid-run is replaced
    by the cluster (its tasks are rescheduled on the others); results are only yielded once.
    """

    def __init__(self, address, timeout_s: float = 10.0):
        distributed = _import_distributed()
        self._distributed = distributed
        if isinstance(address, distributed.Client):
            self.client = address
            self._own = False
        else:
            try:
                self.client = distributed.Client(address, timeout=f"{timeout_s}s",
                                                 set_as_default=False)
            except (OSError, TimeoutError) as exc:
                raise BatchError(f"cannot connect to the Dask scheduler at {address}: {exc}") from None
            self._own = True
        warm_up()  # refreshes numba's disk cache, which workers on this machine then load
        try:
            self.client.register_plugin(__getattr__("WarmUpPlugin")(), name="smafinger-warm-up")
            info = self.client.run(_worker_info)
        except Exception as exc:
            self.close()
            raise BatchError(f"the Dask workers cannot run smafinger ({type(exc).__name__}: {exc}); "
                             "install smafinger on every worker") from None
        import smafinger

        bad = {w: i["version"] for w, i in info.items() if i["version"] != smafinger.__version__}
        if bad:
            self.close()
            raise BatchError(f"the Dask workers run other smafinger versions than {smafinger.__version__}: {bad}")

    @property
    def slots(self) -> int:
        n = sum(self.client.nthreads().values())
        return max(1, n)

    def map_chunks(self, chunks, reduce=None):
        futures = [self.client.submit(run_chunk, c, reduce, pure=False) for c in chunks]
        ac = self._distributed.as_completed(futures, loop=self.client.loop)
        try:
            for f in ac:
                try:
                    res = f.result()
                except Exception as exc:  # KilledWorker and the like
                    raise BatchError(f"a Dask task failed ({type(exc).__name__}: {exc}); finished runs are kept") from None
                f.release()
                yield res
        finally:
            left = [f for f in futures if not f.done()]
            if left:
                self.client.cancel(left)

    def close(self, cancel: bool = False) -> None:
        if self._own:
            self.client.close()


def make_pool(workers: int | None = None, scheduler=None):
    """:class:`DaskPool` with a scheduler, else :class:`SerialPool` for one worker, else
    :class:`LocalPool`."""
    if scheduler is not None:
        return DaskPool(scheduler)
    if workers is not None and workers < 1:
        raise ValueError(f"workers = {workers!r} must be >= 1")
    n = workers or available_cores()
    return SerialPool() if n == 1 else LocalPool(n)


# ---------------------------------------------------------------------------------------
# one-call API
# ---------------------------------------------------------------------------------------
def run_batch(runs: Iterable[RunSpec | dict], *, workers: int | None = None, scheduler=None,
              reduce: Callable | None = None, chunk_size: int | None = None,
              errors: str = "raise", pool=None) -> list:
    """Run many simulations in parallel; the results in input order.

    Parameters
    ----------
    runs : iterable of RunSpec or dict
        Validated specs (:func:`~smafinger.engine.run.make_spec`) or its keyword arguments.
    workers : int, optional
        Local worker processes (default: every available core; 1: in this process).
    scheduler : str or distributed.Client, optional
        Run on this Dask cluster instead.
    reduce : callable, optional
        Applied to each :class:`~smafinger.results.SimulationResult` in the worker, so that
        only what it returns travels back (must be picklable: a module-level function or a
        ``functools.partial`` of one). Default: the whole result.
    chunk_size : int, optional
        Runs per task (default: about four tasks per worker, at most 64 runs).
    errors : {"raise", "return"}
        A failed run raises :class:`BatchError` (after the others finished), or its
        exception is returned in its place.
    pool : optional
        A pool from :func:`make_pool` to reuse (kept open), e.g. in a loop of batches.
    """
    if errors not in ("raise", "return"):
        raise ValueError(f"errors = {errors!r} is not one of raise, return")
    specs = [as_spec(r) for r in runs]
    if not specs:
        return []
    own = pool is None
    if own:
        pool = make_pool(workers, scheduler)
    try:
        size = chunk_size or auto_chunk_size(len(specs), pool.slots)
        tasks = list(enumerate(specs))
        out: list[Any] = [None] * len(specs)
        failed: list[tuple[int, Exception]] = []
        for outcomes in pool.map_chunks(chunked(tasks, size), reduce):
            for i, ok, value in outcomes:
                out[i] = value
                if not ok:
                    failed.append((i, value))
    except BaseException:
        if own:
            pool.close(cancel=True)
        raise
    if own:
        pool.close()
    if failed and errors == "raise":
        i, exc = min(failed, key=lambda x: x[0])
        raise BatchError(f"{len(failed)} of {len(specs)} runs failed; first: run {i}: "
                         f"{type(exc).__name__}: {exc}") from exc
    return out


__all__ = ["run_batch", "run_chunk", "make_pool", "SerialPool", "LocalPool", "DaskPool", "BatchError",
           "DistributedMissing", "specs_product", "as_spec", "warm_up", "available_cores",
           "auto_chunk_size", "chunked"]
