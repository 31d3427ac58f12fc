"""Reading and validating a sweep spec (TOML): ``[base]``, ``[sweep]``, ``[vary]``.

Every error is a :class:`~smafinger.analysis.sweep_spec.SweepSpecError` whose message names
the file, the field and the value. The points themselves are checked later, in the workers
(:func:`~smafinger.analysis.sweep.run_sweep`), before any run starts.
"""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from ..parameters import ParameterError
from ..parameters.base import field_spec
from .sweep_spec import DEFAULT_MAX_RUNS, MODES, RUN_KEYS, SweepSpec, SweepSpecError, Vary, scenario_spec

BASE_KEYS = set(RUN_KEYS) | {"set", "scenario"}
SWEEP_KEYS = {"mode", "samples", "seed", "chunk_size", "traces_interval_s", "name", "save_interval_s", "check_step"}
VARY_KEYS = {"fields", "values", "start", "stop", "num", "min", "max", "log"}


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


def load_spec(path: str | Path, max_runs: int = DEFAULT_MAX_RUNS) -> SweepSpec:
    """Read and validate a sweep spec file (see :func:`parse_spec`)."""
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
    return parse_spec(data, source=str(path), base_dir=path.parent, max_runs=max_runs)


def _probe_value(f: str):
    """A value of the right kind for field ``f`` (to check only that the field exists)."""
    if f in RUN_KEYS:
        return {float: 1.0, bool: True, str: "x"}[RUN_KEYS[f]]
    try:
        kind = field_spec(f).metadata["kind"]
    except ParameterError:
        return None  # _coerce reports the unknown name
    return {"float": 1.0, "bool": True}.get(kind, "x")



def parse_spec(data: dict, source: str = "<dict>", base_dir: Path = Path("."),
               max_runs: int = DEFAULT_MAX_RUNS) -> SweepSpec:
    """Validate a sweep spec given as a dict (the parsed TOML).

    ``max_runs`` bounds ``start/stop/num`` ranges before their values are made (a single
    name's count is a lower bound of the sweep's size); the whole size is checked by
    :func:`~smafinger.analysis.sweep.run_sweep`.
    """
    unknown = set(data) - {"base", "sweep", "vary"}
    if unknown:
        raise _err(source, "top level", f"unknown table(s) {', '.join(sorted(unknown))} (expected [base], [sweep], [vary])")
    base = data.get("base", {})
    sweep = data.get("sweep", {})
    for tname, table, allowed in (("[base]", base, BASE_KEYS), ("[sweep]", sweep, SWEEP_KEYS)):
        if not isinstance(table, dict):
            raise _err(source, tname, "must be a table")
        bad = set(table) - allowed
        if bad:
            raise _err(source, tname, f"unknown key(s) {', '.join(sorted(bad))} (allowed: {', '.join(sorted(allowed))})")
    b = _parse_base(source, base)
    settings = _parse_sweep(source, sweep)
    vary = data.get("vary")
    if not isinstance(vary, dict) or not vary:
        raise _err(source, "[vary]", "is missing or empty: name at least one varied parameter")
    used_fields: dict[str, str] = {}
    for vname in vary:
        _check_column_name(source, vname)
    varies = [_parse_vary(source, vname, entry, settings["mode"], b, used_fields, max_runs)
              for vname, entry in vary.items()]
    if settings["mode"] == "list":
        lengths = {v.name: len(v.values) for v in varies}
        if len(set(lengths.values())) > 1:
            raise _err(source, "[vary]", f"mode = 'list' pairs the i-th values of every name; the lengths differ: {lengths}")
    return SweepSpec(base=b, vary=tuple(varies), source=source, base_dir=base_dir, **settings)


