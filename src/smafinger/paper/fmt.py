"""Numbers as text for the report: ``None`` (a time that did not happen) is "never"."""

from __future__ import annotations

from typing import Iterable


def num(value: float | None, fmt: str = ".1f", unit: str = "") -> str:
    """``value`` formatted, with ``unit`` appended; "never" for ``None``."""
    return "never" if value is None else f"{value:{fmt}}{unit}"


def secs(value: float | None, fmt: str = ".1f") -> str:
    """A time in seconds: ``"18.5 s"``; "never" for ``None``."""
    return num(value, fmt, " s")


def pct(value: float | None) -> str:
    """A fraction as a whole percentage: ``"21%"``; "n/a" for ``None``."""
    return "n/a" if value is None else f"{100 * value:.0f}%"


def nums(values: Iterable[float | None], fmt: str = ".2f") -> str:
    """Comma-separated values (no unit)."""
    return ", ".join(num(v, fmt) for v in values)


def span(values: Iterable[float | None], unit: str = " s", fmt: str = ".1f") -> str:
    """``"15.7-21.6 s"`` over the known values (one value if they agree at ``fmt``); "n/a"
    if none."""
    v = [x for x in values if x is not None]
    if not v:
        return "n/a"
    lo, hi = f"{min(v):{fmt}}", f"{max(v):{fmt}}"
    return f"{lo}{unit}" if lo == hi else f"{lo}-{hi}{unit}"


def ratio_phrase(value: float | None, ref: float, tol: float) -> str:
    """How ``value`` compares with ``ref``, in words computed from the numbers: "within
    20% of", "about half of", "x% below/above"."""
    if value is None:
        return "no value for"
    r = value / ref
    if abs(r - 1.0) <= tol:
        return f"within {pct(tol)} of"
    if abs(r - 0.5) <= 0.1:
        return f"about half ({pct(r)}) of"
    return f"{pct(abs(r - 1.0))} {'below' if r < 1.0 else 'above'}"


def md_escape(text: str) -> str:
    return text.replace("|", "\\|")


__all__ = ["num", "secs", "pct", "nums", "span", "ratio_phrase", "md_escape"]
