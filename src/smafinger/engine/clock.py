"""The engine's integer clock: every time is a whole number of ticks of 1 ns.

Step ends, PWM periods, controller updates, output samples and target changes fall on exact
ticks, so no time drifts from adding dt.
"""

from __future__ import annotations

import math

import numpy as np

#: one tick [s]
TICK_S = 1e-9
#: the latest time the clock holds [ticks]: 2**62 ns, about 146 years; half the int64 range,
#: so that the sum of two clock times (a time plus a step, a PWM period) cannot overflow
MAX_TICKS = 2**62
#: :data:`MAX_TICKS` in seconds (about 4.6e9 s)
MAX_S = MAX_TICKS * TICK_S


def _beyond(name: str, value_s) -> ValueError:
    return ValueError(f"{name} = {value_s!r} s is beyond the clock's range ({MAX_S:.3g} s, about 146 years)")
#: ticks per second (exact: ticks / TICKS_PER_S is the correctly rounded time in seconds)
TICKS_PER_S = 1_000_000_000


def to_ticks(name: str, value_s: float, allow_zero: bool = False) -> int:
    """Seconds to integer ticks of 1 ns; refuses values that are not whole ticks or that are
    beyond :data:`MAX_S`."""
    if isinstance(value_s, (bool, np.bool_)) or not isinstance(value_s, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name} = {value_s!r} is not a number of seconds")
    if not math.isfinite(value_s):
        raise ValueError(f"{name} = {value_s!r} is not a finite number of seconds")
    if value_s < 0 or (value_s == 0 and not allow_zero):
        raise ValueError(f"{name} = {value_s!r} s must be {'>= 0' if allow_zero else '> 0'}")
    if value_s > MAX_S:
        raise _beyond(name, value_s)
    ticks = round(value_s / TICK_S)
    if ticks == 0 and value_s > 0:  # 1e-300 s passed the test below as 0 ticks (a 0 s step: a hang)
        raise ValueError(f"{name} = {value_s!r} s is shorter than the clock's tick, 1 ns")
    if abs(ticks * TICK_S - value_s) > 1e-6 * TICK_S * max(1.0, ticks) and abs(ticks * TICK_S - value_s) > 1e-12:
        raise ValueError(f"{name} = {value_s!r} s is not a whole number of nanoseconds")
    return int(ticks)


def ticks_array(name: str, values_s: np.ndarray) -> np.ndarray:
    """:func:`to_ticks` (zero allowed) of many times at once; the first bad one is named."""
    v = np.asarray(values_s, dtype=float)
    with np.errstate(invalid="ignore", over="ignore"):
        ticks = np.rint(v / TICK_S)
        err = np.abs(ticks * TICK_S - v)
        ok = (np.isfinite(v) & (v >= 0) & (v <= MAX_S)
              & ((err <= 1e-6 * TICK_S * np.maximum(1.0, ticks)) | (err <= 1e-12)))
    if not ok.all():
        i = int(np.flatnonzero(~ok)[0])
        to_ticks(f"{name} [{i}]", float(v[i]), allow_zero=True)  # raises with the reason
    return ticks.astype(np.int64)
