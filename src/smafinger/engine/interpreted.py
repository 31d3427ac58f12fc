"""The engine interpreted: the same kernel as plain Python, in a child process, while numba compiles.

numba compiles the kernel on its first use for a mechanism, wire count and controller type and
caches it (``__pycache__`` beside the sources, or ``NUMBA_CACHE_DIR``): 40-50 s per kernel on a
2-core machine. Until then a short run is quicker interpreted. The child process imports the
package with ``NUMBA_DISABLE_JIT=1``: every ``@njit`` function is then its Python source and
every ``@overload`` helper its Python body (the same dispatch tables), so it runs the same
equations in the same order. Its signals agree with the compiled kernel's to rounding (the
compiler may fuse a multiply and an add; ``tests/test_interpreted.py``).

Engines (:func:`~smafinger.engine.run.simulate` ``engine=``, ``smafinger simulate --engine``; the
default comes from the environment variable ``SMAFINGER_ENGINE``, else ``auto``):

- ``compiled``: the compiled kernel, compiled first if it is not cached;
- ``interpreted``: the child process, whatever the cache holds;
- ``auto``: the compiled kernel if it is cached; otherwise the run interpreted when
  :func:`interpreted_estimate_s` is at most :data:`INTERPRETED_LIMIT_S`, with the kernel
  compiled meanwhile by a detached background process (one per kernel at a time) for the runs
  that follow; a longer run compiles first.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import subprocess
import sys
import tempfile
from pathlib import Path

from . import integrators
from .defaults import ENGINE_ENV, ENGINES
#: interpreted cost per integrator stage of a step [s]: measured on a 2-core machine, the
#: paper's full cycle (45 s) took 1.2 s at the long step (9,000 one-stage steps: 133 us) and
#: 14.2 s at rk4 1 ms (45,000 four-stage steps and their PWM edges: 79 us); the larger is used
S_PER_STAGE = 140e-6
#: ``auto`` interprets a run estimated to take at most this long [s]; a kernel compiles in 40-50 s
INTERPRETED_LIMIT_S = 30.0


def engine_setting(engine: str | None) -> str:
    """The engine to use: ``engine`` if given, else ``$SMAFINGER_ENGINE``, else ``auto``."""
    source = "engine"
    if engine is None:
        engine, source = os.environ.get(ENGINE_ENV, "auto"), ENGINE_ENV
    if engine not in ENGINES:
        raise ValueError(f"{source} = {engine!r} is not one of {', '.join(ENGINES)}")
    return engine


def interpreted_estimate_s(spec) -> float:
    """The interpreted run's expected duration [s]: steps x the integrator's stages x :data:`S_PER_STAGE`."""
    return spec.t_end_s / spec.dt_s * integrators.get(spec.method).stages * S_PER_STAGE


def choose(engine: str, cached: bool, spec) -> str:
    """``compiled`` or ``interpreted`` for a run under the setting ``engine`` (see the module
    docstring); ``cached``: the compiled kernel is in numba's cache (or already loaded)."""
    if engine != "auto":
        return engine
    if cached or interpreted_estimate_s(spec) > INTERPRETED_LIMIT_S:
        return "compiled"
    return "interpreted"


def _child(mode: str) -> subprocess.Popen:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_JIT"}
    if mode == "run":
        env["NUMBA_DISABLE_JIT"] = "1"
    detached = mode == "build"
    return subprocess.Popen([sys.executable, "-m", __name__, mode], env=env, stdin=subprocess.PIPE,
                            stdout=subprocess.DEVNULL if detached else subprocess.PIPE,
                            stderr=subprocess.DEVNULL if detached else subprocess.PIPE,
                            start_new_session=detached)


def run_interpreted(spec):
    """The :class:`~smafinger.results.SimulationResult` of ``spec``, run interpreted in a child process.

    Raises what the run raises there (:class:`~smafinger.engine.run.SimulationError` for a
    blow-up, with the time and the state).
    """
    proc = _child("run")
    out, err = proc.communicate(pickle.dumps(spec))
    if proc.returncode != 0 or not out:
        raise RuntimeError(f"the interpreted engine's process failed (exit status {proc.returncode}): "
                           f"{err.decode(errors='replace').strip()[-2000:]}")
    status, value = pickle.loads(out)
    if status == "error":
        raise value
    return value


def build_in_background(spec) -> None:
    """Compile (into numba's cache) the kernel ``spec`` needs, in a detached process that outlives
    this one; it does nothing if another process is compiling the same kernel."""
    proc = _child("build")
    proc.stdin.write(pickle.dumps(spec))
    proc.stdin.close()


def _lock_path(spec) -> Path:
    """A lock file per kernel and numba cache folder (one build at a time)."""
    from .run import kernel_key
    key = repr((kernel_key(spec), os.environ.get("NUMBA_CACHE_DIR", ""), sys.executable))
    return Path(tempfile.gettempdir()) / f"smafinger-build-{hashlib.sha1(key.encode()).hexdigest()[:16]}.lock"


def _build(spec) -> None:
    from .run import compile_kernel
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        compile_kernel(spec)
        return
    with open(_lock_path(spec), "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return  # another process is compiling it
        compile_kernel(spec)


def _overflow_error(spec, exc: OverflowError):
    """The :class:`~smafinger.engine.run.SimulationError` for an overflow: Python's ``math`` raises
    where the compiled code gives Inf (which the kernel reports as a blow-up). The time and the
    state are the kernel's at the start of the sub-step that overflowed (its frame's locals)."""
    from .run import SimulationError, describe_state

    tb, frame = exc.__traceback__, None
    while tb is not None:
        if tb.tb_frame.f_code.co_name == "run_kernel":
            frame = tb.tb_frame
        tb = tb.tb_next
    if frame is None:
        return SimulationError(f"numerical blow-up (overflow: {exc})")
    t_s = frame.f_locals["a"] * frame.f_locals["run"].tick_s
    return SimulationError(f"numerical blow-up at t = {t_s:.9g} s (an overflow, {exc}, in the sub-step from "
                           f"there): {describe_state(spec.params, frame.f_locals['y'])}")


def _run(spec) -> tuple:
    from .run import run_spec
    try:
        return "ok", run_spec(spec, engine="compiled")
    except OverflowError as exc:
        return "error", _overflow_error(spec, exc)
    except Exception as exc:  # noqa: BLE001 - sent to the parent, which raises it
        try:
            pickle.dumps(exc)
        except Exception:  # noqa: BLE001
            exc = RuntimeError(f"{type(exc).__name__}: {exc}")
        return "error", exc


def _main(mode: str) -> None:
    spec = pickle.loads(sys.stdin.buffer.read())
    if mode == "build":
        _build(spec)
        return
    stdout, sys.stdout = sys.stdout, sys.stderr  # nothing but the result on stdout
    answer = _run(spec)
    stdout.buffer.write(pickle.dumps(answer))
    stdout.flush()


if __name__ == "__main__":
    _main(sys.argv[1])
