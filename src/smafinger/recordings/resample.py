"""A recording against a simulation grid: the input held onto the grid, the output compared
at its own sample times.

Times closer than ``tol_s`` (default: the engine's tick, 1 ns) count as the same instant, so a
grid computed as ``k * dt`` does not miss a sample time by a rounding error. The tolerance is
never more than a quarter of the smallest sample spacing, so it cannot merge two samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..engine.clock import TICK_S
from .recording import Recording
from .signals import RecordingError


def _grid(t_grid) -> np.ndarray:
    t = np.asarray(t_grid, dtype=np.float64)
    if t.ndim != 1 or t.size == 0:
        raise RecordingError(f"t_grid: expected a non-empty 1-D array of times, got shape {t.shape}")
    if not np.isfinite(t).all():
        i = int(np.flatnonzero(~np.isfinite(t))[0])
        raise RecordingError(f"t_grid[{i}] = {t[i]} is not finite")
    if (np.diff(t) <= 0).any():
        i = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise RecordingError(f"t_grid[{i}] = {float(t[i])!r} s is not after t_grid[{i - 1}] = {float(t[i - 1])!r} s")
    return t


def _tol(tol_s: float, *times: np.ndarray) -> float:
    if not (np.isfinite(tol_s) and tol_s >= 0):
        raise RecordingError(f"tol_s = {tol_s!r} must be a finite number >= 0")
    spacings = [np.min(np.diff(t)) for t in times if t.size > 1]
    return min([float(tol_s)] + [0.25 * float(s) for s in spacings])


def input_on_grid(recording: Recording, t_grid, tol_s: float = TICK_S) -> np.ndarray:
    """The input held (zero-order hold) onto ``t_grid``.

    At grid time t the value is that of the last input sample at or before t (within
    ``tol_s``); after the last sample its value is held.

    Parameters
    ----------
    recording : Recording
    t_grid : array_like
        Strictly increasing times [s], in the recording's time frame.
    tol_s : float
        Times closer than this are the same instant (see the module docstring).

    Returns
    -------
    ndarray
        The input (SI) at each grid time.

    Raises
    ------
    RecordingError
        If the grid starts before the first input sample (the input is unknown there), or the
        grid is not a strictly increasing finite 1-D array.
    """
    t_in, v_in = recording.input.t_s, recording.input.values
    t = _grid(t_grid)
    tol = _tol(tol_s, t_in, t)
    if t[0] < t_in[0] - tol:
        raise RecordingError(f"{recording.file}: t_grid starts at {float(t[0])!r} s, before the first sample of "
                             f"the input {recording.input.source!r} ({float(t_in[0])!r} s); start the grid there")
    return v_in[np.searchsorted(t_in, t + tol, side="right") - 1]


@dataclass(frozen=True)
class OutputSamples:
    """The measured output at its own times, with where each time falls on a simulation grid.

    A sample at time t_i lies between grid points ``index[i]`` and ``index[i] + 1``, a fraction
    ``weight[i]`` of the way; ``weight[i] == 0`` when t_i is a grid time (within the
    tolerance). The simulated output at the sample times is then
    ``(1 - w) * y[index] + w * y[index + 1]``: an exact gather ``y[index]`` when every sample is
    on the grid (:attr:`exact`; choose the simulator's output interval to divide the sample
    period), otherwise linear interpolation (error at most dt^2/8 * max|y''|).

    Attributes
    ----------
    name : str
        ``position_m`` or ``theta_rad``.
    t_s, values : ndarray
        Sample times [s] and measured values (SI).
    index : ndarray of int
        Grid index at or before each sample.
    weight : ndarray
        Fraction of the grid step from ``index`` to the sample, in [0, 1).
    """

    name: str
    t_s: np.ndarray
    values: np.ndarray
    index: np.ndarray
    weight: np.ndarray

    @property
    def exact(self) -> bool:
        """True when every sample time is a grid time (no interpolation)."""
        return not self.weight.any()

    def model_at(self, on_grid) -> np.ndarray:
        """A simulated signal given on the grid -> its values at the sample times."""
        y = np.asarray(on_grid, dtype=np.float64)
        below = y[self.index]
        if self.exact:
            return below
        above = y[np.minimum(self.index + 1, y.size - 1)]
        return np.where(self.weight == 0, below, (1.0 - self.weight) * below + self.weight * above)

    def residuals(self, on_grid) -> np.ndarray:
        """Simulated minus measured, at the sample times."""
        return self.model_at(on_grid) - self.values


def output_on_grid(recording: Recording, t_grid, tol_s: float = TICK_S) -> OutputSamples:
    """Locate the measured output's sample times on a simulation grid.

    Parameters
    ----------
    recording : Recording
    t_grid : array_like
        Strictly increasing times [s] at which the simulation reports its output; it must
        cover every output sample.
    tol_s : float
        Times closer than this are the same instant.

    Returns
    -------
    OutputSamples

    Raises
    ------
    RecordingError
        Naming the first output sample outside the grid.
    """
    out = recording.output
    t = _grid(t_grid)
    tol = _tol(tol_s, out.t_s, t)
    j = np.searchsorted(t, out.t_s + tol, side="right") - 1
    outside = (j < 0) | (out.t_s > t[-1] + tol)
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        raise RecordingError(f"{recording.file}: output {out.source!r} sample {i + 1} at {float(out.t_s[i])!r} s is "
                             f"outside t_grid [{float(t[0])!r}, {float(t[-1])!r}] s; the grid must cover the output")
    on = np.abs(out.t_s - t[j]) <= tol
    nxt = np.minimum(j + 1, t.size - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(on, 0.0, (out.t_s - t[j]) / (t[nxt] - t[j]))
    return OutputSamples(out.name, out.t_s, out.values, j, w)


def input_program(recording: Recording) -> tuple[tuple[float, float], ...]:
    """The input as a piecewise-constant program ``((t_start, value), ...)``.

    Consecutive samples with equal values are merged, so each step starts where the value
    changes; the first starts at the first input sample. Values are SI (duty as a fraction).
    The simulator's programs start at 0 s: see :meth:`Recording.with_time_origin`.
    """
    t, v = recording.input.t_s, recording.input.values
    keep = np.ones(v.size, dtype=bool)
    keep[1:] = v[1:] != v[:-1]
    return tuple(zip(t[keep].tolist(), v[keep].tolist()))
