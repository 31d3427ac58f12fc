"""What a running sweep tells its user, on the common :class:`smafinger.progress.Display`.

A live bar on a terminal; in a batch job's log (not a terminal) a line such as ``sweep fig8:
120/231 runs (52%), 0 failed, 4.1 s elapsed, about 3.8 s left, 2 workers`` every
``interval_s``, with the worker count read live (a cluster that loses a worker says so).
"""

from __future__ import annotations

from ..progress import Display


class Progress:
    """Progress of one sweep on a rich ``console`` (nothing without one): ``bar`` a live bar,
    else plain lines every ``interval_s``."""

    def __init__(self, console, bar: bool, interval_s: float, name: str):
        mode = "off" if console is None else ("bar" if bar else "lines")
        self.display = Display(mode, console, interval_s, transient=False)
        self.name = name
        self._task = None

    def line(self, text: str) -> None:
        self.display.line(text)

    def watch(self, pool) -> None:
        """A pool that reports waits (a Dask cluster with no task finishing) reports them here."""
        if hasattr(pool, "on_idle") and self.display.mode != "off":
            pool.on_idle = self.line

    def pool(self, pool) -> None:
        link = getattr(pool, "dashboard_link", None)
        if link:
            self.line(f"Dask dashboard: {link}")

    def start(self, total: int, done: int) -> None:
        self._task = self.display.task(f"sweep {self.name}", total, "runs", done=done, note="0 failed")

    def update(self, done: int, failed: int, pool) -> None:
        if self._task is not None:
            self._task.update(completed=done, note=f"{failed} failed", suffix=f"{pool.slots} workers")

    def stop(self) -> None:
        self.display.stop()
