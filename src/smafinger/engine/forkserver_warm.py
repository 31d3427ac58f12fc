"""Imported once by the forkserver local workers fork from (:data:`.forking.PRELOAD`).

It loads the compiled kernel there, from numba's disk cache, so that every worker forked from
it starts warm instead of loading the kernel itself (about 0.8 s a worker, numba's registries
included). A kernel not in the cache is not compiled here: the client compiles it
(:class:`.pools.LocalPool`) and the workers load it as they start.
"""

from .pools import warm_up, warm_up_cached

try:
    if warm_up_cached():
        warm_up()
except Exception:  # noqa: BLE001 - the workers then warm up themselves, and report what fails
    pass
