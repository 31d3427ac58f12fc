"""Parametric sweeps: a TOML spec, many runs, one tidy table, resumable.

A sweep spec (see ``examples/sweep-fig8.toml`` and ``docs/sweeps.md``)::

    [base]                        # the run every point starts from
    params = "paper2010-table2"   # a named set or a .toml file (relative to the spec)
    strategy = "open-loop"
    voltage = "0:8:0,8:0:0"
    t_end_s = 20.0
    set = { C_DF_heating_Nms = 0.02 }   # optional fixed parameter overrides

    [sweep]
    mode = "grid"                 # grid | list | random | lhs
    # samples = 200, seed = 1     # random / lhs

    [vary.h0]                     # one varied name ...
    fields = ["h0_heating_W_m2K", "h0_cooling_W_m2K"]   # ... may set several fields
    start = 60.0
    stop = 70.0
    num = 21

The table has a row per run: ``run_id`` (a hash of the run's canonical spec: unique, and
stable across reruns of the same spec), ``point`` (its index in the sweep), the varied
values, ``status``/``error``, and the run's metrics (see :data:`METRIC_COLUMNS` and the
per-segment ``seg{i}_*`` columns). Results are written as they finish into
``OUT.parts/``; a rerun of an interrupted sweep skips the runs already there; at the end the
parts are consolidated into ``OUT`` (written atomically) and removed.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
import os
import time
import tomllib
import uuid
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..engine.run import RunSpec, SimulationError, make_spec  # noqa: F401 (SimulationError: re-exported)
from ..parameters import ParameterError, ParameterSet, resolve
from ..parameters.base import field_spec
from ..profiles import ProfileError

#: bump when the meaning of a run's canonical spec (and so of run_id) changes
RUN_ID_SCHEMA = 1
MODES = ("grid", "list", "random", "lhs")
#: run settings (make_spec arguments) that a sweep may set in [base] or vary
RUN_KEYS = {
    "params": str, "strategy": str, "profile": str, "voltage": str, "t_end_s": float,
    "dt_s": float, "method": str, "output_interval_s": float, "tol_deg": float,
    "hold_s": float, "independent_wait": bool,
}
BASE_KEYS = set(RUN_KEYS) | {"set", "scenario"}
SWEEP_KEYS = {"mode", "samples", "seed", "chunk_size", "traces_interval_s", "name"}
VARY_KEYS = {"fields", "values", "start", "stop", "num", "min", "max", "log"}
#: the joint has started to move once it is this far from its initial angle
MOTION_THRESHOLD_DEG = 0.5
#: per-run metric columns, in table order (then the per-segment ``seg{i}_*`` columns)
METRIC_COLUMNS = (
    "status", "error", "energy_upper_J", "energy_lower_J", "peak_T_upper_C", "peak_T_lower_C",
    "peak_stress_upper_Pa", "peak_stress_lower_Pa", "interlock_violations", "theta_max_deg",
    "theta_min_deg", "theta_final_deg", "motion_start_s", "steps", "wall_s",
)
SEGMENT_COLUMNS = ("target_deg", "start_s", "reached_s", "overshoot_deg")
TRACE_COLUMNS = ("t_s", "theta_deg", "theta_ref_deg", "omega_deg_s", "T_upper_C", "T_lower_C",
                 "xi_upper", "xi_lower", "sigma_upper_Pa", "sigma_lower_Pa", "V_upper_V",
                 "V_lower_V", "duty_upper", "duty_lower")
_META_KEY = b"smafinger.sweep"


class SweepSpecError(ValueError):
    """The sweep spec is malformed; the message names the field and the value."""


class SweepInterrupted(KeyboardInterrupt):
    """The sweep was interrupted; what finished is saved (run it again to resume)."""

    def __init__(self, done: int, total: int, parts: Path):
        super().__init__(f"interrupted after {done} of {total} runs; finished runs are saved in "
                         f"{parts} - run the same sweep again to resume")
        self.done, self.total, self.parts = done, total, parts


# ---------------------------------------------------------------------------------------
# the spec
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Vary:
    """One varied name: the fields it sets and its values (or its range, for sampling)."""

    name: str
    fields: tuple[str, ...]
    values: tuple | None = None
    low: float | None = None
    high: float | None = None
    log: bool = False


@dataclass(frozen=True)
class Run:
    point: int
    run_id: str
    values: dict
    spec: RunSpec


@dataclass(frozen=True)
class SweepSpec:
    base: dict
    vary: tuple[Vary, ...]
    mode: str = "grid"
    samples: int | None = None
    seed: int | None = None
    chunk_size: int | None = None
    traces_interval_s: float = 0.1
    name: str = "sweep"
    source: str = "<dict>"
    base_dir: Path = field(default=Path("."), compare=False)

    # ---- points ----------------------------------------------------------------------
    def points(self) -> list[dict[str, Any]]:
        """The varied values of every point, in sweep order."""
        names = [v.name for v in self.vary]
        if self.mode == "grid":
            combos = itertools.product(*(v.values for v in self.vary))
        elif self.mode == "list":
            combos = zip(*(v.values for v in self.vary))
        else:
            u = _unit_samples(self.mode, self.samples, len(self.vary), self.seed)
            cols = []
            for j, v in enumerate(self.vary):
                if v.log:
                    x = np.exp(np.log(v.low) + u[:, j] * (np.log(v.high) - np.log(v.low)))
                else:
                    x = v.low + u[:, j] * (v.high - v.low)
                cols.append([float(a) for a in x])
            combos = zip(*cols)
        return [dict(zip(names, c)) for c in combos]

    def runs(self) -> list[Run]:
        """Every run, validated (raises :class:`SweepSpecError` naming the point)."""
        base_params = self._base_params()
        runs, seen = [], {}
        for i, values in enumerate(self.points()):
            try:
                spec = self._run_spec(base_params, values)
            except (ParameterError, ProfileError, ValueError, TypeError) as exc:
                shown = ", ".join(f"{k} = {v!r}" for k, v in values.items())
                raise SweepSpecError(f"{self.source}: point {i} ({shown}): {exc}") from None
            rid = run_id(spec)
            if rid in seen:
                raise SweepSpecError(
                    f"{self.source}: points {seen[rid]} and {i} are the same run "
                    f"({', '.join(f'{k} = {v!r}' for k, v in values.items())}); remove the duplicate value"
                )
            seen[rid] = i
            runs.append(Run(i, rid, values, spec))
        return runs

    def _base_params(self):
        b = self.base
        if "scenario" in b:
            return None
        try:
            p = resolve(_params_ref(b.get("params", "paper2010"), self.base_dir))
            return p.replace(**b.get("set", {})) if b.get("set") else p
        except ParameterError as exc:
            raise SweepSpecError(f"{self.source}: [base] {exc}") from None

    def _run_spec(self, base_params, values) -> RunSpec:
        run_kw = {k: v for k, v in self.base.items() if k in RUN_KEYS}
        param_changes = {}
        for v in self.vary:
            for f in v.fields:
                if f in RUN_KEYS:
                    run_kw[f] = values[v.name]
                else:
                    param_changes[f] = values[v.name]
        if "scenario" in self.base:
            spec = _scenario_spec(self.base["scenario"])
            params = spec.params
            if "params" in run_kw:
                params = resolve(_params_ref(run_kw.pop("params"), self.base_dir))
            if self.base.get("set"):
                params = params.replace(**self.base["set"])
            kw = {f.name: getattr(spec, f.name) for f in dataclasses.fields(spec)}
            kw.update(run_kw)
            kw["params"] = params.replace(**param_changes) if param_changes else params
            return make_spec(**kw)
        params = base_params
        if "params" in run_kw:  # varied parameter set
            params = resolve(_params_ref(run_kw.pop("params"), self.base_dir))
            if self.base.get("set"):
                params = params.replace(**self.base["set"])
        if param_changes:
            params = params.replace(**param_changes)
        return make_spec(params=params, **run_kw)

    def canonical(self) -> dict:
        """A JSON-ready description of the sweep (stored in the table's metadata)."""
        return {
            "name": self.name, "mode": self.mode, "samples": self.samples, "seed": self.seed,
            "base": {k: v for k, v in self.base.items()},
            "vary": [{"name": v.name, "fields": list(v.fields),
                      "values": list(v.values) if v.values is not None else None,
                      "min": v.low, "max": v.high, "log": v.log} for v in self.vary],
        }


def _params_ref(value, base_dir: Path):
    """A parameter-set name, or a .toml path resolved relative to the spec's folder."""
    if isinstance(value, ParameterSet):
        return value
    s = str(value)
    if s.endswith(".toml") and not Path(s).is_absolute():
        cand = base_dir / s
        if cand.exists():
            return str(cand)
    return s


def _scenario_spec(name: str) -> RunSpec:
    try:
        from .. import scenarios  # optional module (another part of the project)
    except ImportError:
        raise SweepSpecError(f"[base] scenario = {name!r}: this version of smafinger has no scenarios; "
                             "give params/strategy/profile/voltage instead") from None
    got = scenarios.get(name)
    if isinstance(got, RunSpec):
        return got
    if isinstance(got, dict):
        return make_spec(**got)
    spec = getattr(got, "spec", None)
    if isinstance(spec, RunSpec):
        return spec
    if callable(spec):
        return spec()
    raise SweepSpecError(f"[base] scenario = {name!r}: cannot turn {type(got).__name__} into a run spec")


def _unit_samples(mode: str, n: int, d: int, seed: int | None) -> np.ndarray:
    if mode == "random":
        return np.random.default_rng(seed).random((n, d))
    from scipy.stats import qmc

    try:
        sampler = qmc.LatinHypercube(d=d, rng=seed)
    except TypeError:  # scipy < 1.15
        sampler = qmc.LatinHypercube(d=d, seed=seed)
    return sampler.random(n)


def _err(source: str, where: str, msg: str) -> SweepSpecError:
    return SweepSpecError(f"{source}: {where}: {msg}")


def _number(source, where, value, integer=False):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _err(source, where, f"{value!r} is not a number")
    if integer:
        if isinstance(value, float) and not value.is_integer():
            raise _err(source, where, f"{value!r} is not a whole number")
        return int(value)
    if not math.isfinite(value):
        raise _err(source, where, f"{value!r} is not finite")
    return float(value)


def _coerce(source: str, where: str, target: str, value):
    """A varied or base value converted to the kind its target field expects."""
    if target in RUN_KEYS:
        kind = RUN_KEYS[target]
        if kind is float:
            return _number(source, where, value)
        if kind is bool:
            if not isinstance(value, bool):
                raise _err(source, where, f"{value!r} is not true/false")
            return value
        if not isinstance(value, str):
            raise _err(source, where, f"{value!r} is not a string")
        return value
    try:
        f = field_spec(target)
    except ParameterError:
        raise _err(source, where, f"{target!r} is neither a parameter nor a run setting "
                                  f"({', '.join(sorted(RUN_KEYS))})") from None
    kind = f.metadata["kind"]
    if kind == "float":
        return _number(source, where, value)
    if kind == "bool":
        if not isinstance(value, bool):
            raise _err(source, where, f"{value!r} is not true/false")
        return value
    if kind == "str" or kind == "choice":
        if not isinstance(value, str):
            raise _err(source, where, f"{value!r} is not a string")
        return value
    return value  # pragma: no cover


def load_spec(path: str | Path) -> SweepSpec:
    """Read and validate a sweep spec file."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise SweepSpecError(f"sweep spec not found: {path}") from None
    except IsADirectoryError:
        raise SweepSpecError(f"sweep spec {path} is a directory, not a TOML file") from None
    except tomllib.TOMLDecodeError as exc:
        raise SweepSpecError(f"{path}: not valid TOML ({exc})") from None
    except UnicodeDecodeError:
        raise SweepSpecError(f"{path}: not a text (TOML) file") from None
    return parse_spec(data, source=str(path), base_dir=path.parent)


def parse_spec(data: dict, source: str = "<dict>", base_dir: Path = Path(".")) -> SweepSpec:
    """Validate a sweep spec given as a dict (the parsed TOML)."""
    unknown = set(data) - {"base", "sweep", "vary"}
    if unknown:
        raise _err(source, "top level", f"unknown table(s) {', '.join(sorted(unknown))} (expected [base], [sweep], [vary])")
    base = data.get("base", {})
    sweep = data.get("sweep", {})
    vary = data.get("vary")
    for tname, table, allowed in (("[base]", base, BASE_KEYS), ("[sweep]", sweep, SWEEP_KEYS)):
        if not isinstance(table, dict):
            raise _err(source, tname, "must be a table")
        bad = set(table) - allowed
        if bad:
            raise _err(source, tname, f"unknown key(s) {', '.join(sorted(bad))} (allowed: {', '.join(sorted(allowed))})")

    # ---- [base] ---------------------------------------------------------------------
    b: dict[str, Any] = {}
    for k, v in base.items():
        if k == "set":
            if not isinstance(v, dict):
                raise _err(source, "[base] set", f"{v!r} must be a table of parameter = value")
            b["set"] = {f: _coerce(source, f"[base] set.{f}", f, x) for f, x in v.items()}
            for f in b["set"]:
                if f in RUN_KEYS:
                    raise _err(source, f"[base] set.{f}", "is a run setting: put it in [base] directly")
        elif k == "scenario":
            if not isinstance(v, str):
                raise _err(source, "[base] scenario", f"{v!r} is not a string")
            try:
                _scenario_spec(v)
            except SweepSpecError as exc:
                raise SweepSpecError(f"{source}: {exc}") from None
            except (ValueError, KeyError) as exc:
                raise _err(source, "[base] scenario", f"{str(exc).strip(chr(39))}") from None
            b[k] = v
        else:
            b[k] = _coerce(source, f"[base] {k}", k, v)

    # ---- [sweep] --------------------------------------------------------------------
    mode = sweep.get("mode", "grid")
    if mode not in MODES:
        raise _err(source, "[sweep] mode", f"{mode!r} is not one of {', '.join(MODES)}")
    samples = sweep.get("samples")
    seed = sweep.get("seed")
    if mode in ("random", "lhs"):
        if samples is None:
            raise _err(source, "[sweep] samples", f"is required with mode = {mode!r}")
        samples = _number(source, "[sweep] samples", samples, integer=True)
        if samples < 1:
            raise _err(source, "[sweep] samples", f"{samples} must be >= 1")
        seed = 0 if seed is None else _number(source, "[sweep] seed", seed, integer=True)
        if seed < 0:
            raise _err(source, "[sweep] seed", f"{seed} must be >= 0")
    else:
        for k in ("samples", "seed"):
            if k in sweep:
                raise _err(source, f"[sweep] {k}", f"is only used with mode = 'random' or 'lhs', not {mode!r}")
    chunk = sweep.get("chunk_size")
    if chunk is not None:
        chunk = _number(source, "[sweep] chunk_size", chunk, integer=True)
        if chunk < 1:
            raise _err(source, "[sweep] chunk_size", f"{chunk} must be >= 1")
    tr = _number(source, "[sweep] traces_interval_s", sweep.get("traces_interval_s", 0.1))
    if tr <= 0:
        raise _err(source, "[sweep] traces_interval_s", f"{tr} must be > 0")
    name = sweep.get("name", Path(source).stem if source != "<dict>" else "sweep")
    if not isinstance(name, str):
        raise _err(source, "[sweep] name", f"{name!r} is not a string")

    # ---- [vary] ---------------------------------------------------------------------
    if not isinstance(vary, dict) or not vary:
        raise _err(source, "[vary]", "is missing or empty: name at least one varied parameter")
    varies = []
    used_fields: dict[str, str] = {}
    for vname, entry in vary.items():
        where = f"[vary] {vname}"
        if isinstance(entry, list):
            entry = {"values": entry}
        if not isinstance(entry, dict):
            raise _err(source, where, f"{entry!r} must be a list of values or a table")
        bad = set(entry) - VARY_KEYS
        if bad:
            raise _err(source, where, f"unknown key(s) {', '.join(sorted(bad))} (allowed: {', '.join(sorted(VARY_KEYS))})")
        fields = entry.get("fields", [vname])
        if isinstance(fields, str):
            fields = [fields]
        if not isinstance(fields, list) or not fields or not all(isinstance(f, str) for f in fields):
            raise _err(source, f"{where}.fields", f"{fields!r} must be a non-empty list of field names")
        for f in fields:
            _coerce(source, f"{where}.fields", f, _probe_value(f))  # known field?
            if f in used_fields:
                raise _err(source, f"{where}.fields", f"{f!r} is already set by [vary] {used_fields[f]}")
            if f in b.get("set", {}) or f in b:
                raise _err(source, f"{where}.fields", f"{f!r} is also fixed in [base]; vary it or fix it, not both")
            used_fields[f] = vname
        log = entry.get("log", False)
        if not isinstance(log, bool):
            raise _err(source, f"{where}.log", f"{log!r} is not true/false")
        has_values = "values" in entry
        has_lin = any(k in entry for k in ("start", "stop", "num"))
        has_range = any(k in entry for k in ("min", "max"))
        if sum((has_values, has_lin, has_range)) != 1:
            raise _err(source, where, "give exactly one of: values = [...], start/stop/num, or min/max")
        if mode in ("random", "lhs"):
            if not has_range:
                raise _err(source, where, f"mode = {mode!r} samples within ranges: give min and max")
            lo = _number(source, f"{where}.min", entry.get("min"))
            hi = _number(source, f"{where}.max", entry.get("max"))
            if not lo < hi:
                raise _err(source, where, f"min = {lo!r} must be below max = {hi!r}")
            if log and lo <= 0:
                raise _err(source, f"{where}.min", f"{lo!r} must be > 0 with log = true")
            for f in fields:
                numeric = RUN_KEYS[f] is float if f in RUN_KEYS else field_spec(f).metadata["kind"] == "float"
                if not numeric:
                    raise _err(source, f"{where}.fields", f"{f!r} is not numeric and cannot be sampled in a range")
            varies.append(Vary(vname, tuple(fields), None, lo, hi, log))
            continue
        if has_range:
            raise _err(source, where, f"min/max ranges need mode = 'random' or 'lhs' (mode is {mode!r}); "
                                      "use values or start/stop/num")
        if has_lin:
            for k in ("start", "stop", "num"):
                if k not in entry:
                    raise _err(source, where, f"start/stop/num: {k} is missing")
            start = _number(source, f"{where}.start", entry["start"])
            stop = _number(source, f"{where}.stop", entry["stop"])
            num = _number(source, f"{where}.num", entry["num"], integer=True)
            if num < 1:
                raise _err(source, f"{where}.num", f"{num} must be >= 1")
            if log:
                if start <= 0 or stop <= 0:
                    raise _err(source, where, f"log = true needs start and stop > 0 (got {start!r}, {stop!r})")
                vals = np.geomspace(start, stop, num)
            else:
                vals = np.linspace(start, stop, num)
            values = tuple(float(x) for x in vals)
        else:
            raw = entry["values"]
            if not isinstance(raw, list) or not raw:
                raise _err(source, f"{where}.values", f"{raw!r} must be a non-empty list")
            if log:
                raise _err(source, f"{where}.log", "only applies to start/stop/num or min/max")
            values = tuple(_coerce(source, f"{where}.values[{i}]", fields[0], x) for i, x in enumerate(raw))
            for f in fields[1:]:
                for i, x in enumerate(raw):
                    _coerce(source, f"{where}.values[{i}]", f, x)
        varies.append(Vary(vname, tuple(fields), values))
    if mode == "list":
        lengths = {v.name: len(v.values) for v in varies}
        if len(set(lengths.values())) > 1:
            raise _err(source, "[vary]", f"mode = 'list' pairs the i-th values of every name; the lengths differ: {lengths}")
    spec = SweepSpec(base=b, vary=tuple(varies), mode=mode, samples=samples, seed=seed,
                     chunk_size=chunk, traces_interval_s=tr, name=name, source=source,
                     base_dir=base_dir)
    return spec


def _probe_value(f: str):
    """A value of the right kind for field ``f`` (to check only that the field exists)."""
    if f in RUN_KEYS:
        return {float: 1.0, bool: True, str: "x"}[RUN_KEYS[f]]
    try:
        kind = field_spec(f).metadata["kind"]
    except ParameterError:
        return None  # _coerce reports the unknown name
    return {"float": 1.0, "bool": True}.get(kind, "x")


# ---------------------------------------------------------------------------------------
# run identity
# ---------------------------------------------------------------------------------------
def canonical_run(spec: RunSpec) -> dict:
    """Everything that decides a run's outcome, as plain JSON-ready values."""
    v = spec.voltage
    return {
        "schema": RUN_ID_SCHEMA,
        "params": spec.params.to_dict(),
        "strategy": spec.strategy,
        "profile": spec.profile.to_text(),
        "voltage": None if v is None else ",".join(f"{t!r}:{a!r}:{b!r}" for t, a, b in v.steps),
        "t_end_s": spec.t_end_s, "dt_s": spec.dt_s, "method": spec.method,
        "output_interval_s": spec.output_interval_s, "tol_deg": spec.tol_deg,
        "hold_s": spec.hold_s, "independent_wait": spec.independent_wait,
    }


def run_id(spec: RunSpec) -> str:
    """16 hex digits of the SHA-256 of the run's canonical spec."""
    text = json.dumps(canonical_run(spec), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


# ---------------------------------------------------------------------------------------
# worker side: one run's row
# ---------------------------------------------------------------------------------------
def metrics_row(result, traces_interval_s: float | None = None) -> dict:
    """The table row (metrics) of one run; with ``traces_interval_s`` also its sampled trace
    under the key ``"_trace"``. Runs in the worker (picklable, module level)."""
    s = result.summary()
    th = result.signal("theta_deg")
    t = result.t
    moved = np.flatnonzero(np.abs(th - th[0]) > MOTION_THRESHOLD_DEG)
    row = {
        "status": "ok", "error": "",
        "energy_upper_J": s["energy_J"]["upper"], "energy_lower_J": s["energy_J"]["lower"],
        "peak_T_upper_C": s["peak_temperature_C"]["upper"],
        "peak_T_lower_C": s["peak_temperature_C"]["lower"],
        "peak_stress_upper_Pa": s["peak_stress_Pa"]["upper"],
        "peak_stress_lower_Pa": s["peak_stress_Pa"]["lower"],
        "interlock_violations": int(s["interlock_violations"]),
        "theta_max_deg": float(np.max(th)), "theta_min_deg": float(np.min(th)),
        "theta_final_deg": float(th[-1]),
        "motion_start_s": float(t[moved[0]]) if moved.size else math.nan,
        "steps": int(s["steps"]), "wall_s": float(s["wall_s"]),
    }
    segs = {seg["index"]: seg for seg in s["segments"]}
    for i, seg_def in enumerate(result.spec.profile.segments):
        seg = segs.get(i)
        row[f"seg{i}_target_deg"] = float(seg_def.target_deg)
        row[f"seg{i}_start_s"] = float(seg["start_s"]) if seg else math.nan
        reached = seg["reached_s"] if seg else None
        row[f"seg{i}_reached_s"] = math.nan if reached is None else float(reached)
        row[f"seg{i}_overshoot_deg"] = float(seg["overshoot_deg"]) if seg else math.nan
    if traces_interval_s:
        step = max(1, round(traces_interval_s / result.spec.output_interval_s))
        row["_trace"] = {c: np.ascontiguousarray(result.signal(c)[::step]) for c in TRACE_COLUMNS}
    return row


def error_row(exc: BaseException) -> dict:
    return {"status": "error", "error": f"{type(exc).__name__}: {exc}"}


def _column_order(varied: list[str], n_segments: int) -> list[str]:
    cols = ["run_id", "point", *varied, *METRIC_COLUMNS]
    for i in range(n_segments):
        cols += [f"seg{i}_{c}" for c in SEGMENT_COLUMNS]
    return cols


# ---------------------------------------------------------------------------------------
# storage
# ---------------------------------------------------------------------------------------
def parts_dir(out: Path) -> Path:
    return out.with_name(out.name + ".parts")


def traces_path(out: Path) -> Path:
    """``results.parquet`` -> ``results.traces.parquet``."""
    return out.with_name(out.stem + ".traces" + out.suffix)


def _atomic_parquet(table, path: Path) -> None:
    import pyarrow.parquet as pq

    from ..results import atomic_write

    atomic_write(path, lambda tmp: pq.write_table(table, tmp))


def _rows_table(rows: list[dict]):
    import pandas as pd
    import pyarrow as pa

    df = pd.DataFrame(rows)
    return pa.Table.from_pandas(df, preserve_index=False)


def _traces_table(traces: list[tuple[str, dict]]):
    import pyarrow as pa

    ids = [rid for rid, tr in traces for _ in range(len(tr["t_s"]))]
    cols = {"run_id": pa.array(ids, type=pa.string())}
    for c in TRACE_COLUMNS:
        cols[c] = pa.array(np.concatenate([tr[c] for _, tr in traces]))
    return pa.table(cols)


def _write_part(pdir: Path, rows: list[dict], traces: list[tuple[str, dict]]) -> None:
    """One part: ``part-<time>-<uid>.parquet`` (+ ``.traces.parquet``), each atomic.

    The rows file is the 'done' mark: it is written last.
    """
    pdir.mkdir(exist_ok=True)
    stem = f"part-{time.time_ns():020d}-{uuid.uuid4().hex[:8]}"
    if traces:
        _atomic_parquet(_traces_table(traces), pdir / f"{stem}.traces.parquet")
    _atomic_parquet(_rows_table(rows), pdir / f"{stem}.parquet")


def _read_meta(path: Path) -> dict | None:
    import pyarrow.parquet as pq

    meta = pq.read_schema(path).metadata or {}
    if _META_KEY not in meta:
        return None
    return json.loads(meta[_META_KEY])


def _load_done(out: Path, pdir: Path, traces: bool):
    """Finished rows (metrics only, keyed by run_id) and traces from OUT and its parts.

    Later sources win (parts, newest last): a run done twice keeps its newest row.
    """
    import pandas as pd
    import pyarrow.parquet as pq

    frames, tframes = [], []
    if out.exists():
        try:
            meta = _read_meta(out)
        except Exception:  # noqa: BLE001 - not parquet at all
            meta = None
        if meta is None:
            raise SweepSpecError(f"{out} exists and is not a smafinger sweep table; choose another --out or remove it")
        df = pq.read_table(out).to_pandas()
        df = df.drop(columns=[c for c in ["point", *meta.get("varied", [])] if c in df.columns])
        df["_src"] = "out"
        frames.append(df)
        tp = traces_path(out)
        if traces and tp.exists():
            tdf = pq.read_table(tp).to_pandas()
            tdf["_src"] = "out"
            tframes.append(tdf)
    if pdir.is_dir():
        for f in sorted(pdir.glob("part-*.parquet")):
            if f.name.endswith(".traces.parquet"):
                continue
            try:
                df = pq.read_table(f).to_pandas()
            except Exception:  # noqa: BLE001 - an unreadable part is simply redone
                continue
            df["_src"] = f.name
            frames.append(df)
            tf = f.with_name(f.name[: -len(".parquet")] + ".traces.parquet")
            if traces and tf.exists():
                try:
                    tdf = pq.read_table(tf).to_pandas()
                except Exception:  # noqa: BLE001
                    tdf = None
                if tdf is not None:
                    tdf["_src"] = f.name
                    tframes.append(tdf)
    rows = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=["run_id", "_src"])
    trs = pd.concat(tframes, ignore_index=True) if tframes else pd.DataFrame(columns=["run_id", "_src"])
    if traces and len(rows):
        # a run counts as done only if its trace is there too (a failed run has none)
        have = set(zip(trs["run_id"], trs["_src"]))
        failed = (rows["status"] == "error").to_numpy() if "status" in rows.columns else np.zeros(len(rows), bool)
        traced = np.array([(r, s) in have for r, s in zip(rows["run_id"], rows["_src"])], dtype=bool)
        rows = rows[traced | failed]
    rows = rows.drop_duplicates("run_id", keep="last")
    return rows, trs


# ---------------------------------------------------------------------------------------
# running
# ---------------------------------------------------------------------------------------
@dataclass
class SweepReport:
    out: Path
    traces_out: Path | None
    total: int
    resumed: int
    ran: int
    failed: int
    wall_s: float
    backend: str


def run_sweep(spec: SweepSpec | str | Path, out: str | Path | None = None, *, workers: int | None = None,
              scheduler=None, traces: bool = False, progress: bool = False, console=None,
              chunk_size: int | None = None,
              on_progress: Callable[[int, int], None] | None = None) -> SweepReport:
    """Run a sweep (resuming one that was interrupted) and write its table to ``out``.

    ``scheduler``: a Dask scheduler address (``tcp://HOST:PORT``) or ``Client``; without it
    the runs go to ``workers`` local processes (default: every core). ``on_progress(done,
    total)`` is called after each finished chunk. Returns a :class:`SweepReport`.
    """
    from ..engine import batch

    t_start = time.perf_counter()
    if not isinstance(spec, SweepSpec):
        spec = load_spec(spec)
    out = Path(out) if out is not None else Path(f"{spec.name}.parquet")
    if out.suffix.lower() not in (".parquet", ".pq"):
        raise SweepSpecError(f"--out {out}: the results file must end in .parquet")
    if out.parent and not out.parent.is_dir():
        raise SweepSpecError(f"--out {out}: folder {out.parent} does not exist")
    if workers is not None and workers < 1:
        raise SweepSpecError(f"--workers {workers}: must be >= 1")
    runs = spec.runs()
    by_id = {r.run_id: r for r in runs}
    pdir = parts_dir(out)
    done_rows, _ = _load_done(out, pdir, traces)
    done_ids = set(done_rows["run_id"]) & set(by_id)
    todo = [r for r in runs if r.run_id not in done_ids]
    total = len(runs)
    if traces and any(r.spec.output_interval_s > spec.traces_interval_s * (1 + 1e-9) for r in todo):
        raise SweepSpecError(f"{spec.source}: [sweep] traces_interval_s = {spec.traces_interval_s} is shorter "
                             "than the runs' output_interval_s")
    reduce = partial(metrics_row, traces_interval_s=spec.traces_interval_s if traces else None)
    _say(console, f"sweep {spec.name}: {total} runs"
                  + (f", {len(done_ids)} already done" if done_ids else ""))
    backend = "nothing left to run"
    failed = 0
    if todo:
        pool = batch.make_pool(workers, scheduler)
        backend = (f"Dask scheduler {scheduler if isinstance(scheduler, str) else 'client'} "
                   f"({pool.slots} worker threads)" if scheduler is not None else
                   f"{pool.slots} local worker process{'es' if pool.slots > 1 else ''}"
                   if pool.slots > 1 else "this process")
        _say(console, f"running {len(todo)} runs on {backend}")
        size = chunk_size or spec.chunk_size or batch.auto_chunk_size(len(todo), pool.slots)
        chunks = batch.chunked([(r.run_id, r.spec) for r in todo], size)
        done = len(done_ids)
        bar = _progress(console) if progress else None
        task = bar.add_task("sweep", total=total, completed=done) if bar else None
        try:
            if bar:
                bar.start()
            for outcomes in pool.map_chunks(chunks, reduce):
                rows, trs = [], []
                for rid, ok, value in outcomes:
                    if ok:
                        tr = value.pop("_trace", None)
                        if tr is not None:
                            trs.append((rid, tr))
                    else:
                        value = error_row(value)
                        failed += 1
                    rows.append({"run_id": rid, **value})
                _write_part(pdir, rows, trs)
                done += len(rows)
                if bar:
                    bar.update(task, completed=done)
                if on_progress:
                    on_progress(done, total)
        except KeyboardInterrupt:
            if bar:
                bar.stop()
            pool.close(cancel=True)
            raise SweepInterrupted(done, total, pdir) from None
        except BaseException:
            if bar:
                bar.stop()
            pool.close(cancel=True)
            raise
        if bar:
            bar.stop()
        pool.close()
    _consolidate(spec, runs, out, pdir, traces)
    return SweepReport(out=out, traces_out=traces_path(out) if traces else None, total=total,
                       resumed=len(done_ids), ran=len(todo), failed=failed,
                       wall_s=time.perf_counter() - t_start, backend=backend)


def _consolidate(spec: SweepSpec, runs: list[Run], out: Path, pdir: Path, traces: bool) -> None:
    """Join the point table with every finished row; write OUT (and traces) atomically."""
    import pandas as pd
    import pyarrow as pa

    rows, trs = _load_done(out, pdir, traces)
    ids = [r.run_id for r in runs]
    rows = rows[rows["run_id"].isin(set(ids))]
    missing = set(ids) - set(rows["run_id"])
    if missing:
        raise RuntimeError(f"internal error: {len(missing)} runs have no result after the sweep")
    varied = [v.name for v in spec.vary]
    points = pd.DataFrame([{"run_id": r.run_id, "point": r.point, **r.values} for r in runs])
    keep = rows.drop(columns=["_src"])
    table = points.merge(keep, on="run_id", how="left", validate="one_to_one")
    n_seg = max(len(r.spec.profile.segments) for r in runs)
    cols = _column_order(varied, n_seg)
    extra = [c for c in table.columns if c not in cols]
    table = table[[c for c in cols if c in table.columns] + extra].sort_values("point").reset_index(drop=True)
    table["point"] = table["point"].astype("int64")
    for c in ("interlock_violations", "steps"):
        if c in table.columns and not table[c].isna().any():
            table[c] = table[c].astype("int64")
    meta = {"varied": varied, "spec": spec.canonical(), "version": _version(),
            "traces": traces, "motion_threshold_deg": MOTION_THRESHOLD_DEG}
    if traces:
        src = dict(zip(rows["run_id"], rows["_src"]))
        trs = trs[[src.get(r) == s for r, s in zip(trs["run_id"], trs["_src"])]]
        order = {rid: i for i, rid in enumerate(ids)}
        trs = trs.assign(_o=trs["run_id"].map(order)).sort_values(["_o", "t_s"], kind="stable")
        trs = trs.drop(columns=["_o", "_src"]).reset_index(drop=True)
        ttab = pa.Table.from_pandas(trs, preserve_index=False)
        ttab = ttab.replace_schema_metadata({**(ttab.schema.metadata or {}), _META_KEY: json.dumps(
            {"varied": [], "of": out.name, "interval_s": spec.traces_interval_s})})
        _atomic_parquet(ttab, traces_path(out))
    tab = pa.Table.from_pandas(table, preserve_index=False)
    tab = tab.replace_schema_metadata({**(tab.schema.metadata or {}), _META_KEY: json.dumps(meta, default=str)})
    _atomic_parquet(tab, out)
    if pdir.is_dir():
        for f in pdir.iterdir():
            try:
                f.unlink()
            except OSError:
                pass
        try:
            pdir.rmdir()
        except OSError:
            pass


def read_results(path: str | Path, with_timing: bool = True):
    """A sweep table as a pandas DataFrame (``with_timing=False`` drops ``wall_s``)."""
    import pandas as pd

    df = pd.read_parquet(path)
    if not with_timing and "wall_s" in df.columns:
        df = df.drop(columns=["wall_s"])
    return df


def _version() -> str:
    import smafinger

    return smafinger.__version__


def _say(console, text: str) -> None:
    if console is not None:
        console.print(text, highlight=False)


def _progress(console):
    from rich.progress import (BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn,
                               TimeRemainingColumn)

    return Progress(TextColumn("sweep"), BarColumn(), MofNCompleteColumn(), TextColumn("runs"),
                    TimeElapsedColumn(), TextColumn("eta"), TimeRemainingColumn(), console=console)


__all__ = ["SweepSpec", "SweepSpecError", "SweepInterrupted", "SweepReport", "Vary", "Run",
           "load_spec", "parse_spec", "run_sweep", "run_id", "canonical_run", "metrics_row",
           "read_results", "parts_dir", "traces_path", "METRIC_COLUMNS", "TRACE_COLUMNS"]
