"""Sweep storage: durable part files, resume, and a streaming merge into the final table.

- Every file is written by :func:`smafinger.files.atomic_write` with ``durable=True``: under a
  temporary name (``.NAME.HOST-PID.RANDOM.tmp``), flushed to disk (``fsync``), renamed, and
  its folder flushed too, so a finished part survives a crash or a power cut. Temporaries
  left by a killed process are removed by the next run: only names of this pattern, and only
  those whose process (on this host) is gone.
- Finished runs go to ``OUT.parts/part-*.parquet`` (and ``part-*.traces.parquet``, written
  first); the rows file is the 'done' mark.
- Which runs are finished, and the merge into ``OUT``: :mod:`.sweep_merge`.
"""

from __future__ import annotations

import json
import re
import threading
import time
import uuid
from pathlib import Path

import numpy as np

from ..files import HOST as _HOST  # noqa: F401  (the host in temporary names)
from ..files import LEGACY_TMP_AGE_S, atomic_write, clean_stale_temporaries, fsync_dir  # noqa: F401

META_KEY = b"smafinger.sweep"
#: points per row group of the table, and the most trace samples per row group of the traces
TABLE_BLOCK = 65_536
TRACE_BLOCK_SAMPLES = 1_000_000


class StoreError(ValueError):
    """The output file is not a sweep table (never overwritten)."""


# ---------------------------------------------------------------------------------------
# file names
# ---------------------------------------------------------------------------------------
def parts_dir(out: Path) -> Path:
    return out.with_name(out.name + ".parts")


def traces_path(out: Path) -> Path:
    """``results.parquet`` -> ``results.traces.parquet``."""
    return out.with_name(out.stem + ".traces" + out.suffix)


PART_NAMES = [r"part-\d{20}-[0-9a-f]{8}(?:\.traces)?\.parquet"]


def clean_stale(out: Path) -> list[Path]:
    """:func:`clean_stale_temporaries` for ``OUT``, its traces and its parts."""
    names = [re.escape(out.name), re.escape(traces_path(out).name)]
    removed = clean_stale_temporaries(out.parent, names)
    pdir = parts_dir(out)
    removed += clean_stale_temporaries(pdir, PART_NAMES)
    return removed


# ---------------------------------------------------------------------------------------
# parts
# ---------------------------------------------------------------------------------------
def _import_writer_libraries() -> None:
    try:
        import pandas  # noqa: F401
        import pyarrow.pandas_compat  # noqa: F401
        import pyarrow.parquet  # noqa: F401
    except Exception:  # noqa: BLE001 - write_part imports them itself and reports what fails
        pass


def preload_writer() -> threading.Thread:
    """Start importing what :func:`write_part` needs, in a thread, and return it.

    pyarrow imports pandas the first time it builds any table (it checks every input for
    pandas types): 0.5-0.9 s on a 2-core machine, which the first part written used to wait
    for. Started as the run pass begins, the import overlaps the wait for the first results
    (the workers starting, the first chunk running), when this process has nothing else to
    do. Not a daemon: the process ends after the import, never in the middle of it.
    """
    th = threading.Thread(target=_import_writer_libraries, name="smafinger-preload-writer")
    th.start()
    return th


def rows_table(rows: list[dict]):
    """The rows as a table with a column for every key of any row (in order of first
    appearance), null where a row has none. ``pyarrow.Table.from_pylist`` takes the columns of
    the first row alone: a part opening with a failed run (a row with no metrics) lost every
    other run's metrics."""
    import pyarrow as pa

    names = list(dict.fromkeys(k for r in rows for k in r))
    return pa.table({k: [r.get(k) for r in rows] for k in names})


def write_part(pdir: Path, rows: list[dict], traces: dict | None, traces_interval_s: float | None = None) -> Path:
    """One part: ``part-<time>-<uid>.parquet`` (+ ``.traces.parquet``, written first, stating the
    interval its traces were sampled at), each durable."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    if not pdir.is_dir():
        pdir.mkdir()
        fsync_dir(pdir.parent)
    stem = f"part-{time.time_ns():020d}-{uuid.uuid4().hex[:8]}"
    if traces is not None:
        ttab = pa.table(traces).replace_schema_metadata({META_KEY: json.dumps({"interval_s": traces_interval_s})})
        atomic_write(pdir / f"{stem}.traces.parquet", lambda tmp: pq.write_table(ttab, tmp), durable=True)
    tab = rows_table(rows)
    path = pdir / f"{stem}.parquet"
    atomic_write(path, lambda tmp: pq.write_table(tab, tmp), durable=True)
    return path


def read_meta(path: Path) -> dict | None:
    import pyarrow.parquet as pq

    meta = pq.read_schema(path).metadata or {}
    if META_KEY not in meta:
        return None
    return json.loads(meta[META_KEY])


def traces_interval(path: Path) -> float | None:
    """The interval a traces file (``OUT.traces`` or a part's) says its runs were sampled at;
    None if it says none (parts written before they did) or cannot be read."""
    try:
        value = (read_meta(path) or {}).get("interval_s")
    except Exception:  # noqa: BLE001 - unreadable: no interval
        return None
    return float(value) if value is not None else None


def _ids(column) -> np.ndarray:
    return np.asarray(column.to_numpy(zero_copy_only=False), dtype=object).astype("S16")


class IdIndex:
    """Run id -> point of the current sweep (ids in point order, ``S16``)."""

    def __init__(self, ids: np.ndarray):
        self.ids = ids
        self._order = np.argsort(ids, kind="stable")
        self._sorted = ids[self._order]

    def points(self, ids: np.ndarray) -> np.ndarray:
        """The point of each id, -1 for ids not in the sweep."""
        if len(self._sorted) == 0 or len(ids) == 0:
            return np.full(len(ids), -1, dtype=np.int64)
        k = np.searchsorted(self._sorted, ids)
        k = np.minimum(k, len(self._sorted) - 1)
        hit = self._sorted[k] == ids
        return np.where(hit, self._order[k], -1).astype(np.int64)
