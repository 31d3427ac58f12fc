"""A run's outputs: signals (CSV, Parquet, MATLAB), the summary (JSON) and the figure.

Each writer stages its file(s) on a :class:`smafinger.files.Outputs`, so that a command writes
all of its outputs or none. Every output says how it was made
(:func:`smafinger.provenance.provenance`):

- **CSV** (``run.csv``): plain columns with a header row, readable as is by
  ``pandas.read_csv`` and MATLAB's ``readtable``; the provenance goes to a sidecar
  ``run.provenance.json`` beside it;
- **Parquet** (``run.parquet``): the provenance in the schema metadata under
  ``smafinger.provenance`` (JSON), read back by :func:`read_provenance`;
- **MATLAB** (``run.mat``): one Simulink "Structure With Time" per signal
  (:func:`smafinger.recordings.write_mat`) and a ``provenance`` struct, whose ``run_json``
  holds the exact run definition;
- **summary** (``run.json``): the metrics (rounded to 12 significant digits), the warnings
  and ``provenance`` (exact).

``smafinger simulate --from FILE`` re-runs any of them (:func:`read_provenance`).
"""

from __future__ import annotations

import json
import numbers
import os
from pathlib import Path

from .files import Outputs, OutputError, json_ready, json_text
from .provenance import ProvenanceError, provenance

#: signal file suffix -> format
SIGNAL_FORMATS = {".csv": "csv", ".parquet": "parquet", ".pq": "parquet", ".mat": "mat"}
#: figure formats
PLOT_SUFFIXES = (".png", ".pdf", ".svg")
#: Parquet schema metadata key of the provenance
PARQUET_KEY = b"smafinger.provenance"
#: CSV float format (9 significant digits: a 1 ns step at 1000 s, 1e-9 relative elsewhere)
CSV_FLOAT_FORMAT = "%.9g"
#: rows formatted and written at a time by :func:`write_signals_csv`
CSV_CHUNK_ROWS = 8192


def sidecar_path(csv_path: str | Path) -> Path:
    """``run.csv`` -> ``run.provenance.json``."""
    return Path(csv_path).with_suffix(".provenance.json")


def check_suffix(path: str | Path, allowed, what: str) -> str:
    """The lower-case suffix of ``path`` if allowed, :class:`OutputError` otherwise."""
    suffix = Path(path).suffix.lower()
    if suffix not in allowed:
        raise OutputError(f"{what} {path}: the file name must end in {' or '.join(dict.fromkeys(allowed))}")
    return suffix


def add_signals(outputs: Outputs, result, path: str | Path, what: str = "--out", **extra) -> None:
    """Stage the signals as CSV (and its sidecar), Parquet or MATLAB by ``path``'s suffix."""
    fmt = SIGNAL_FORMATS[check_suffix(path, SIGNAL_FORMATS, what)]
    if result.samples_every != 1:  # a thinned result (SimulationResult.decimated): the file says so
        extra.setdefault("samples_every", result.samples_every)
    prov = provenance(result.spec, **extra)
    if fmt == "csv":
        names = list(result.column_names)
        columns = [result.signal(n) for n in names]
        outputs.add(path, lambda tmp: write_signals_csv(tmp, names, columns), what)
        text = json_text(prov, digits=None)
        outputs.add(sidecar_path(path), lambda tmp: Path(tmp).write_text(text), f"{what} (provenance sidecar)")
    elif fmt == "parquet":
        outputs.add(path, _parquet_writer(result, prov), what)
    else:
        from .recordings.matwrite import mat_variables, save_mat

        names = [n for n in result.column_names if n != "t_s"]
        mdict, _ = mat_variables(result.t, {n: result.signal(n) for n in names}, _for_matlab(prov))
        outputs.add(path, lambda tmp: save_mat(tmp, mdict), what)


def write_signals_csv(path: str | Path, names: list[str], columns: list) -> None:
    """The columns as CSV, byte for byte what ``pandas.DataFrame.to_csv(index=False,
    float_format=CSV_FLOAT_FORMAT)`` writes, about 3x faster and without importing pandas.

    The fast path formats a whole row with one ``%`` (C code) and covers what runs produce:
    float64 columns of finite values under plain names. Anything else (NaN, which pandas
    writes as an empty field; other dtypes; names that need quoting) goes through pandas.
    """
    import numpy as np

    if not _plain_csv(names, columns):
        import pandas as pd

        pd.DataFrame(dict(zip(names, columns))).to_csv(path, index=False, float_format=CSV_FLOAT_FORMAT)
        return
    data = np.column_stack(columns)
    row = ",".join([CSV_FLOAT_FORMAT] * len(names))
    eol = os.linesep
    with open(path, "w", encoding="utf-8", newline="") as f:
        f.write(",".join(names) + eol)
        for start in range(0, len(data), CSV_CHUNK_ROWS):
            f.write("".join([row % tuple(r) + eol for r in data[start:start + CSV_CHUNK_ROWS].tolist()]))


