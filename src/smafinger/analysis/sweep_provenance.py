"""How a sweep table was made, and the table as a MATLAB file.

A sweep table's Parquet metadata (``smafinger.sweep``) holds the spec as given (``spec``)
and, under ``provenance``: the smafinger version, the base parameter set resolved (every
value after ``[base] set``; a varied field's value is in its row), the base run settings
with every default filled in, and what ``run_id`` is. A row's run is the base with the row's
varied values; its ``run_id`` is the first 16 hex digits of the SHA-256 of that run's
canonical definition (:func:`~smafinger.analysis.sweep_spec.canonical_run`).

:func:`write_table_mat` writes a finished table as a MATLAB file: one struct ``sweep`` with
an N x 1 field per column (``struct2table(sweep)``) and that ``provenance``.
"""

from __future__ import annotations

import inspect
import json
from pathlib import Path

from .sweep_spec import RUN_ID_SCHEMA


def run_settings(run_kw: dict, params) -> dict:
    """The base run settings with make_spec's defaults filled in (the numerics as they resolve
    for the base run, :mod:`smafinger.engine.numerics`; a point's varied values can change its
    own, which its row's ``run_method``, ``run_dt_s``, ``run_pwm`` hold), as JSON values."""
    from ..engine.numerics import chosen
    from ..engine.run import make_spec
    from ..profiles import TargetProfile, VoltageProgram
    from ..provenance import program_text

    defaults = {k: v.default for k, v in inspect.signature(make_spec).parameters.items() if k != "params"}
    given = {**defaults, **run_kw}
    program = given["voltage"]
    if isinstance(program, str):
        program = VoltageProgram.parse(program, given["drive"])
    n = chosen(params, given["controller"], given["t_end_s"], given["method"], given["dt_s"], given["pwm"], program)
    given.update(method=n.method, dt_s=n.dt_s, pwm=n.pwm)
    out = {}
    for k, v in given.items():
        if isinstance(v, TargetProfile):
            v = v.to_text()
        elif isinstance(v, VoltageProgram):
            out["drive"] = v.kind
            v = program_text(v)
        out[k] = v
    return out


def sweep_provenance(template) -> dict:
    """The ``provenance`` entry of a sweep table's metadata (see the module docstring)."""
    from .. import __version__

    return {
        "smafinger_version": __version__,
        "base_parameters": {"mechanism": template.params.mechanism, **template.params.to_dict()},
        "base_run_settings": run_settings(template.run_kw, template.params),
        "run_id": f"first 16 hex digits of the SHA-256 of the run's canonical definition (schema {RUN_ID_SCHEMA})",
    }


def write_table_mat(table: str | Path, mat: str | Path, what: str = "--mat") -> None:
    """Write a finished sweep table (Parquet) as a MATLAB file, with its provenance."""
    import pyarrow.parquet as pq

    from ..files import atomic_write
    from ..recordings.matwrite import save_mat, table_variables
    from .sweep_store import META_KEY

    t = pq.read_table(table)
    meta = json.loads((t.schema.metadata or {}).get(META_KEY, b"{}"))
    prov = {"spec_json": json.dumps(meta.get("spec"), sort_keys=True),
            "provenance_json": json.dumps(meta.get("provenance"), sort_keys=True),
            "smafinger_version": (meta.get("provenance") or {}).get("smafinger_version", meta.get("version", "?"))}
    columns = {name: t[name].to_numpy(zero_copy_only=False) for name in t.column_names}
    mdict = table_variables(columns, prov, "sweep")
    atomic_write(Path(mat), lambda tmp: save_mat(tmp, mdict))
