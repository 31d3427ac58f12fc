"""Batch runs on a ``dask.distributed`` cluster (optional extra: ``pip install smafinger[distributed]``).

**Dask workers run pickled code sent by the client: connect only to a cluster you trust.**
The scheduler is checked before anything else (:func:`check_scheduler`): a malformed
address, a refused connection, or a port that is not a Dask scheduler fail fast, in one
line naming the address.
"""

from __future__ import annotations

import math
import os
import time
import warnings

from .pools import (CONNECT_TIMEOUT_S, IN_FLIGHT_PER_SLOT, BatchError, SchedulerError, SerialPool, _END,
                    _import_distributed, is_warm, warm_up)


#: how often the pool looks whether a task has finished while none has
IDLE_POLL_S = 1.0
#: with no task finished for this long, the pool says what the cluster has (then again as long)
IDLE_REPORT_S = 30.0
#: the longest --connect-timeout taken (a day)
MAX_CONNECT_TIMEOUT_S = 86400.0
#: the name of the worker plugin that loads the kernel on every worker (removed at the end)
PLUGIN_NAME = "smafinger-warm-up"


class WorkerVersionError(BatchError):
    """A worker runs another smafinger version than the client (one that joined after the start)."""


def checked_task(fn, item, version: str):
    """``fn(item)`` on a worker, once it is known to run the client's smafinger ``version``: a
    worker that joins the cluster after the pool's start is checked here, by each task."""
    import smafinger

    if smafinger.__version__ != version:
        raise WorkerVersionError(f"a Dask worker runs smafinger {smafinger.__version__}, the client {version}")
    return fn(item)


def _finished(ac, timeout_s: float) -> list:
    """The futures ``ac`` (an ``as_completed``) has finished, waiting at most ``timeout_s`` for
    one (on the condition its own blocking iteration waits on, a tenth of a second at a time)."""
    deadline = time.monotonic() + timeout_s
    while True:
        done = ac.next_batch(block=False)
        left = deadline - time.monotonic()
        if done or left <= 0:
            return done
        with ac.thread_condition:
            ac.thread_condition.wait(timeout=min(0.1, left))


def parse_scheduler_address(address: str) -> tuple[str, str, int | None]:
    """``(scheme, host, port)`` of ``[SCHEME://]HOST[:PORT]``; ValueError naming it if malformed."""
    text = str(address).strip()
    scheme, sep, rest = text.partition("://")
    if not sep:
        scheme, rest = "tcp", text
    if not scheme.isidentifier() or not rest or "/" in rest:
        raise ValueError(f"--scheduler {address!r}: expected an address like tcp://HOST:PORT")
    if rest.startswith("["):  # [IPv6]:PORT
        host, _, tail = rest[1:].partition("]")
        port_text = tail[1:] if tail.startswith(":") else None
    else:
        host, colon, port_text = rest.rpartition(":")
        if not colon:
            host, port_text = rest, None
    if not host:
        raise ValueError(f"--scheduler {address!r}: the host is missing (expected tcp://HOST:PORT)")
    port = None
    if port_text is not None:
        if not (port_text.isascii() and port_text.isdigit()) or not 1 <= int(port_text) <= 65535:  # not '²'
            raise ValueError(f"--scheduler {address!r}: port {port_text!r} is not a number in 1..65535")
        port = int(port_text)
    return scheme, host, port


