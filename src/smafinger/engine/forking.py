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
    this process ends; pools started later use it.

    The forkserver starts with SIGINT blocked (this thread's signal mask while it is spawned,
    which a new process inherits): it is in this process's process group, which a terminal's
    Ctrl-C reaches whole, and a Ctrl-C in the 1.5-2 s of its imports killed it with a traceback
    of those imports. :mod:`.forkserver_warm` then ignores SIGINT there and unblocks it, so that
    the workers forked from it have it unblocked as before (and ignored from their start, not
    only from the pool's worker initializer on). This process's mask is restored at once: a
    Ctrl-C that came meanwhile is delivered here then, as usual.
    """
    if (workers or available_cores()) <= 1 or mp_context().get_start_method() != "forkserver":
        return
    import signal
    from multiprocessing import forkserver, resource_tracker

    # first, on its own: it unblocks SIGINT in this thread as it ends (it does the same for
    # its own process), which would undo the mask below if forkserver.ensure_running() did it
    resource_tracker.ensure_running()
    sigmask = getattr(signal, "pthread_sigmask", None)
    old = sigmask(signal.SIG_BLOCK, {signal.SIGINT}) if sigmask is not None else None
    try:
        forkserver.ensure_running()
    finally:
        if sigmask is not None:
            sigmask(signal.SIG_SETMASK, old)
