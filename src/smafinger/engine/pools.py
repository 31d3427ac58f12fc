"""Where batch runs happen: this process, local worker processes, or a Dask cluster.

A pool runs *tasks* (one call of a picklable function on one item, typically a chunk of
runs) and yields their outcomes as they finish. It never holds more than a few tasks per
worker in flight: the items are drawn lazily from their iterable, so a batch of 10^6 runs
is never all in memory at once.

- :class:`SerialPool`: one after the other in this process;
- :class:`LocalPool`: worker processes (``forkserver`` where available, else ``spawn``;
  :mod:`.forking`), each warm (numba's compiled kernel loaded from its on-disk cache, once in
  the forkserver) and each watching its client: if the client dies, even by SIGKILL, its
  workers exit at once, and with them the forkserver and multiprocessing's resource tracker;
- :class:`~.dask_pool.DaskPool`: the workers of a ``dask.distributed`` cluster (optional extra,
  ``pip install smafinger[distributed]``; imported only when used). **Dask workers run
  pickled code sent by the client: connect only to a cluster you trust.**
"""

from __future__ import annotations

import os
import pickle
import signal
import threading
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from functools import partial
from typing import Any, Callable, Iterable, Iterator, Sequence

from ..values import is_whole
from .forking import available_cores, mp_context, start_forkserver  # noqa: F401 (re-exported)
from .run import RunSpec, kernel_cached, make_spec, run_spec

#: a task: (key, spec or recipe); a chunk: a list of tasks; a task's outcome: (key, ok, value)
Task = tuple[Any, Any]
Outcome = tuple[Any, bool, Any]
#: tasks in flight per worker slot: one running, one queued behind it
IN_FLIGHT_PER_SLOT = 2
#: default time to connect to a Dask scheduler (CLI: --connect-timeout)
CONNECT_TIMEOUT_S = 10.0

#: the process that loaded the kernel into this one's memory: this one, or the forkserver a worker
#: was forked from (:mod:`.forkserver_warm`); None until then
_WARMED_IN: int | None = None


class BatchError(RuntimeError):
    """A batch could not be completed (a run failed with ``errors="raise"``, a pool broke)."""


class DistributedMissing(ImportError):
    """``dask.distributed`` is needed (``--scheduler``) but not installed."""


class SchedulerError(BatchError):
    """The Dask scheduler address is malformed, unreachable, or not a Dask scheduler."""


def _import_distributed():
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise DistributedMissing(
            "a Dask scheduler needs dask.distributed, which is not installed: "
            "pip install 'smafinger[distributed]'"
        ) from None
    return distributed


# ---------------------------------------------------------------------------------------
# worker side
# ---------------------------------------------------------------------------------------
def warm_up() -> bool:
    """Load (or compile) the numba kernel in this process, once: a 2 ms run.

    Returns True if this call did the work, False if the process was already warm.
    """
    global _WARMED_IN
    if _WARMED_IN is not None:
        return False
    run_spec(_warm_up_spec())
    _WARMED_IN = os.getpid()
    return True


def _warm_up_spec() -> RunSpec:
    return make_spec("paper2010", "cooperative", "0:-30", t_end_s=0.002)


def warm_up_cached() -> bool:
    """Whether :func:`warm_up` would load the kernel (from numba's disk cache), not compile it."""
    return kernel_cached(_warm_up_spec())


def is_warm() -> bool:
    return _WARMED_IN is not None


def warmed_in(_=None) -> tuple[int, int | None]:
    """(this process's id, the id of the process that loaded the kernel here: :data:`_WARMED_IN`).
    The argument is ignored, so that it can be mapped over tasks (:meth:`LocalPool.start`)."""
    return os.getpid(), _WARMED_IN


def build_spec(item) -> RunSpec:
    """A :class:`RunSpec` from a spec or a *recipe* (an object whose ``build()`` makes one).

    Recipes let the validation of each run happen in the worker that runs it.
    """
    if isinstance(item, RunSpec):
        return item
    build = getattr(item, "build", None)
    if callable(build):
        return build()
    raise TypeError(f"a batch item must be a RunSpec or a recipe with build(), not {type(item).__name__}")


def run_chunk(tasks: Sequence[Task], reduce: Callable | None = None, record: str = "all") -> list[Outcome]:
    """Run a chunk of tasks here; the worker-side function of :func:`run_batch`.

    Each outcome is ``(key, True, value)`` with ``value = reduce(result)`` (the
    :class:`~smafinger.results.SimulationResult` itself without ``reduce``), or
    ``(key, False, exception)`` if building the spec, the run or ``reduce`` raised. ``record``:
    the signals each run records (:func:`~smafinger.engine.run.run_spec`).
    """
    warm_up()
    out: list[Outcome] = []
    for key, item in tasks:
        try:
            res = run_spec(build_spec(item), record=record)
            out.append((key, True, reduce(res) if reduce is not None else res))
        except Exception as exc:  # noqa: BLE001 - reported per run, the batch goes on
            out.append((key, False, exc))
    return out