def check_scheduler(address: str, timeout_s: float = CONNECT_TIMEOUT_S) -> str:
    """Fail fast unless a Dask scheduler answers at ``address`` within ``timeout_s``.

    Returns the normalised address. Raises :class:`SchedulerError` (one line, naming the
    address) if the address is malformed, refuses or drops the connection, or accepts it but
    does not answer as a Dask scheduler in time (``distributed.Client`` alone would wait
    forever there).
    """
    import asyncio
    import socket

    if not (isinstance(timeout_s, (int, float)) and 0 < timeout_s <= MAX_CONNECT_TIMEOUT_S):
        raise SchedulerError(f"--connect-timeout {timeout_s!r}: must be a number of seconds > 0 and at most "
                             f"{MAX_CONNECT_TIMEOUT_S:g}")
    try:
        scheme, host, port = parse_scheduler_address(address)
    except ValueError as exc:
        raise SchedulerError(str(exc)) from None
    port = 8786 if port is None else port
    shown = f"{scheme}://{host}:{port}" if ":" not in host else f"{scheme}://[{host}]:{port}"
    t0 = time.monotonic()
    if scheme in ("tcp", "tls"):
        try:
            socket.create_connection((host, port), timeout=timeout_s).close()
        except UnicodeError:  # a host name the IDNA codec refuses (a label over 63 characters)
            raise SchedulerError(f"--scheduler {address!r}: host {host!r} is not a valid host name") from None
        except OSError as exc:
            reason = "no answer" if isinstance(exc, TimeoutError) else (exc.strerror or str(exc))
            raise SchedulerError(f"cannot connect to the Dask scheduler at {shown}: {reason}") from None
    distributed = _import_distributed()

    async def identity():
        comm = await distributed.comm.connect(shown, timeout=timeout_s)
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    left = max(0.1, timeout_s - (time.monotonic() - t0))
    try:
        reply = asyncio.run(asyncio.wait_for(identity(), left))
    except (asyncio.TimeoutError, TimeoutError, OSError) as exc:
        # distributed's own connect gives up with an OSError "Timed out trying to connect ..."
        if not isinstance(exc, TimeoutError) and "timed out" not in str(exc).lower():
            raise SchedulerError(f"{shown} is not a Dask scheduler ({type(exc).__name__}: "
                                 f"{str(exc).splitlines()[0] if str(exc) else ''})") from None
        raise SchedulerError(f"{shown} accepts connections but is not a Dask scheduler "
                             f"(no answer within {timeout_s:g} s; see --connect-timeout)") from None
    except Exception as exc:  # noqa: BLE001 - any failure of the handshake is one line
        raise SchedulerError(f"{shown} is not a Dask scheduler ({type(exc).__name__}: "
                             f"{str(exc).splitlines()[0] if str(exc) else ''})") from None
    if not (isinstance(reply, dict) and reply.get("type") == "Scheduler"):
        kind = reply.get("type") if isinstance(reply, dict) else type(reply).__name__
        raise SchedulerError(f"{shown} is not a Dask scheduler (it says it is a {kind})")
    return shown


