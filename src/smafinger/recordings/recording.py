"""The :class:`Recording`: one bench run, each signal on its own sample times, in SI units."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from .signals import INPUTS, SIGNALS, RecordingError, check_times

_SI_INPUTS = tuple(s.si_name for s in SIGNALS if s.name in INPUTS)
_SI_OUTPUTS = tuple(s.si_name for s in SIGNALS if s.role == "output")


def _frozen(a) -> np.ndarray:
    a = np.array(a, dtype=np.float64)  # a copy, so the caller's array stays its own
    a.setflags(write=False)
    return a


@dataclass(frozen=True)
class Series:
    """One signal at its own sample times.

    Attributes
    ----------
    name : str
        SI name: ``duty`` (fraction), ``voltage_V``, ``current_A``, ``position_m``,
        ``theta_rad``, ``T_C`` or ``resistance_ohm``.
    t_s, values : ndarray
        Sample times [s] (strictly increasing) and values (SI), read-only float64 arrays.
    source : str
        The column or variable it was read from.
    scale : float
        The mapping's scale that was applied (1 if none), before the conversion to SI.
    """

    name: str
    t_s: np.ndarray
    values: np.ndarray
    source: str = ""
    scale: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "t_s", _frozen(self.t_s))
        object.__setattr__(self, "values", _frozen(self.values))
        where = f"series {self.name!r}"
        if self.t_s.ndim != 1 or self.t_s.shape != self.values.shape:
            raise RecordingError(f"{where}: {self.t_s.shape} times but {self.values.shape} values")
        if self.t_s.size < 2:
            raise RecordingError(f"{where}: {self.t_s.size} sample(s); at least 2 are needed")
        rows = np.arange(1, self.t_s.size + 1)
        check_times(where, self.t_s, rows, "sample", None)
        if not np.isfinite(self.values).all():
            i = int(np.flatnonzero(~np.isfinite(self.values))[0])
            raise RecordingError(f"{where}, sample {i + 1}: value is {self.values[i]} (must be finite)")

    def __len__(self) -> int:
        return self.t_s.size

    def shifted(self, dt_s: float) -> "Series":
        """The same series with every time minus ``dt_s``."""
        return replace(self, t_s=self.t_s - dt_s)


@dataclass(frozen=True)
class Recording:
    """One bench run read by :func:`~smafinger.recordings.read_recording`.

    Attributes
    ----------
    file : str
        The file it was read from.
    input : Series
        What was sent: ``duty`` (a fraction of the supply voltage in the actuator's
        parameters), ``voltage_V`` or ``current_A``.
    output : Series
        What was measured: ``position_m`` (a linear actuator) or ``theta_rad`` (the joint).
    T_C, resistance_ohm : Series or None
        Optional wire temperature [degC] and resistance [ohm].
    meta : mapping
        Read-only facts about the file: format, the source of each signal and its scale,
        MATLAB variable names, block names and labels, a ``provenance`` struct if present.
    """

    file: str
    input: Series
    output: Series
    T_C: Series | None = None
    resistance_ohm: Series | None = None
    meta: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.input.name not in _SI_INPUTS:
            raise RecordingError(f"{self.file}: input {self.input.name!r} is not one of {', '.join(_SI_INPUTS)}")
        if self.output.name not in _SI_OUTPUTS:
            raise RecordingError(f"{self.file}: output {self.output.name!r} is not one of {', '.join(_SI_OUTPUTS)}")
        object.__setattr__(self, "meta", MappingProxyType(dict(self.meta)))

    @property
    def input_kind(self) -> str:
        """``"duty"``, ``"voltage_V"`` or ``"current_A"``."""
        return self.input.name

    @property
    def output_name(self) -> str:
        """``"position_m"`` or ``"theta_rad"``."""
        return self.output.name

    def series(self) -> tuple[Series, ...]:
        """Every series present: input, output, then ``T_C`` and ``resistance_ohm`` if given."""
        return tuple(s for s in (self.input, self.output, self.T_C, self.resistance_ohm) if s is not None)

    def with_time_origin(self, t0_s: float | None = None) -> "Recording":
        """The same recording with ``t0_s`` subtracted from every time.

        Parameters
        ----------
        t0_s : float, optional
            Default: the first input sample time, so that the input starts at 0 s as the
            simulator's programs do. The subtraction rounds like any float subtraction.
        """
        t0 = float(self.input.t_s[0]) if t0_s is None else float(t0_s)
        opt = {k: (None if s is None else s.shifted(t0)) for k, s in
               (("T_C", self.T_C), ("resistance_ohm", self.resistance_ohm))}
        return replace(self, input=self.input.shifted(t0), output=self.output.shifted(t0),
                       meta={**self.meta, "time_origin_s": t0}, **opt)
