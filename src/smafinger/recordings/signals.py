"""The canonical signals of a bench recording, their plausible ranges and the sample checks.

Every rule about what a recorded signal may hold lives here, once: the names a file or a
mapping uses, the range a value may take in the file's units, the conversion to SI and the
checks on times and values that every reader (CSV, Parquet, MATLAB) applies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


class RecordingError(ValueError):
    """A recording cannot be used; the one-line message names the file, the column or
    variable and, where one is at fault, the row or sample."""


#: the canonical name of the time column (and of a plain time vector in a MATLAB file)
TIME = "t_s"

INPUT = "input"
OUTPUT = "output"
EXTRA = "extra"


@dataclass(frozen=True)
class SignalSpec:
    """One canonical signal.

    Attributes
    ----------
    name : str
        Its name in a file and in a mapping (file units: ``theta_deg`` is in degrees).
    role : str
        ``"input"`` (what was sent), ``"output"`` (what was measured) or ``"extra"``.
    lo, hi : float
        Plausible range of a value in file units; ``lo`` excluded when ``lo_open``.
    unit : str
        Unit of the file values, for messages.
    si_name : str
        Its name once converted to SI (``theta_deg`` becomes ``theta_rad``).
    to_si : float
        Factor from file units to SI.
    hint_scale, hint_unit : float or None, str
        If the values times ``hint_scale`` would be in range, the refusal says the file looks
        like it is in ``hint_unit`` and shows the mapping scale that converts it.
    """

    name: str
    role: str
    lo: float
    hi: float
    unit: str
    si_name: str
    to_si: float = 1.0
    lo_open: bool = False
    hint_scale: float | None = None
    hint_unit: str = ""

    def in_range(self, v: np.ndarray) -> np.ndarray:
        """Elementwise: is each value inside the plausible range?"""
        low = v > self.lo if self.lo_open else v >= self.lo
        return low & (v <= self.hi)

    def range_text(self) -> str:
        return f"{'(' if self.lo_open else '['}{self.lo:g}, {self.hi:g}] {self.unit}".rstrip()


SIGNALS: tuple[SignalSpec, ...] = (
    SignalSpec("duty", INPUT, 0.0, 1.0, "(fraction of the supply voltage)", "duty",
               hint_scale=0.01, hint_unit="percent"),
    SignalSpec("voltage_V", INPUT, 0.0, 100.0, "V", "voltage_V"),
    SignalSpec("current_A", INPUT, 0.0, 20.0, "A", "current_A"),
    SignalSpec("position_m", OUTPUT, -1.0, 1.0, "m", "position_m", hint_scale=1e-3, hint_unit="millimetres"),
    SignalSpec("theta_deg", OUTPUT, -180.0, 180.0, "deg", "theta_rad", to_si=math.pi / 180.0),
    SignalSpec("T_C", EXTRA, -50.0, 400.0, "degC", "T_C"),
    SignalSpec("resistance_ohm", EXTRA, 0.0, 1e4, "ohm", "resistance_ohm", lo_open=True),
)
SPEC: dict[str, SignalSpec] = {s.name: s for s in SIGNALS}
INPUTS = tuple(s.name for s in SIGNALS if s.role == INPUT)
OUTPUTS = tuple(s.name for s in SIGNALS if s.role == OUTPUT)
EXTRAS = tuple(s.name for s in SIGNALS if s.role == EXTRA)
#: every name a mapping may assign
MAPPABLE = (TIME,) + tuple(SPEC)


@dataclass(frozen=True)
class RawSignal:
    """One signal as read from a file, before checks and conversion.

    Attributes
    ----------
    where : str
        ``"<file>: column 'x'"`` or ``"<file>: variable 'x'"``, the start of every message.
    t_s, values : ndarray
        Its own sample times and values (empty cells already dropped), float64.
    rows : ndarray
        1-based row (CSV, Parquet: data row; MATLAB: sample) of each sample, for messages.
    row_word : str
        ``"data row"`` or ``"sample"``.
    line_offset : int or None
        For text files: file line = row + ``line_offset`` (the header is line 1).
    """

    where: str
    t_s: np.ndarray
    values: np.ndarray
    rows: np.ndarray
    row_word: str = "data row"
    line_offset: int | None = None

    def at(self, i: int) -> str:
        """``"data row 7 (line 8)"`` or ``"sample 7"`` for the i-th sample (0-based)."""
        return describe_row(int(self.rows[i]), self.row_word, self.line_offset)


def describe_row(row: int, row_word: str, line_offset: int | None) -> str:
    """``"data row 7 (line 8)"`` or ``"sample 7"``."""
    if line_offset is None:
        return f"{row_word} {row}"
    return f"{row_word} {row} (line {row + line_offset})"


def check_times(where: str, t: np.ndarray, rows: np.ndarray, row_word: str,
                line_offset: int | None, what: str = "time") -> None:
    """Refuse non-finite, repeated or decreasing sample times.

    Raises
    ------
    RecordingError
        Naming ``where``, the row and the two times that are out of order.
    """
    bad = ~np.isfinite(t)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise RecordingError(f"{where}, {describe_row(int(rows[i]), row_word, line_offset)}: "
                             f"{what} is {t[i]} (times must be finite)")
    step = np.diff(t)
    if (step <= 0).any():
        i = int(np.flatnonzero(step <= 0)[0]) + 1
        kind = "repeats" if step[i - 1] == 0 else "goes back"
        raise RecordingError(
            f"{where}, {describe_row(int(rows[i]), row_word, line_offset)}: {what} {kind} "
            f"({float(t[i])!r} s after {float(t[i - 1])!r} s); times must increase strictly")


def check_signal(raw: RawSignal, spec: SignalSpec, source: str, scale: float) -> None:
    """Refuse a signal whose samples cannot be used as ``spec``.

    Checks, in order: at least 2 samples, finite and strictly increasing times, finite values,
    values in the plausible range of ``spec`` (after the mapping's ``scale``). A range refusal
    says when the values look like another unit and which mapping scale converts them.

    Raises
    ------
    RecordingError
        One line naming the file, the column or variable and the row.
    """
    n = raw.values.size
    if n < 2:
        raise RecordingError(f"{raw.where}: {n} sample(s) as {spec.name}; at least 2 are needed")
    check_times(raw.where, raw.t_s, raw.rows, raw.row_word, raw.line_offset)
    bad = ~np.isfinite(raw.values)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise RecordingError(f"{raw.where}, {raw.at(i)}: value is {raw.values[i]} "
                             f"({spec.name} must be a finite number)")
    ok = spec.in_range(raw.values)
    if not ok.all():
        i = int(np.flatnonzero(~ok)[0])
        scaled = "" if scale == 1.0 else f" (after the mapping's scale {scale:g})"
        raise RecordingError(f"{raw.where}, {raw.at(i)}: {spec.name} = {raw.values[i]:g}{scaled} is outside "
                             f"{spec.range_text()}{_unit_hint(raw.values, spec, source, scale)}")


def _unit_hint(values: np.ndarray, spec: SignalSpec, source: str, scale: float) -> str:
    if spec.hint_scale is None or not spec.in_range(values * spec.hint_scale).all():
        return ""
    s = scale * spec.hint_scale
    return (f"; it looks like {spec.hint_unit}: map it with a scale, "
            f"--map {spec.name}={source}*{s:g} (Python: {{'{spec.name}': ('{source}', {s:g})}})")
