"""The compiled kernel's entry points, looked up once per kernel, and whether numba's JIT is on."""

from __future__ import annotations

import os

from numba import config as numba_config, typeof

from .kernel import run_kernel

#: numba's JIT is disabled in this process: the kernel runs as Python (:mod:`.interpreted`)
INTERPRETED = bool(numba_config.DISABLE_JIT)


class CompiledKernels:
    """The kernel compiled (or loaded from numba's cache) once per mechanism, then called directly.

    numba types every argument at every call, and typing the nested records costs about a
    millisecond; their types depend only on the mechanism and the controller's record type
    (every value is a float, every option an enum member), so the entry point is looked up once
    per mechanism, wire count and controller (:func:`.run.kernel_key`). With numba's JIT disabled
    (the interpreted engine, :mod:`.interpreted`) the kernel is its Python function.
    """

    def __init__(self) -> None:
        self._entry: dict[tuple, object] = {}

    def __call__(self, key: tuple, args: tuple):
        fn = self._entry.get(key)
        if fn is None and INTERPRETED:
            fn = self._entry[key] = run_kernel
        if fn is None:
            sig = tuple(typeof(a) for a in args)
            run_kernel.compile(sig)
            fn = self._entry[key] = run_kernel.overloads[sig].entry_point
        return fn

    def cached(self, key: tuple, args: tuple) -> bool:
        """Is the kernel for these arguments loaded, or in numba's cache (so no compile is needed)?

        Reads the cache's index as numba's ``Dispatcher.compile`` does before compiling, and
        checks that the kernel's data file is there too (numba writes the index first); if that
        fails (another numba version), says yes: the caller then compiles as before.
        """
        if key in self._entry or INTERPRETED:
            return True
        try:
            sig = tuple(typeof(a) for a in args)
            cache = run_kernel._cache
            run_kernel.targetctx.refresh()
            index = cache._cache_file._load_index()
            data = index.get(cache._index_key(sig, run_kernel.targetctx.codegen()))
            return data is not None and os.path.exists(os.path.join(cache._cache_path, data))
        except Exception:  # noqa: BLE001 - a numba internal changed: compile as before
            return True


#: the kernels this process has looked up
kernels = CompiledKernels()
