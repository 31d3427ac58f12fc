"""What long work tells its user on stderr: a live bar on a terminal, plain lines in a log.

One display for every command (simulate, reproduce, sweep, identify):

- ``"bar"``: a rich progress bar per task (on a terminal);
- ``"lines"``: a plain line per task every ``interval_s`` seconds, readable in a batch job's
  log: ``sweep fig8: 120/231 runs (52%), 0 failed, 4.1 s elapsed, about 3.8 s left, 2 workers``;
- ``"off"``: nothing.

:meth:`Display.auto` picks the mode from a command's ``--progress/--no-progress`` flag.
"""

from __future__ import annotations

import time
from typing import Callable

MODES = ("bar", "lines", "off")


def duration(s: float) -> str:
    """A duration for people: ``4.1 s``, ``3.2 min``, ``1.5 h`` (``?`` if unknown)."""
    if s != s or s == float("inf"):  # NaN / inf
        return "?"
    if s < 120:
        return f"{s:.1f} s"
    if s < 7200:
        return f"{s / 60:.1f} min"
    return f"{s / 3600:.1f} h"


class Task:
    """One counted piece of work on a :class:`Display` (runs, simulated seconds, fits)."""

    def __init__(self, display: "Display", label: str, total: float, unit: str, integer: bool,
                 done: float, note: str, suffix: str):
        self.display, self.label, self.total, self.unit, self.integer = display, label, total, unit, integer
        self.done = self.done0 = done
        self.note, self.suffix = note, suffix
        self.t0 = self.last = time.monotonic()
        self._id = None

    def counts(self) -> str:
        if self.integer:
            return f"{int(self.done)}/{int(self.total)} {self.unit}".rstrip()
        return f"{self.done:.1f}/{self.total:.1f} {self.unit}".rstrip()

    def text(self) -> str:
        """The plain progress line."""
        now = time.monotonic()
        elapsed = now - self.t0
        rate = (self.done - self.done0) / elapsed if elapsed > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        pct = 100.0 * self.done / self.total if self.total else 100.0
        parts = [f"{self.label}: {self.counts()} ({pct:.0f}%)", self.note,
                 f"{duration(elapsed)} elapsed", f"about {duration(left)} left", self.suffix]
        return ", ".join(p for p in parts if p)

    def update(self, completed: float | None = None, advance: float | None = None, note: str | None = None,
               suffix: str | None = None) -> None:
        if completed is not None:
            self.done = completed
        if advance is not None:
            self.done += advance
        if note is not None:
            self.note = note
        if suffix is not None:
            self.suffix = suffix
        self.display._show(self)


class Display:
    """Progress of long work: ``mode`` is ``"bar"``, ``"lines"`` or ``"off"`` (see the module
    docstring). ``console``: a rich console (default: stderr). Use it as a context manager,
    or call :meth:`stop` at the end."""

    def __init__(self, mode: str = "off", console=None, interval_s: float = 10.0, transient: bool = True):
        if mode not in MODES:
            raise ValueError(f"progress mode {mode!r} is not one of {', '.join(MODES)}")
        if not interval_s > 0:
            raise ValueError(f"progress interval {interval_s!r} s must be > 0")
        if console is None and mode != "off":
            from rich.console import Console

            console = Console(stderr=True)
        self.mode, self.console, self.interval_s, self.transient = mode, console, interval_s, transient
        self._bar = None

    @classmethod
    def auto(cls, flag: bool | None, console=None, interval_s: float = 10.0, off_terminal: str = "off",
             transient: bool = True) -> "Display":
        """The display a ``--progress/--no-progress`` flag asks for: ``False`` none; ``True`` a bar
        on a terminal, lines otherwise; ``None`` (not given) a bar on a terminal, else
        ``off_terminal``."""
        if flag is False:
            return cls("off")
        if console is None:
            from rich.console import Console

            console = Console(stderr=True)
        mode = "bar" if console.is_terminal else ("lines" if flag else off_terminal)
        return cls(mode, console, interval_s, transient)

    @property
    def enabled(self) -> bool:
        return self.mode != "off"

    def __enter__(self) -> "Display":
        return self

    def __exit__(self, *exc) -> bool:
        self.stop()
        return False

    def line(self, text: str) -> None:
        """A message (above a live bar, or as a plain line)."""
        if self.mode != "off":
            self.console.print(text, highlight=False, soft_wrap=True, markup=False)

    def task(self, label: str, total: float, unit: str = "", integer: bool = True, done: float = 0,
             note: str = "", suffix: str = "") -> Task:
        """Start counting ``total`` units of work."""
        task = Task(self, label, total, unit, integer, done, note, suffix)
        if self.mode == "bar":
            bar = self._ensure_bar()
            task._id = bar.add_task(label, total=total, completed=done, counts=task.counts(),
                                    note=", ".join(p for p in (note, suffix) if p))
        return task

    def counter(self, label: str, unit: str = "") -> Callable[[int, int], None]:
        """An ``on_progress(done, total)`` callback counting on a task of this display, the task
        made at the first call (when the total is known)."""
        made: list[Task] = []

        def update(done: int, total: int) -> None:
            if not made:
                made.append(self.task(label, total, unit))
            made[0].update(completed=done)

        return update

    def _ensure_bar(self):
        if self._bar is None:
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

            self._bar = Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.fields[counts]}"),
                                 TimeElapsedColumn(), TimeRemainingColumn(), TextColumn("{task.fields[note]}"),
                                 console=self.console, transient=self.transient)
            self._bar.start()
        return self._bar

    def _show(self, task: Task) -> None:
        if self.mode == "bar" and task._id is not None:
            self._bar.update(task._id, completed=task.done, counts=task.counts(),
                             note=", ".join(p for p in (task.note, task.suffix) if p))
        elif self.mode == "lines":
            now = time.monotonic()
            if now - task.last >= self.interval_s:
                task.last = now
                self.line(task.text())

    def stop(self) -> None:
        if self._bar is not None:
            self._bar.stop()
            self._bar = None
