"""Imported once by the forkserver local workers fork from (:data:`.forking.PRELOAD`).

It loads the compiled kernel there, from numba's disk cache, so that every worker forked from
it starts warm instead of loading the kernel itself (about 0.8 s a worker, numba's registries
included). A kernel not in the cache is not compiled here: the client compiles it
(:class:`.pools.LocalPool`) and the workers load it as they start.

It is imported in the forkserver only: it makes the process that imports it ignore Ctrl-C.
"""

import signal

# Ctrl-C goes to the whole process group, the forkserver included: it is for the client to
# handle (the forkserver itself ignores SIGINT once its preload is done). The client spawned
# this process with SIGINT blocked (:func:`.forking.start_forkserver`), so that a Ctrl-C during
# the imports so far was held, not raised: ignoring it discards it, and unblocking it then
# leaves the mask as the workers forked from here had it before.
signal.signal(signal.SIGINT, signal.SIG_IGN)
if hasattr(signal, "pthread_sigmask"):
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})

from .pools import warm_up, warm_up_cached  # noqa: E402 - after the signal set-up above

try:
    if warm_up_cached():
        warm_up()
except Exception:  # noqa: BLE001 - the workers then warm up themselves, and report what fails
    pass
