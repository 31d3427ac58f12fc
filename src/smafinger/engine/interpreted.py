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
  that follow; a longer run compiles first, and so does a run whose child process fails
  (:class:`InterpretedFailure`: the package not importable there, say).

An interpreted run shows no progress bar.
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

#: interpreted cost of a sub-step [s], and of each integrator stage in it (a conservative fit to
#: the paper's full cycle, 45 s, on a 2-core machine: 1.2 s at the long step, 9,003 one-stage
#: sub-steps, estimated 1.2 s; 14.2 s at rk4 1 ms, 83,282 four-stage sub-steps, estimated 24 s)
S_PER_SUBSTEP = 90e-6
S_PER_STAGE = 45e-6
#: ``auto`` interprets a run estimated to take at most this long [s]; a kernel compiles in 40-50 s
INTERPRETED_LIMIT_S = 30.0


class InterpretedFailure(RuntimeError):
    """The interpreted engine's child process failed (not the run: a blow-up is a SimulationError)."""


def engine_setting(engine: str | None) -> str:
    """The engine to use: ``engine`` if given, else ``$SMAFINGER_ENGINE``, else ``auto``."""
    source = "engine"
    if engine is None:
        engine, source = os.environ.get(ENGINE_ENV, "auto"), ENGINE_ENV
    if engine not in ENGINES:
        raise ValueError(f"{source} = {engine!r} is not one of {', '.join(ENGINES)}")
    return engine


def interpreted_estimate_s(spec) -> float:
    """The interpreted run's expected duration [s] from its sub-steps: one per step and, with the
    PWM resolved at its edges, about one more per PWM period (its duty edge)."""
    substeps = spec.t_end_s / spec.dt_s
    if spec.pwm == "exact":
        substeps += spec.t_end_s / spec.params.pwm_period_s
    return substeps * (S_PER_SUBSTEP + integrators.get(spec.method).stages * S_PER_STAGE)


def choose(engine: str, cached: bool, spec) -> str:
    """``compiled`` or ``interpreted`` for a run under the setting ``engine`` (see the module
    docstring); ``cached``: the compiled kernel is in numba's cache (or already loaded)."""
    if engine != "auto":
        return engine
    if cached or interpreted_estimate_s(spec) > INTERPRETED_LIMIT_S:
        return "compiled"
    return "interpreted"


def child_env(mode: str) -> dict:
    """The environment of a child process: this one's, with this process's ``sys.path`` (so that
    it imports the package this process imported), and numba's JIT disabled to ``run``."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_JIT"}
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    if mode == "run":
        env["NUMBA_DISABLE_JIT"] = "1"
    return env


def _child(mode: str, stderr=subprocess.PIPE) -> subprocess.Popen:
    """``python -m`` this module in ``mode`` (:func:`child_env`); a ``build`` is detached from this process."""
    detached = mode == "build"
    return subprocess.Popen([sys.executable, "-m", __name__, mode], env=child_env(mode), stdin=subprocess.PIPE,
                            stdout=subprocess.DEVNULL if detached else subprocess.PIPE, stderr=stderr,
                            start_new_session=detached)


def run_interpreted(spec):
    """The :class:`~smafinger.results.SimulationResult` of ``spec``, run interpreted in a child process.

    Raises what the run raises there (:class:`~smafinger.engine.run.SimulationError` for a
    blow-up, with the time and the state).
    """
    proc = _child("run")
    try:
        out, err = proc.communicate(pickle.dumps(spec))
    except BaseException:  # an interrupt (Ctrl-C in a notebook reaches this process only)
        proc.kill()
        proc.wait()
        raise
    if proc.returncode != 0 or not out:
        raise InterpretedFailure(f"the interpreted engine's process failed (exit status {proc.returncode}): "
                                 f"{err.decode(errors='replace').strip()[-2000:]}")
    try:
        status, value = pickle.loads(out)
    except Exception as exc:  # noqa: BLE001 - a garbled answer
        raise InterpretedFailure(f"the interpreted engine's answer could not be read: {exc}") from None
    if status == "error":
        raise value
    return value


def build_in_background(spec) -> None:
    """Compile (into numba's cache) the kernel ``spec`` needs, in a detached process that outlives
    this one; it does nothing if another process is compiling the same kernel. What it prints
    (a failed compile) goes to ``<temp>/smafinger-build-<user>-<kernel>.log``."""
    try:
        with open(_build_path(spec, ".log"), "wb") as log:
            proc = _child("build", stderr=log)
        proc.stdin.write(pickle.dumps(spec))
        proc.stdin.close()
    except OSError:  # no log or no child: the next run compiles, as before this module
        return


def _build_path(spec, suffix: str) -> Path:
    """A file per user, kernel, numba cache folder and Python (one build at a time): the lock, the log."""
    from .run import kernel_key
    key = repr((kernel_key(spec), os.environ.get("NUMBA_CACHE_DIR", ""), sys.executable, sys.path))
    user = os.getuid() if hasattr(os, "getuid") else os.getlogin()
    return Path(tempfile.gettempdir()) / f"smafinger-build-{user}-{hashlib.sha1(key.encode()).hexdigest()[:16]}{suffix}"


def _locked(file) -> bool:
    """Take the lock on an open file; False if another process holds it (no lock off POSIX)."""
    try:
        import fcntl
    except ImportError:
        return True
    try:
        fcntl.flock(file, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return False
    return True


def _build(spec) -> None:
    from .run import compile_kernel
    with open(_build_path(spec, ".lock"), "w") as lock:
        if _locked(lock):  # else another process is compiling it
            compile_kernel(spec)


def _blow_up(spec, exc: ArithmeticError | ValueError):
    """The :class:`~smafinger.engine.run.SimulationError` for a math error inside the kernel, or
    None if it was raised elsewhere. Python's ``math`` raises (an overflow, ``cos(inf)``) where
    compiled code gives Inf or NaN, which the kernel reports as a blow-up; the time and the state
    here are the kernel's at the start of the sub-step that failed (its frame's locals)."""
    from .run import SimulationError, describe_state

    tb, frame = exc.__traceback__, None
    while tb is not None:
        if tb.tb_frame.f_code.co_name == "run_kernel":
            frame = tb.tb_frame
        tb = tb.tb_next
    if frame is None:
        return None
    ticks = frame.f_locals.get("a", frame.f_locals.get("t"))  # a sub-step's start, or its tick's
    if ticks is None:
        return None
    t_s = ticks * frame.f_locals["run"].tick_s
    return SimulationError(f"numerical blow-up at t = {t_s:.9g} s ({type(exc).__name__}: {exc}, in the sub-step "
                           f"from there): {describe_state(spec.params, frame.f_locals['y'])}")


def _run(spec) -> tuple:
    from .run import run_spec
    try:
        return "ok", run_spec(spec, engine="compiled")
    except Exception as exc:  # noqa: BLE001 - sent to the parent, which raises it
        if isinstance(exc, (ArithmeticError, ValueError)):
            exc = _blow_up(spec, exc) or exc
        try:
            pickle.loads(pickle.dumps(exc))
        except Exception:  # noqa: BLE001
            exc = RuntimeError(f"{type(exc).__name__}: {exc}")
        return "error", exc


def _main(mode: str) -> None:
    spec = pickle.loads(sys.stdin.buffer.read())
    if mode == "build":
        _build(spec)
        return
    result = os.fdopen(os.dup(1), "wb")  # the result's channel; anything else printed goes to stderr
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    answer = _run(spec)
    result.write(pickle.dumps(answer))
    result.flush()


if __name__ == "__main__":
    _main(sys.argv[1])
