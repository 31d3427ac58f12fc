"""Simulation results: named signals, metrics, export and plots."""

from __future__ import annotations

import json
import math
import os
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .engine.kernel import OUT_COLUMNS
from .metrics import time_to_reach  # noqa: F401  (re-exported: defined in metrics)

#: exported column -> (kernel column, scale)
EXPORT_COLUMNS: dict[str, tuple[str, float]] = {
    "t_s": ("t", 1.0),
    "theta_deg": ("theta", 180.0 / math.pi),
    "theta_ref_deg": ("theta_ref", 180.0 / math.pi),
    "omega_deg_s": ("omega", 180.0 / math.pi),
    "T_upper_C": ("T_u", 1.0),
    "T_lower_C": ("T_l", 1.0),
    "xi_upper": ("xi_u", 1.0),
    "xi_lower": ("xi_l", 1.0),
    "sigma_upper_Pa": ("sigma_u", 1.0),
    "sigma_lower_Pa": ("sigma_l", 1.0),
    "force_upper_N": ("sigma_u", None),  # sigma * S_w
    "force_lower_N": ("sigma_l", None),
    "arm_upper_m": ("arm_u", 1.0),
    "arm_lower_m": ("arm_l", 1.0),
    "spring_upper_m": ("spring_u", 1.0),
    "spring_lower_m": ("spring_l", 1.0),
    "V_upper_V": ("V_u", 1.0),
    "V_lower_V": ("V_l", 1.0),
    "duty_upper": ("duty_u", 1.0),
    "duty_lower": ("duty_l", 1.0),
}
_COL = {n: i for i, n in enumerate(OUT_COLUMNS)}


def temp_path(path: str | Path) -> Path:
    """A fresh hidden temporary name beside ``path`` (for write-then-rename)."""
    path = Path(path)
    return path.with_name(f".{path.name}.{uuid.uuid4().hex[:12]}.tmp")


def atomic_write(path: str | Path, write) -> None:
    """Write via a temporary file in the same directory, then rename: never half-written.

    ``write(tmp)`` creates the temporary file itself, so the result gets the usual
    permissions (umask), not the 0600 of :func:`tempfile.mkstemp`.
    """
    path = Path(path)
    tmp = temp_path(path)
    try:
        write(str(tmp))
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


@dataclass
class SimulationResult:
    """A run's signals (sampled at the output interval), metrics and run statistics."""

    spec: Any
    data: np.ndarray
    segment_start_s: np.ndarray
    segment_reached_s: np.ndarray
    substeps: int
    interlock_violations: int
    wall_s: float
    _metrics: dict | None = field(default=None, repr=False)

    # ---- signals ---------------------------------------------------------------------
    def raw(self, name: str) -> np.ndarray:
        """A kernel signal in SI units (radians for angles)."""
        return self.data[:, _COL[name]]

    @property
    def t(self) -> np.ndarray:
        return self.raw("t")

    def signal(self, name: str) -> np.ndarray:
        """An exported signal by its column name (e.g. ``theta_deg``)."""
        src, scale = EXPORT_COLUMNS[name]
        if scale is None:
            return self.raw(src) * (math.pi * self.spec.params.wire_diameter_m**2 / 4.0)
        return self.raw(src) * scale

    def __getattr__(self, name: str):
        if name in EXPORT_COLUMNS:
            return self.signal(name)
        raise AttributeError(name)

    def to_pandas(self):
        import pandas as pd

        return pd.DataFrame({name: self.signal(name) for name in EXPORT_COLUMNS})

    def to_csv(self, path: str | Path) -> None:
        df = self.to_pandas()
        atomic_write(path, lambda tmp: df.to_csv(tmp, index=False, float_format="%.9g"))

    def to_parquet(self, path: str | Path) -> None:
        df = self.to_pandas()
        atomic_write(path, lambda tmp: df.to_parquet(tmp, index=False))

    def save(self, path: str | Path) -> None:
        """CSV or Parquet by the file's suffix."""
        suffix = Path(path).suffix.lower()
        if suffix == ".csv":
            self.to_csv(path)
        elif suffix in (".parquet", ".pq"):
            self.to_parquet(path)
        else:
            raise ValueError(f"output file {path}: suffix must be .csv or .parquet")

    # ---- metrics ---------------------------------------------------------------------
    @property
    def metrics(self) -> dict:
        if self._metrics is None:
            self._metrics = compute_metrics(self)
        return self._metrics

    def summary(self) -> dict:
        """Metrics plus run statistics, JSON-ready."""
        m = dict(self.metrics)
        m["params"] = self.spec.params.name
        m["strategy"] = self.spec.strategy
        m["method"] = self.spec.method
        m["dt_s"] = self.spec.dt_s
        m["t_end_s"] = self.spec.t_end_s
        m["steps"] = self.substeps
        m["wall_s"] = self.wall_s
        return m

    def write_summary(self, path: str | Path) -> None:
        text = json.dumps(self.summary(), indent=2)
        atomic_write(path, lambda tmp: Path(tmp).write_text(text + "\n"))

    def plot(self, path: str | Path | None = None, title: str | None = None):
        from .plotting import plot_result

        return plot_result(self, path, title)


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
    """The run's metrics (:func:`smafinger.metrics.run_metrics`) with its reach settings and
    interlock count."""
    from .metrics import Span, run_metrics

    spec = result.spec
    spans = []
    for i, start, end in segment_bounds(result):
        seg = spec.profile.segments[i]
        reached = result.segment_reached_s[i]
        spans.append(Span(i, start, end, seg.target_deg, seg.enable,
                          None if math.isnan(reached) else float(reached)))
    wires = ("upper", "lower")
    m = run_metrics(result.t, result.signal("theta_deg"), spans,
                    temperature_C={w: result.signal(f"T_{w}_C") for w in wires},
                    stress_Pa={w: result.signal(f"sigma_{w}_Pa") for w in wires},
                    energy_J={"upper": result.raw("E_u"), "lower": result.raw("E_l")})
    return {"segments": m["segments"], "tol_deg": spec.tol_deg, "hold_s": spec.hold_s,
            "energy_J": m["energy_J"], "peak_temperature_C": m["peak_temperature_C"],
            "peak_stress_Pa": m["peak_stress_Pa"], "interlock_violations": result.interlock_violations}