def __getattr__(name: str):
    # The worker plugin subclasses distributed.WorkerPlugin, so it is created on first use
    # (distributed stays an optional import); it is cached here so that pickles of it
    # resolve to the same class on the workers.
    if name == "WarmUpPlugin":
        distributed = _import_distributed()

        class WarmUpPlugin(distributed.WorkerPlugin):
            """Loads the numba kernel once per worker, when the worker starts."""

            name = PLUGIN_NAME

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
    """Runs tasks on a ``dask.distributed`` cluster.

    ``address``: the scheduler (``tcp://HOST:PORT``) or an existing ``Client``. Every worker
    must be able to import the same version of smafinger. A worker lost mid-run is replaced
    by the cluster (its tasks are rescheduled on the others); results are only yielded once.
    The worker count (:attr:`slots`) is read live from the scheduler.

    Dask workers run pickled code sent by the client: connect only to a cluster you trust.
    """

    def __init__(self, address, timeout_s: float = CONNECT_TIMEOUT_S):
        import smafinger

        distributed = _import_distributed()
        self._distributed = distributed
        self._slots, self._slots_at = 1, -1e9
        self._version = smafinger.__version__
        self._plugin = False
        #: called with a line of text while no task finishes (:data:`IDLE_REPORT_S`); a sweep
        #: sets its progress display's line, else a Python warning
        self.on_idle = lambda text: warnings.warn(text, RuntimeWarning, stacklevel=2)
        if isinstance(address, distributed.Client):
            self.client = address
            self._own = False
        else:
            shown = check_scheduler(address, timeout_s)
            try:
                self.client = distributed.Client(shown, timeout=f"{timeout_s}s", set_as_default=False)
            except Exception as exc:  # noqa: BLE001 - one line naming the address
                raise SchedulerError(f"cannot connect to the Dask scheduler at {shown}: "
                                     f"{type(exc).__name__}: {exc}") from None
            self._own = True
        self.address = getattr(self.client.scheduler, "address", str(address))
        warm_up()  # refreshes numba's disk cache, which workers on this machine then load
        try:
            self.client.register_plugin(__getattr__("WarmUpPlugin")(), name=PLUGIN_NAME)
            self._plugin = True
            info = self.client.run(_worker_info)
        except Exception as exc:
            self.close()
            raise BatchError(f"the Dask workers cannot run smafinger ({type(exc).__name__}: {exc}); "
                             "install smafinger on every worker") from None
        bad = {w: i["version"] for w, i in info.items() if i["version"] != self._version}
        if bad:
            self.close()
            raise BatchError(f"the Dask workers run other smafinger versions than {self._version}: {bad}")

    def threads(self) -> int | None:
        """Worker threads in the cluster now (0: none; None: the scheduler does not answer)."""
        try:
            return sum(self.client.nthreads().values())
        except Exception:  # noqa: BLE001 - a scheduler that is going away
            return None

    @property
    def slots(self) -> int:
        """Worker threads in the cluster now, for sizing (at least 1; asked again after 1 s)."""
        now = time.monotonic()
        if now - self._slots_at > 1.0:
            n = self.threads()
            if n is not None:  # a scheduler that is going away keeps the last count
                self._slots = max(1, n)
            self._slots_at = now
        return self._slots

    @property
    def dashboard_link(self) -> str | None:
        try:
            return self.client.dashboard_link
        except Exception:  # noqa: BLE001 - no dashboard (dashboard_address=None)
            return None

    def describe(self) -> str:
        return f"Dask scheduler {self.address} ({self.slots} worker threads)"

    def map_tasks(self, fn, items):
        """Yield each task's result as soon as it finishes; a few tasks per worker in flight.

        Each task first checks its worker's smafinger version (:func:`checked_task`). While no
        task finishes, :attr:`on_idle` is told every :data:`IDLE_REPORT_S` how many worker
        threads the cluster has (a cluster with none, or that lost them all, waits for workers:
        an adaptive cluster starts them on demand).
        """
        it = iter(items)
        ac = self._distributed.as_completed([], loop=self.client.loop)
        live: set = set()

        def fill() -> None:
            while len(live) < IN_FLIGHT_PER_SLOT * self.slots:
                item = next(it, _END)
                if item is _END:
                    return
                f = self.client.submit(checked_task, fn, item, self._version, pure=False)
                live.add(f)
                ac.add(f)

        try:
            fill()
            idle_since, report_at = time.monotonic(), IDLE_REPORT_S
            while live:
                done = _finished(ac, IDLE_POLL_S)
                if not done:
                    waited = time.monotonic() - idle_since
                    if waited >= report_at:
                        report_at += IDLE_REPORT_S
                        self.on_idle(self._idle_text(waited))
                    continue
                idle_since, report_at = time.monotonic(), IDLE_REPORT_S
                for f in done:
                    live.discard(f)
                    try:
                        res = f.result()
                    except WorkerVersionError as exc:
                        raise BatchError(f"{exc}: install the same version on every worker") from None
                    except Exception as exc:  # KilledWorker and the like
                        first = str(exc).splitlines()[0] if str(exc) else ""
                        raise BatchError(f"a Dask task failed ({type(exc).__name__}: {first})") from None
                    f.release()
                    yield res
                fill()
        finally:
            if live:
                self.client.cancel(list(live))

    def _idle_text(self, waited_s: float) -> str:
        n = self.threads()
        has = ("the scheduler does not answer" if n is None else
               f"the cluster has {n} worker thread{'s' if n != 1 else ''}")
        wait = "; waiting for workers (Ctrl-C stops; finished runs are kept)" if not n else ""
        return f"no Dask task has finished for {math.floor(waited_s):d} s: {has}{wait}"

    def close(self, cancel: bool = False) -> None:
        if self._plugin:  # a worker joining later must not load this client's plugin
            try:
                self.client.unregister_worker_plugin(PLUGIN_NAME)
            except Exception:  # noqa: BLE001 - a scheduler that is gone has no plugin left
                pass
            self._plugin = False
        if self._own:
            self.client.close()
