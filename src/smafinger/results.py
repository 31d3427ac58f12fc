"""Simulation results: named signals, metrics, export and plots."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .engine.signals import MC, WC, columns, structured
from .parameters import changed_from_named
from .values import is_real
from .files import atomic_write, temp_path  # noqa: F401  (re-exported: older imports)
from .metrics import time_to_reach  # noqa: F401  (re-exported: defined in metrics)


def _read_only(a: np.ndarray) -> np.ndarray:
    """A view of ``a`` that cannot be written through."""
    v = a.view()
    v.flags.writeable = False
    return v


def _suffixed(path: str | Path, suffix: str, method: str) -> str | Path:
    """``path``, refused (ValueError naming it) unless it ends in ``suffix``."""
    if Path(path).suffix.lower() != suffix:
        raise ValueError(f"{method}: path {str(path)!r} does not end in {suffix} "
                         f"(save() writes CSV, Parquet or MATLAB by the suffix)")
    return path


@dataclass
class SimulationResult:
    """A run's signals (sampled at the output interval), metrics and run statistics.

    ``mechanism_signals`` (fields x samples) and ``wire_signals`` (wires x fields x samples) are
    the recorded float64 arrays, one contiguous row per signal (rows ``engine.signals.MC`` and
    ``WC``, SI units); :meth:`signal` and the attributes named like the exported columns
    (``result.theta_deg``, ``result.T_upper_C``) give them in the exported units.
    :attr:`mechanism` and :attr:`wires` give them as structured arrays, one row per sample.
    """

    spec: Any
    mechanism_signals: np.ndarray
    wire_signals: np.ndarray
    segment_start_s: np.ndarray  #: each segment's start [s]; NaN for a segment that never started
    segment_reached_s: np.ndarray
    substeps: int
    interlock_violations: int
    wall_s: float
    engine: str = "compiled"  #: the kernel that ran: compiled, or interpreted (engine.interpreted)
    #: the recorded fields if not every signal (``run_spec(record="metrics")``: a sweep's runs)
    recorded: tuple[str, ...] | None = None
    #: every how many of the run's output samples this result keeps (:meth:`decimated`)
    samples_every: int = 1
    #: the run against the same run at half its step (:mod:`smafinger.step_check`; None: not checked)
    step_check: Any = None
    _metrics: dict | None = field(default=None, repr=False)

    # ---- signals ---------------------------------------------------------------------
    @property
    def columns(self) -> list[tuple[str, str, str | int, float]]:
        """Exported columns: (name, recorded field, "mechanism" or wire index, scale); those of the
        recorded fields only if the run did not record every signal."""
        p = self.spec.params
        cols = columns(p.mechanism, p.wire_names, p.coordinate.scale)
        return cols if self.recorded is None else [c for c in cols if c[1] in self.recorded]

    def _structured(self) -> tuple[np.ndarray, np.ndarray]:
        m, w = structured(self.mechanism_signals, self.wire_signals)
        for arr in (m, w):
            for name in arr.dtype.names if self.recorded is not None else ():
                if name not in self.recorded:
                    arr[name] = np.nan  # not recorded: its memory was never written
        return m, w

    @property
    def column_names(self) -> list[str]:
        """The exported columns' names (``t_s``, ``theta_deg``, ``T_upper_C``, ...), in order."""
        return [c[0] for c in self.columns]

    @property
    def mechanism(self) -> np.ndarray:
        """The mechanism's recorded fields as a structured array, one row per sample (a copy)."""
        return self._structured()[0]

    @property
    def wires(self) -> np.ndarray:
        """The wires' recorded fields as a structured array, samples x wires (a copy)."""
        return self._structured()[1]

    @property
    def t(self) -> np.ndarray:
        """The sample times [s] (a read-only view)."""
        return _read_only(self.mechanism_signals[MC.t])

    def signal(self, name: str) -> np.ndarray:
        """An exported signal by its column name (e.g. ``theta_deg``, ``T_upper_C``): a read-only
        view of the recorded row if it is exported as recorded (``T = r.T_upper_C; T += 273.15``
        would otherwise change the result, its metrics and what it saves), else a scaled copy."""
        for col, fld, where, scale in self.columns:
            if col == name:
                raw = (self.mechanism_signals[getattr(MC, fld)] if where == "mechanism"
                       else self.wire_signals[where, getattr(WC, fld)])
                return _read_only(raw) if scale == 1.0 else raw * scale
        also = "; this run recorded only its metrics' signals" if self.recorded is not None else ""
        raise KeyError(f"no signal {name!r} (signals: {', '.join(self.column_names)}{also})")

    def __getattr__(self, name: str):
        if name.startswith("_") or name in ("spec", "mechanism_signals", "wire_signals"):
            raise AttributeError(name)
        try:
            return self.signal(name)
        except KeyError:
            raise AttributeError(name) from None

    def decimated(self, every: int) -> "SimulationResult":
        """The result thinned to every ``every``-th sample (an integer >= 1), its metrics kept at
        full resolution; its saved files say so (``samples_every`` in their provenance)."""
        every = sample_stride(every)
        metrics = self.metrics
        return dataclasses.replace(self, mechanism_signals=np.ascontiguousarray(self.mechanism_signals[:, ::every]),
                                   wire_signals=np.ascontiguousarray(self.wire_signals[..., ::every]),
                                   samples_every=self.samples_every * every, _metrics=metrics)

    def to_pandas(self):
        """The exported signals as a :class:`pandas.DataFrame`, one column per :attr:`column_names`
        (the CSV's columns, in its units), one row per sample; a copy."""
        import pandas as pd

        return pd.DataFrame({name: np.array(self.signal(name)) for name in self.column_names})

    def to_csv(self, path: str | Path) -> None:
        """The signals as CSV, with the provenance in ``NAME.provenance.json`` beside it.
        ``path`` must end in ``.csv`` (:meth:`save` chooses the format by the suffix)."""
        self.save(_suffixed(path, ".csv", "to_csv"))

    def to_parquet(self, path: str | Path) -> None:
        """The signals as Parquet, with the provenance in the schema metadata.
        ``path`` must end in ``.parquet``."""
        self.save(_suffixed(path, ".parquet", "to_parquet"))

    def to_mat(self, path: str | Path) -> None:
        """The signals as a MATLAB file (one Structure With Time per signal, and provenance).
        ``path`` must end in ``.mat``."""
        self.save(_suffixed(path, ".mat", "to_mat"))

    def save(self, path: str | Path) -> None:
        """CSV, Parquet or MATLAB by the file's suffix (:mod:`smafinger.export`), atomically."""
        from .export import add_signals
        from .files import Outputs

        out = Outputs()
        add_signals(out, self, path, "output file")
        out.commit()

    # ---- metrics ---------------------------------------------------------------------
    def step_check_warning(self) -> str | None:
        """The step check's warning (None: not checked, or within the budget), worded for a
        closed loop where the run has one (:meth:`.step_check.StepCheck.warning`)."""
        if self.step_check is None:
            return None
        return self.step_check.warning(closed_loop=self.spec.strategy != "open-loop")

    @property
    def metrics(self) -> dict:
        if self._metrics is None:
            self._metrics = compute_metrics(self)
        return self._metrics

    def summary(self) -> dict:
        """Metrics plus run statistics, JSON-ready."""
        m = dict(self.metrics)
        m["params"] = self.spec.params.name
        m["params_changed"] = list(changed_from_named(self.spec.params))  # from the set of that name
        m["mechanism"] = self.spec.params.mechanism
        m["strategy"] = self.spec.strategy
        m["method"] = self.spec.method
        m["dt_s"] = self.spec.dt_s
        m["t_end_s"] = self.spec.t_end_s
        m["steps"] = self.substeps
        m["wall_s"] = self.wall_s
        m["engine"] = self.engine
        if self.step_check is not None:
            m["step_check"] = self.step_check.to_dict()
        return m

    def write_summary(self, path: str | Path) -> None:
        """The summary JSON: :meth:`summary` (rounded) and the run's provenance (exact)."""
        from .export import add_summary
        from .files import Outputs

        out = Outputs()
        add_summary(out, self, path, "summary file")
        out.commit()

    def plot(self, path: str | Path | None = None, title: str | None = None):
        """Five stacked panels laid out like the paper's figures (:func:`.plotting.plot_result`).

        Returns the :class:`matplotlib.figure.Figure`; with ``path`` it is also written there
        (PNG, PDF or SVG by the suffix, atomically) and closed. Uses matplotlib's current
        backend (without a display, matplotlib picks Agg itself).
        """
        from .plotting import plot_result

        return plot_result(self, path, title)


