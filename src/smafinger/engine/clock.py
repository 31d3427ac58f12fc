"""The engine's integer clock: every time is a whole number of ticks of 1 ns.

Step ends, PWM periods, controller updates, output samples and target changes fall on exact
ticks, so no time drifts from adding dt.
"""

from __future__ import annotations

import math

import numpy as np

#: one tick [s]
TICK_S = 1e-9
#: ticks per second (exact: ticks / TICKS_PER_S is the correctly rounded time in seconds)
TICKS_PER_S = 1_000_000_000


def to_ticks(name: str, value_s: float, allow_zero: bool = False) -> int:
    """Seconds to integer ticks of 1 ns; refuses values that are not whole ticks."""
    if not isinstance(value_s, (int, float)) or not math.isfinite(value_s):
        raise ValueError(f"{name} = {value_s!r} is not a finite number of seconds")
    if value_s < 0 or (value_s == 0 and not allow_zero):
        raise ValueError(f"{name} = {value_s!r} s must be {'>= 0' if allow_zero else '> 0'}")
    ticks = round(value_s / TICK_S)
    if abs(ticks * TICK_S - value_s) > 1e-6 * TICK_S * max(1.0, ticks) and abs(ticks * TICK_S - value_s) > 1e-12:
        raise ValueError(f"{name} = {value_s!r} s is not a whole number of nanoseconds")
    return int(ticks)


def ticks_array(name: str, values_s: np.ndarray) -> np.ndarray:
    """:func:`to_ticks` (zero allowed) of many times at once; the first bad one is named."""
    v = np.asarray(values_s, dtype=float)
    ticks = np.rint(v / TICK_S)
    err = np.abs(ticks * TICK_S - v)
    ok = (np.isfinite(v) & (v >= 0)
          & ((err <= 1e-6 * TICK_S * np.maximum(1.0, ticks)) | (err <= 1e-12)))
    if not ok.all():
        i = int(np.flatnonzero(~ok)[0])
        to_ticks(f"{name} [{i}]", float(v[i]), allow_zero=True)  # raises with the reason
    return ticks.astype(np.int64)