def watch_parent() -> threading.Thread | None:
    """Exit this worker process as soon as the process that started it dies.

    A worker blocked on its task queue would otherwise live on after a SIGKILL of its
    client, and keep the forkserver and the resource tracker alive too (both wait for
    every holder of their pipes to exit). ``multiprocessing.parent_process()`` is the
    client under ``forkserver`` and ``spawn`` alike, and its ``join()`` returns when the
    client is gone (its sentinel pipe closes), on every platform.
    """
    import multiprocessing as mp

    parent = mp.parent_process()
    if parent is None:
        return None

    def wait_and_exit() -> None:
        parent.join()
        os._exit(1)

    th = threading.Thread(target=wait_and_exit, name="smafinger-parent-watch", daemon=True)
    th.start()
    return th


def _init_local_worker() -> None:
    watch_parent()
    # Ctrl-C goes to the whole process group: let only the parent handle it, so that it can
    # save what is done and stop the pool cleanly.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    warm_up()


# ---------------------------------------------------------------------------------------
# pools
# ---------------------------------------------------------------------------------------
class SerialPool:
    """Runs the tasks one after the other in this process."""

    slots = 1
    dashboard_link: str | None = None

    def describe(self) -> str:
        return "this process"

    def map_tasks(self, fn: Callable, items: Iterable) -> Iterator:
        """``fn(item)`` for each item, yielded as each finishes (here: in order)."""
        for item in items:
            yield fn(item)

    def map_chunks(self, chunks: Iterable[list[Task]], reduce: Callable | None = None,
                   record: str = "all") -> Iterator[list[Outcome]]:
        """Each chunk's outcomes (:func:`run_chunk`) as soon as it finishes."""
        return self.map_tasks(partial(run_chunk, reduce=reduce, record=record), chunks)

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
        start_forkserver(self.slots)  # its imports and warm-up overlap the warm-up here
        # compile here first if numba's disk cache is stale: the workers then load it
        # instead of compiling all at once
        warm_up()
        self._ex = ProcessPoolExecutor(max_workers=self.slots, mp_context=mp_context(),
                                       initializer=_init_local_worker)

    def describe(self) -> str:
        return f"{self.slots} local worker process{'es' if self.slots > 1 else ''}"

    def map_chunks(self, chunks, reduce=None, record="all"):
        """As :meth:`SerialPool.map_chunks`; ``reduce`` must pickle, since it runs in the workers
        (TypeError before any task is sent: a lambda ran with one worker and failed with two)."""
        if reduce is not None:
            try:
                pickle.dumps(reduce)
            except Exception as exc:
                raise TypeError(f"reduce = {reduce!r} cannot be sent to the worker processes ({exc}): give a "
                                "function defined at a module's top level, a functools.partial of one, or "
                                "Compact(...)") from None
        return super().map_chunks(chunks, reduce, record)

    def start(self) -> "LocalPool":
        """Start and warm up every worker now (otherwise it happens with the first tasks)."""
        list(self._ex.map(warmed_in, range(self.slots)))
        return self

    def map_tasks(self, fn, items):
        """Yield each task's result as soon as it finishes (completion order)."""
        from concurrent.futures.process import BrokenProcessPool

        it = iter(items)
        pending: set = set()
        undelivered = 0  # finished tasks whose outcome is not yet yielded: held here too

        def fill() -> None:
            # the bound covers every task drawn and not yet delivered, running or finished
            while len(pending) + undelivered < IN_FLIGHT_PER_SLOT * self.slots:
                item = next(it, _END)
                if item is _END:
                    return
                pending.add(self._ex.submit(fn, item))

        try:
            fill()
            while pending:
                done, pending_left = wait(pending, return_when=FIRST_COMPLETED)
                pending.clear()
                pending.update(pending_left)
                undelivered = len(done)
                for f in done:
                    try:
                        res = f.result()
                    except BrokenProcessPool as exc:
                        raise BatchError(f"a worker process died ({exc})") from None  # the caller says what it kept
                    undelivered -= 1
                    fill()
                    yield res
        finally:
            for f in pending:
                f.cancel()

    def close(self, cancel: bool = False) -> None:
        self._ex.shutdown(wait=True, cancel_futures=cancel)


_END = object()


def make_pool(workers: int | None = None, scheduler=None, connect_timeout_s: float = CONNECT_TIMEOUT_S):
    """:class:`DaskPool` with a scheduler, else :class:`SerialPool` for one worker, else
    :class:`LocalPool`."""
    if scheduler is not None:
        from .dask_pool import DaskPool

        return DaskPool(scheduler, timeout_s=connect_timeout_s)
    if workers is not None and not is_whole(workers):
        raise TypeError(f"workers = {workers!r} must be an integer >= 1 (or None: every core)")
    if workers is not None and workers < 1:
        raise ValueError(f"workers = {workers!r} must be >= 1")
    n = workers or available_cores()
    return SerialPool() if n == 1 else LocalPool(n)
