"""A claim of the paper: a metric, a criterion and the paper's value, evaluated on runs.

A :class:`Claim` names the runs it reads, how to measure them (``measure``: runs ->
named numbers), and its criterion (``checks``: each a sentence and a test of the numbers).
The report and the tests both call :meth:`Claim.evaluate`, so a criterion is written once:

- every check holds -> ``yes``; some hold (or all the ``fallback`` checks do) ->
  ``partly``; none -> ``no``; a claim without checks is only reported (``n/a``);
- ``known_gap`` marks a claim the model is known not to reproduce, and says why: the
  tests expect it to fail (strict xfail) and the report says so beside its numbers.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

Values = dict[str, Any]


class Verdict(str, enum.Enum):
    YES = "yes"
    PARTLY = "partly"
    NO = "no"
    REPORTED = "n/a"
    NOT_RUN = "not run"


@dataclass(frozen=True)
class Check:
    """One condition of a criterion: what it says, and its test on the measured values."""

    text: str
    test: Callable[[Values], bool]


@dataclass(frozen=True)
class Outcome:
    """A claim evaluated: its verdict, the measured values and their text."""

    claim: "Claim"
    verdict: Verdict
    values: Values
    shows: str = ""
    note: str = ""
    failed: tuple[str, ...] = ()
    #: NOT_RUN: the claim's runs that were selected and failed (empty: they were not selected)
    runs_failed: tuple[str, ...] = ()

    def explain(self) -> str:
        """One paragraph for a test failure: the claim, the verdict, what failed, the numbers."""
        return (f"{self.claim.figure}: {self.claim.statement} -> {self.verdict.value}; "
                f"not met: {'; '.join(self.failed) or '-'}; smafinger: {self.shows}")


@dataclass(frozen=True)
class Claim:
    """A claim of the paper and how smafinger checks it.

    Parameters
    ----------
    key : str
        Stable identifier (test ids).
    figure, statement, paper : str
        Where the paper makes the claim, the claim, and the paper's value.
    scenarios : tuple of str
        The runs the claim reads (in the order ``measure`` gets them); empty: every
        scenario run.
    measure : callable
        ``measure(runs) -> dict``: the named numbers the claim is about, from the runs'
        summaries and figure metrics (``run.summary``, ``run.derived``).
    shows : callable
        ``shows(values) -> str``: smafinger's value, as text.
    checks, fallback : tuple of Check
        The criterion (see the module docstring).
    note : str or callable
        Context for the report; a callable gets the values.
    min_runs : int, optional
        Evaluate with at least this many of ``scenarios`` (default: all of them).
    also : tuple of str
        Runs read when they are there (not needed for the verdict to be computed).
    known_gap : str
        Why the model does not reproduce this claim (empty: it is expected to hold).
    """

    key: str
    figure: str
    statement: str
    paper: str
    scenarios: tuple[str, ...]
    measure: Callable[[list], Values]
    shows: Callable[[Values], str]
    checks: tuple[Check, ...] = ()
    fallback: tuple[Check, ...] = ()
    note: str | Callable[[Values], str] = ""
    min_runs: int | None = None
    also: tuple[str, ...] = ()
    known_gap: str = ""

    @property
    def criterion(self) -> str:
        """The criterion in words."""
        if not self.checks:
            return "reported, no criterion"
        text = "; ".join(c.text for c in self.checks)
        if self.fallback:
            text += "; partly: " + "; ".join(c.text for c in self.fallback)
        return text

    def _names(self, runs: Mapping[str, Any]) -> tuple[str, ...]:
        """The claim's scenarios; a claim naming none reads every scenario run."""
        return self.scenarios or tuple(k for k, r in runs.items() if r.scenario is not None)

    def available(self, runs: Mapping[str, Any]) -> list | None:
        """The claim's successful runs (``scenarios`` then ``also``), or ``None`` if too
        few of ``scenarios`` ran."""
        names = self._names(runs)
        have = [runs[n] for n in names if n in runs and runs[n].ok]
        need = len(names) if self.min_runs is None else self.min_runs
        if not names or len(have) < need:
            return None
        return have + [runs[n] for n in self.also if n in runs and runs[n].ok and n not in names]

    def evaluate(self, runs: Mapping[str, Any]) -> Outcome:
        """The verdict on ``runs`` (a mapping name -> run with ``ok``, ``summary``, ``derived``
        and ``scenario``)."""
        have = self.available(runs)
        if have is None:
            return Outcome(self, Verdict.NOT_RUN, {},
                           runs_failed=tuple(n for n in self._names(runs) if n in runs and not runs[n].ok))
        values = self.measure(have)
        note = self.note(values) if callable(self.note) else self.note
        passed = [c.test(values) for c in self.checks]
        failed = tuple(c.text for c, ok in zip(self.checks, passed) if not ok)
        if not self.checks:
            verdict = Verdict.REPORTED
        elif all(passed):
            verdict = Verdict.YES
        elif any(passed) or (self.fallback and all(c.test(values) for c in self.fallback)):
            verdict = Verdict.PARTLY
        else:
            verdict = Verdict.NO
        return Outcome(self, verdict, values, self.shows(values), note, failed)


# ---------------------------------------------------------------------------------------
# tests of measured values (None, "never", fails every comparison)
# ---------------------------------------------------------------------------------------
def known(*values: Any) -> bool:
    """Every value was measured (none is ``None``)."""
    return all(v is not None for v in values)


def increasing(values: Sequence[float | None]) -> bool:
    """Strictly increasing, every value known."""
    return known(*values) and all(b > a for a, b in zip(values, values[1:]))


def decreasing(values: Sequence[float | None]) -> bool:
    """Strictly decreasing, every value known."""
    return known(*values) and all(b < a for a, b in zip(values, values[1:]))


def within(value: float | None, ref: float, tol: float) -> bool:
    """``|value - ref| <= tol * |ref|``."""
    return value is not None and abs(value - ref) <= tol * abs(ref)


def between(value: float | None, lo: float, hi: float) -> bool:
    return value is not None and lo <= value <= hi


def spread(values: Sequence[float]) -> float:
    """Largest minus smallest value."""
    return max(values) - min(values)


__all__ = ["Claim", "Check", "Outcome", "Verdict", "Values", "known", "increasing", "decreasing",
           "within", "between", "spread"]
