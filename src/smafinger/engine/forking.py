"""Where local worker processes come from; imports nothing but the standard library.

Workers fork from a *forkserver* (where the platform has one, else they are spawned): a process
that imports numpy, numba and the engine once and loads the compiled kernel if numba's disk
cache holds it (:mod:`.forkserver_warm`), so that every worker forked from it starts warm.
Doing that takes the forkserver 1.5-2 s; :func:`start_forkserver` starts it early, so that it
happens while the client goes on (importing, reading a sweep's spec, checking its points).
"""

from __future__ import annotations

import os

#: what the forkserver imports before it forks workers (the second loads the kernel)
PRELOAD = ("smafinger.engine.pools", "smafinger.engine.forkserver_warm")


def available_cores() -> int:
    """Cores this process may run on (affinity-aware)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def mp_context():
    """The multiprocessing context local workers start in: ``forkserver``, else ``spawn``."""
    import multiprocessing as mp

    if "forkserver" in mp.get_all_start_methods():
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(list(PRELOAD))
        return ctx
    return mp.get_context("spawn")  # pragma: no cover - Windows / macOS fallback


def start_forkserver(workers: int | None = None) -> None:
    """Start the forkserver now, in the background, if local workers will come from it:
    ``workers`` (default: every core) above 1 and a platform with a forkserver. It runs until
    this process ends; pools started later use it."""
    if (workers or available_cores()) <= 1 or mp_context().get_start_method() != "forkserver":
        return
    from multiprocessing import forkserver

    forkserver.ensure_running()