def _plain_csv(names: list[str], columns: list) -> bool:
    """Whether :func:`write_signals_csv`'s fast path writes what pandas would: unique names
    needing no quotes, float64 columns of equal length, every value finite."""
    import numpy as np

    if not columns or len(set(names)) != len(names) or len(names) != len(columns):
        return False
    if not all(n and n == n.strip() and not any(c in n for c in ',"\r\n') for n in names):
        return False
    return all(isinstance(c, np.ndarray) and c.dtype == np.float64 and c.ndim == 1 and len(c) == len(columns[0])
               and np.isfinite(c).all() for c in columns)


def _parquet_writer(result, prov: dict):
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pandas(result.to_pandas(), preserve_index=False)
    meta = dict(table.schema.metadata or {})
    meta[PARQUET_KEY] = json.dumps(json_ready(prov, None), sort_keys=True).encode()
    table = table.replace_schema_metadata(meta)
    return lambda tmp: pq.write_table(table, tmp)


def _for_matlab(prov: dict) -> dict:
    """The provenance as a MATLAB struct: nulls dropped, the exact definition as ``run_json``."""
    def drop_none(d):
        return {k: drop_none(v) if isinstance(v, dict) else v for k, v in d.items() if v is not None}

    out = drop_none(prov)
    out["run_json"] = json.dumps(prov["run"], sort_keys=True)
    return out


def summary_document(result, **extra) -> dict:
    """The summary JSON: metrics and run statistics (rounded), then ``provenance`` (exact)."""
    doc = json_ready(result.summary())
    doc["provenance"] = provenance(result.spec, **extra)
    return doc


def add_summary(outputs: Outputs, result, path: str | Path, what: str = "--summary", **extra) -> None:
    check_suffix(path, (".json",), what)
    text = json_text(summary_document(result, **extra), digits=None)
    outputs.add(path, lambda tmp: Path(tmp).write_text(text), what)


def add_plot(outputs: Outputs, result, path: str | Path, what: str = "--plot", title: str | None = None) -> None:
    """Stage the five-panel figure (drawn now, saved at commit)."""
    fmt = check_suffix(path, PLOT_SUFFIXES, what).lstrip(".")
    from .plotting import plot_result

    fig = plot_result(result, None, title)
    outputs.add(path, lambda tmp: _save_figure(fig, tmp, fmt), what)


def _save_figure(fig, tmp: str, fmt: str) -> None:
    import matplotlib.pyplot as plt

    try:
        fig.savefig(tmp, dpi=130, format=fmt)
    finally:
        plt.close(fig)


def read_provenance(path: str | Path) -> dict:
    """The provenance record in a summary JSON, a CSV's sidecar (or the CSV itself), a
    Parquet file or a MATLAB file written by smafinger (:class:`ProvenanceError` if none)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if not path.is_file():
        raise ProvenanceError(f"--from {path}: no such file")
    try:
        if suffix == ".csv":
            return read_provenance(sidecar_path(path)) if sidecar_path(path).is_file() else _none(path)
        if suffix in (".parquet", ".pq"):
            import pyarrow.parquet as pq

            meta = pq.read_schema(path).metadata or {}
            doc = json.loads(meta[PARQUET_KEY]) if PARQUET_KEY in meta else _none(path)
        elif suffix == ".mat":
            return _mat_provenance(path)
        else:
            doc = json.loads(path.read_text())
    except ProvenanceError:
        raise
    except _read_errors() as exc:
        first = str(exc).splitlines()[0] if str(exc) else ""
        raise ProvenanceError(f"--from {path}: cannot be read ({type(exc).__name__}: {first})") from None
    if not isinstance(doc, dict):
        return _none(path)
    record = doc.get("provenance", doc)
    return record if isinstance(record, dict) and "run" in record else _none(path)


def _read_errors() -> tuple[type[BaseException], ...]:
    """What reading a damaged JSON, Parquet or MATLAB file raises (scipy's reader: zlib's error on
    a damaged compressed variable, an UnboundLocalError on some damaged headers)."""
    import zlib

    import pyarrow
    from scipy.io.matlab import MatReadError

    return (OSError, ValueError, KeyError, TypeError, IndexError, UnicodeDecodeError, MatReadError,
            pyarrow.ArrowException, zlib.error, UnboundLocalError)


def _mat_provenance(path: Path) -> dict:
    import numpy as np
    from scipy.io import loadmat

    data = loadmat(path, squeeze_me=True, chars_as_strings=True)
    prov = data.get("provenance")
    if "run_json" not in (getattr(getattr(prov, "dtype", None), "names", None) or ()):  # a struct with run_json
        return _none(path)
    record = {"run": json.loads(str(prov["run_json"][()]))}
    for name in prov.dtype.names:  # run_sha256, and what the run recorded beside it (a scenario's name)
        value = prov[name][()]
        if name not in ("run", "run_json") and isinstance(value, (str, numbers.Number)):
            # a number comes back as numpy's or Python's (samples_every was dropped as a Python float)
            record[name] = value.item() if isinstance(value, np.generic) else value
    return record


def _none(path: Path):
    raise ProvenanceError(f"--from {path}: holds no smafinger run definition (a summary JSON, a CSV with its "
                          ".provenance.json, a Parquet or a .mat file written by smafinger simulate)")