def _check_column_name(source: str, vname: str) -> None:
    """A varied name becomes a column of the table beside the run's: it must not be one of
    them (a [vary] status wrote two 'status' columns, both the varied values, and a table
    neither pandas nor a resume could read; found by an API fuzz)."""
    from .sweep_rows import METRIC_COLUMNS

    if vname in ("run_id", "point", *METRIC_COLUMNS) or re.fullmatch(r"seg\d+_.*", vname):
        raise _err(source, f"[vary] {vname}", "is the name of one of the table's own columns (run_id, point, "
                   "status, error, the metrics, seg<k>_...): name the varied values otherwise, with fields = "
                   "[...] naming the parameter")


def _parse_base(source: str, base: dict) -> dict[str, Any]:
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
                scenario_spec(v)
            except SweepSpecError as exc:
                raise SweepSpecError(f"{source}: {exc}") from None
            except (ValueError, KeyError) as exc:
                raise _err(source, "[base] scenario", f"{str(exc).strip(chr(39))}") from None
            b[k] = v
        else:
            b[k] = _coerce(source, f"[base] {k}", k, v)
    return b


def _parse_sweep(source: str, sweep: dict) -> dict[str, Any]:
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
    save = _number(source, "[sweep] save_interval_s", sweep.get("save_interval_s", 1.0))
    if save < 0:
        raise _err(source, "[sweep] save_interval_s", f"{save} must be >= 0")
    name = sweep.get("name", Path(source).stem if source != "<dict>" else "sweep")
    if not isinstance(name, str):
        raise _err(source, "[sweep] name", f"{name!r} is not a string")
    check = sweep.get("check_step", False)
    if not isinstance(check, bool):
        raise _err(source, "[sweep] check_step", f"{check!r} is not true or false")
    return dict(mode=mode, samples=samples, seed=seed, chunk_size=chunk, traces_interval_s=tr,
                save_interval_s=save, name=name, check_step=check)


def _parse_vary(source: str, vname: str, entry, mode: str, b: dict, used_fields: dict[str, str],
                max_runs: int) -> Vary:
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
        return _parse_range(source, where, vname, fields, entry, log)
    if has_range:
        raise _err(source, where, f"min/max ranges need mode = 'random' or 'lhs' (mode is {mode!r}); "
                                  "use values or start/stop/num")
    if has_lin:
        return Vary(vname, tuple(fields), _parse_linspace(source, where, entry, log, max_runs))
    raw = entry["values"]
    if not isinstance(raw, list) or not raw:
        raise _err(source, f"{where}.values", f"{raw!r} must be a non-empty list")
    if log:
        raise _err(source, f"{where}.log", "only applies to start/stop/num or min/max")
    values = tuple(_coerce(source, f"{where}.values[{i}]", fields[0], x) for i, x in enumerate(raw))
    for f in fields[1:]:
        for i, x in enumerate(raw):
            _coerce(source, f"{where}.values[{i}]", f, x)
    return Vary(vname, tuple(fields), values)


def _parse_range(source, where, vname, fields, entry, log) -> Vary:
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
    return Vary(vname, tuple(fields), None, lo, hi, log)


def _parse_linspace(source, where, entry, log, max_runs) -> tuple[float, ...]:
    for k in ("start", "stop", "num"):
        if k not in entry:
            raise _err(source, where, f"start/stop/num: {k} is missing")
    start = _number(source, f"{where}.start", entry["start"])
    stop = _number(source, f"{where}.stop", entry["stop"])
    num = _number(source, f"{where}.num", entry["num"], integer=True)
    if num < 1:
        raise _err(source, f"{where}.num", f"{num} must be >= 1")
    if num > max_runs:
        raise _err(source, f"{where}.num", f"{num:,} values: the sweep would have at least {num:,} runs, "
                                           f"above the limit of {max_runs:,} (--max-runs)")
    if log:
        if start <= 0 or stop <= 0:
            raise _err(source, where, f"log = true needs start and stop > 0 (got {start!r}, {stop!r})")
        vals = np.geomspace(start, stop, num)
    else:
        vals = np.linspace(start, stop, num)
    return tuple(float(x) for x in vals)
