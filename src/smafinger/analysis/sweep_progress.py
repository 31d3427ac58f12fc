"""What a running sweep tells its user: a live bar on a terminal, plain lines otherwise.

A batch job's log is not a terminal: there a line such as ``sweep fig8: 120/231 runs (52%),
0 failed, 4.1 s elapsed, about 3.8 s left, 2 workers`` is printed every ``interval_s``, with
the worker count read live (a cluster that loses a worker says so).
"""

from __future__ import annotations

import time


def _duration(s: float) -> str:
    if s != s or s == float("inf"):  # NaN / inf
        return "?"
    if s < 120:
        return f"{s:.1f} s"
    if s < 7200:
        return f"{s / 60:.1f} min"
    return f"{s / 3600:.1f} h"


class Progress:
    """Progress of one sweep on a rich ``console`` (nothing without one)."""

    def __init__(self, console, bar: bool, interval_s: float, name: str):
        if not interval_s > 0:
            raise ValueError(f"progress interval {interval_s!r} s must be > 0")
        self.console, self.interval_s, self.name = console, interval_s, name
        self._bar = self._task = None
        self._want_bar = bool(bar) and console is not None
        self.total = self.done0 = 0
        self.t0 = self.last = time.monotonic()

    def line(self, text: str) -> None:
        if self.console is not None:
            self.console.print(text, highlight=False, soft_wrap=True)

    def pool(self, pool) -> None:
        link = getattr(pool, "dashboard_link", None)
        if link:
            self.line(f"Dask dashboard: {link}")

    def start(self, total: int, done: int) -> None:
        self.total, self.done0 = total, done
        self.t0 = self.last = time.monotonic()
        if self._want_bar:
            from rich.progress import (BarColumn, MofNCompleteColumn, Progress as Bar, TextColumn,
                                       TimeElapsedColumn, TimeRemainingColumn)

            self._bar = Bar(TextColumn("sweep"), BarColumn(), MofNCompleteColumn(), TextColumn("runs"),
                            TimeElapsedColumn(), TextColumn("eta"), TimeRemainingColumn(), console=self.console)
            self._task = self._bar.add_task("sweep", total=total, completed=done)
            self._bar.start()

    def update(self, done: int, failed: int, pool) -> None:
        if self._bar is not None:
            self._bar.update(self._task, completed=done)
            return
        now = time.monotonic()
        if self.console is None or now - self.last < self.interval_s:
            return
        self.last = now
        elapsed = now - self.t0
        rate = (done - self.done0) / elapsed if elapsed > 0 else 0.0
        left = (self.total - done) / rate if rate > 0 else float("nan")
        pct = 100.0 * done / self.total if self.total else 100.0
        self.line(f"sweep {self.name}: {done}/{self.total} runs ({pct:.0f}%), {failed} failed, "
                  f"{_duration(elapsed)} elapsed, about {_duration(left)} left, {pool.slots} workers")

    def stop(self) -> None:
        if self._bar is not None:
            self._bar.stop()
            self._bar = None