def sample_stride(every) -> int:
    """``every`` (keep every ``every``-th sample) as an int: a whole number >= 1 (10.0 is 10);
    TypeError or ValueError naming it otherwise (-1 reversed a result in time, 2.7 kept every
    2nd sample)."""
    if not is_real(every):
        raise TypeError(f"every = {every!r} must be a whole number >= 1")
    if not (math.isfinite(every) and every == int(every) and every >= 1):
        raise ValueError(f"every = {every!r} must be a whole number >= 1")
    return int(every)


def segment_bounds(result: SimulationResult) -> list[tuple[int, float, float]]:
    """(index, start, end) of every segment that started."""
    t_end = result.spec.t_end_s
    starts = [(i, s) for i, s in enumerate(result.segment_start_s) if s >= 0]
    out = []
    for j, (i, s) in enumerate(starts):
        end = starts[j + 1][1] if j + 1 < len(starts) else t_end
        out.append((i, float(s), float(end)))
    return out


def compute_metrics(result: SimulationResult) -> dict:
    """The run's metrics (:func:`smafinger.metrics.run_metrics`) with its reach settings,
    interlock count and plausibility warnings (:func:`smafinger.plausibility.check`)."""
    from .metrics import Span, run_metrics
    from .plausibility import check

    spec = result.spec
    p = spec.params
    unit = p.coordinate.unit
    wires = p.wire_names
    spans = []
    # open loop: the one segment holds the rest position with no wire enabled, a target no one
    # pursues (its "reach" was the first step, its overshoot 0 whatever the drive did)
    pursued = spec.strategy != "open-loop"
    for i, start, end in segment_bounds(result):
        seg = spec.profile.segments[i]
        reached = result.segment_reached_s[i]
        spans.append(Span(i, start, end, seg.target, seg.enable,
                          None if math.isnan(reached) or not pursued else float(reached), pursued))
    m = run_metrics(result.t, result.signal(f"{p.coordinate.name}_{unit}"), spans,
                    temperature_C={w: result.signal(f"T_{w}_C") for w in wires},
                    stress_Pa={w: result.signal(f"sigma_{w}_Pa") for w in wires},
                    energy_J={w: result.signal(f"electrical_energy_{w}_J") for w in wires},
                    heat_J={w: result.signal(f"heat_{w}_J") for w in wires}, unit=unit)
    # energy_J is the electrical energy at the terminals (its name since 0.1); heat_J the heat the
    # model puts into the wires (with the paper's per-metre reading of Eq. 11, 1/L_w^2 times less)
    return {"segments": m["segments"], f"tol_{unit}": spec.tolerance, "hold_s": spec.hold_s,
            "energy_J": m["energy_J"], "electrical_energy_J": m["energy_J"], "heat_J": m["heat_J"],
            "peak_temperature_C": m["peak_temperature_C"],
            "peak_stress_Pa": m["peak_stress_Pa"], "interlock_violations": result.interlock_violations,
            "warnings": skipped_targets(spans, unit) + check(result) + _step_warning(result)}


def _step_warning(result: SimulationResult) -> list[str]:
    """The step check's warning, if the run was checked and is over the budget (:mod:`.step_check`)."""
    w = result.step_check_warning()
    return [] if w is None else [w]


def skipped_targets(spans: list, unit: str) -> list[str]:
    """A warning per segment that started and ended in the same instant: its target was never
    pursued (a later segment's start time had come when it started on reach, e.g. profile
    ``0:-25,reach:-55,3:-40`` whose -25 deg is reached after 3 s)."""
    return [f"segment {s.index} (target {s.target:g} {unit}) was never pursued: the next segment started at the same "
            f"time, t = {s.start_s:.6g} s" for s in spans[:-1] if s.end_s <= s.start_s]
