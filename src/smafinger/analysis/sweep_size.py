"""A sweep's size, known from its spec before any point is made, and the limits it is held to
(``max_runs``, the free disk space)."""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

from .sweep_rows import METRIC_COLUMNS, TRACE_COLUMNS
from .sweep_spec import SweepSpec, SweepSpecError


class SweepSizeError(SweepSpecError):
    """The sweep is larger than allowed (``max_runs``) or than the free disk space."""


@dataclass(frozen=True)
class SweepSize:
    """A sweep's size, known before anything is made; bytes are uncompressed estimates."""

    runs: int
    table_bytes: int
    traces_bytes: int
    client_bytes: int

    def describe(self) -> str:
        tr = f", traces {_human(self.traces_bytes)}" if self.traces_bytes else ""
        return (f"{self.runs:,} runs (estimated: table {_human(self.table_bytes)}{tr}, "
                f"client memory {_human(self.client_bytes)})")


def _human(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if n < 1000 or unit == "TB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1000
    return ""  # pragma: no cover


def sweep_size(spec: SweepSpec, traces: bool) -> SweepSize:
    """The size of a sweep and its outputs, from the spec alone (no point is made)."""
    n = spec.size()
    profile = spec.base.get("profile")
    n_seg = profile.count(",") + 1 if isinstance(profile, str) else 1
    n_cols = 2 + len(spec.vary) + len(METRIC_COLUMNS) + 4 * n_seg
    samples = int(min(max_t_end(spec) / spec.traces_interval_s, 1e18)) + 1  # 1e308 s: refused later, no overflow
    per_sample = 8 + 8 + 4 * (len(TRACE_COLUMNS) - 1) + 4  # t_s, point, float32 signals, run_id
    lhs = 8 * n * len(spec.vary) if spec.mode == "lhs" else 0
    return SweepSize(n, n * n_cols * 8, n * samples * per_sample if traces else 0, n * 45 + lhs)


def check_size(spec: SweepSpec, out: Path, traces: bool, max_runs: int) -> SweepSize:
    """Refuse (:class:`SweepSizeError`, naming the size) a sweep above ``max_runs`` runs or
    whose outputs cannot fit in the free space of ``out``'s folder."""
    size = sweep_size(spec, traces)
    if size.runs > max_runs:
        raise SweepSizeError(f"{spec.source}: the sweep has {size.describe()}; that is above the limit of "
                             f"{max_runs:,} runs: raise --max-runs to run it")
    free = shutil.disk_usage(out.parent if str(out.parent) else ".").free
    if size.table_bytes + size.traces_bytes > free:
        raise SweepSizeError(f"{spec.source}: the sweep has {size.describe()}, more than the "
                             f"{_human(free)} free in {out.parent or '.'}")
    return size


def max_t_end(spec: SweepSpec) -> float:
    """The longest ``t_end_s`` of the sweep's runs [s] (the length of its traces)."""
    t_end = spec.base.get("t_end_s", 20.0)
    for v in spec.vary:
        if "t_end_s" in v.fields:
            t_end = max(v.values) if v.values is not None else v.high
    return float(t_end)
