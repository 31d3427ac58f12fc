"""Which runs of a sweep are finished, and the streaming merge into ``OUT`` and its traces.

:class:`Finished` reads only the ``run_id`` and ``status`` columns of ``OUT`` and of every
part, and keeps, for each point of the sweep, where the newest finished row of its run is
(12 bytes per point). :func:`write_table` and :func:`write_traces` then write the outputs
block by block in point order, reading only the row groups a block needs.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .sweep_rows import INT_COLUMNS, METRIC_COLUMNS, SEGMENT_COLUMNS, STEP_REFINEMENT, STRING_COLUMNS, TRACE_COLUMNS
from ..files import atomic_write
from .sweep_store import (META_KEY, TABLE_BLOCK, TRACE_BLOCK_SAMPLES, IdIndex, StoreError, _ids, read_meta,
                          traces_interval, traces_path)


class Source:
    """One file of finished rows (``OUT`` or a part) and, if usable, its traces file.

    Files are opened only while read (a sweep may have thousands of parts); the last row
    groups read are kept until :meth:`release`.
    """

    def __init__(self, path: Path, traces: Path | None, is_out: bool = False):
        import pyarrow.parquet as pq

        self.path, self.traces, self.is_out = path, traces, is_out
        md = pq.read_metadata(path)
        self.names = md.schema.to_arrow_schema().names
        self._bounds = np.cumsum([0] + [md.row_group(i).num_rows for i in range(md.num_row_groups)])
        self._rows: tuple[tuple, object] | None = None
        self._traces: tuple[tuple, object] | None = None
        #: OUT: its rows' points (in its own sweep), to skip the traces' row groups of other
        #: points; None (read every row group) unless its traces are of the same merge
        self.own_points: np.ndarray | None = None

    def read_columns(self, names: list[str]):
        import pyarrow.parquet as pq

        return pq.read_table(self.path, columns=[n for n in names if n in self.names])

    def take(self, rows: np.ndarray):
        """The given rows (indices into the file, in that order), reading only their row groups."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        g = np.searchsorted(self._bounds, rows, side="right") - 1
        groups = tuple(np.unique(g).tolist())
        if self._rows is None or self._rows[0] != groups:
            self._rows = (groups, pq.ParquetFile(self.path).read_row_groups(list(groups)))
        sizes = np.diff(self._bounds)[list(groups)]
        first = dict(zip(groups, np.concatenate([[0], np.cumsum(sizes)[:-1]]).tolist()))
        pos = np.array([first[k] for k in g.tolist()], dtype=np.int64) + (rows - self._bounds[g])
        return self._rows[1].take(pa.array(pos, type=pa.int64()))

    def traces_of(self, run_ids: np.ndarray, rows: np.ndarray):
        """The trace samples of these runs (``S16`` ids; ``rows``: their rows in this file)."""
        import pyarrow as pa
        import pyarrow.compute as pc
        import pyarrow.parquet as pq

        pf = pq.ParquetFile(self.traces)
        groups = tuple(range(pf.metadata.num_row_groups))
        if self.is_out and self.own_points is not None and "point" in pf.schema_arrow.names:
            groups = _groups_with(pf, self.own_points[rows])
        if self._traces is None or self._traces[0] != groups:
            self._traces = (groups, pf.read_row_groups(list(groups)))
        table = self._traces[1]
        want = pa.array([r.decode() for r in run_ids.tolist()], type=pa.string())
        return table.filter(pc.is_in(table["run_id"].cast(pa.string()), value_set=want))

    def release(self) -> None:
        self._rows = self._traces = None


def _groups_with(pf, points: np.ndarray) -> tuple:
    """Row groups of a traces file whose ``point`` statistics may hold any of ``points``."""
    idx = pf.schema_arrow.get_field_index("point")
    want = np.unique(points)
    out = []
    for i in range(pf.metadata.num_row_groups):
        st = pf.metadata.row_group(i).column(idx).statistics
        if st is None or not st.has_min_max:
            out.append(i)
            continue
        k = np.searchsorted(want, st.min)
        if k < len(want) and want[k] <= st.max:
            out.append(i)
    return tuple(out)


def same_merge(out_meta: dict, traces: Path) -> bool:
    """Whether ``OUT.traces`` was written by the merge that wrote ``OUT`` (both carry its
    ``merge`` id): only then are its ``point`` numbers OUT's. A merge stopped between the two
    files (the traces are written first) leaves traces numbered by the new spec beside the old
    table; skipping row groups by those numbers lost runs' samples for good (they counted as
    finished). Read by run id alone, every row group, the same file gives every run's samples.
    Tables written before the id existed have none: read whole."""
    try:
        merge = (read_meta(traces) or {}).get("merge")
    except Exception:  # noqa: BLE001 - unreadable: not the same
        return False
    return merge is not None and merge == out_meta.get("merge")


class Finished:
    """For every point: the newest finished row of its run (source, row), from ``OUT`` and
    the parts. With ``traces_interval_s``, a run finished without its trace at that interval
    does not count (a failed run has none and counts)."""

    def __init__(self, out: Path, pdir: Path, index: IdIndex, traces_interval_s: float | None = None):
        self.index, self.traces, self.traces_interval_s = index, traces_interval_s is not None, traces_interval_s
        n = len(index.ids)
        self.src = np.full(n, -1, dtype=np.int32)
        self.row = np.zeros(n, dtype=np.int64)
        self.sources: list[Source] = []
        self.out_meta: dict | None = None
        self.n_parts = 0
        if out.exists():
            try:
                self.out_meta = read_meta(out)
            except Exception:  # noqa: BLE001 - not parquet at all
                self.out_meta = None
            if self.out_meta is None:
                raise StoreError(f"{out} exists and is not a smafinger sweep table; choose another --out or remove it")
            tp = traces_path(out)
            has = bool(self.out_meta.get("traces")) and tp.exists() and self._usable(tp, legacy=False)
            src = Source(out, tp if has else None, is_out=True)
            if has and "point" in src.names and same_merge(self.out_meta, tp):
                src.own_points = src.read_columns(["point"])["point"].to_numpy()
            self._add(src)
        if pdir.is_dir():
            for f in sorted(pdir.glob("part-*.parquet")):
                if f.name.endswith(".traces.parquet"):
                    continue
                tf = f.with_name(f.name[: -len(".parquet")] + ".traces.parquet")
                try:
                    src = Source(f, tf if tf.exists() and self._usable(tf, legacy=True) else None)
                except Exception:  # noqa: BLE001 - an unreadable part is simply redone
                    continue
                self._add(src)
                self.n_parts += 1

    def _usable(self, traces: Path, legacy: bool) -> bool:
        """Whether a traces file was sampled at this sweep's interval (no traces asked: any is).
        ``legacy``: a file that states no interval (parts written before they did) is."""
        if not self.traces:
            return True
        got = traces_interval(traces)
        if got is None:
            return legacy
        return abs(got - self.traces_interval_s) <= 1e-9 * self.traces_interval_s

    def _add(self, src: Source) -> None:
        tab = src.read_columns(["run_id", "status"])
        if "run_id" not in tab.column_names:
            return
        pts = self.index.points(_ids(tab["run_id"]))
        ok = pts >= 0
        if self.traces and src.traces is None:
            status = tab["status"].to_numpy(zero_copy_only=False) if "status" in tab.column_names else None
            ok &= (status == "error") if status is not None else False
        s = len(self.sources)
        self.sources.append(src)
        self.src[pts[ok]] = s
        self.row[pts[ok]] = np.flatnonzero(ok)

    @property
    def done(self) -> np.ndarray:
        return self.src >= 0

    def failed_count(self) -> int:
        """Runs of the sweep whose finished row says ``status = error``."""
        return self._count("status", lambda status: status == "error")

    def flagged_count(self) -> int:
        """Runs of the sweep whose finished row has warnings (rows written before the
        ``warnings`` column existed have none)."""
        return self._count("warnings", lambda w: np.array([bool(x) for x in w], dtype=bool))

    def unchecked_count(self) -> int:
        """Finished ``ok`` rows with no step check (:data:`.sweep_rows.STEP_REFINEMENT` NaN, or a
        row written before that column existed); a check that did not judge has its refinement."""
        n = 0
        for s, src in enumerate(self.sources):
            sel = np.flatnonzero(self.src == s)
            if not sel.size:
                continue
            rows = src.take(self.row[sel])
            ok = rows["status"].to_numpy(zero_copy_only=False) == "ok"
            checked = np.zeros(ok.size, dtype=bool)
            if STEP_REFINEMENT in src.names:
                checked = ~np.isnan(rows[STEP_REFINEMENT].to_numpy(zero_copy_only=False).astype(np.float64))
            n += int(np.sum(ok & ~checked))
            src.release()
        return n

    def _count(self, column: str, which) -> int:
        """Finished rows for which ``which(values of column)`` is true (sources without it: none)."""
        n = 0
        for s, src in enumerate(self.sources):
            sel = np.flatnonzero(self.src == s)
            if sel.size and column in src.names:
                values = src.take(self.row[sel])[column].to_numpy(zero_copy_only=False)
                n += int(np.sum(which(values)))
                src.release()
        return n

    def pieces(self, a: int, b: int):
        """``(source, positions in the block, rows in the source)`` for points a..b-1."""
        src, row = self.src[a:b], self.row[a:b]
        for s in np.unique(src).tolist():
            sel = np.flatnonzero(src == s)
            yield self.sources[s], sel, row[sel]

    def release(self) -> None:
        for s in self.sources:
            s.release()


# ---------------------------------------------------------------------------------------
# writing
# ---------------------------------------------------------------------------------------
def _metric_type(name: str):
    import pyarrow as pa

    if name in STRING_COLUMNS:
        return pa.string()
    if name == "point" or name in INT_COLUMNS:
        return pa.int64()
    return pa.float64()


def _conform(table, fields: list[tuple[str, object]]):
    """``table`` with exactly these (name, type) columns: cast, or all null if absent."""
    import pyarrow as pa

    n = table.num_rows
    cols = [table[name].cast(typ) if name in table.column_names else pa.nulls(n, typ) for name, typ in fields]
    return pa.table(cols, names=[name for name, _ in fields])


def _stream(path: Path, schema, blocks) -> None:
    """Write row groups to ``path`` (durably, via a temporary: :func:`~smafinger.files.atomic_write`)."""
    import pyarrow.parquet as pq

    def write(tmp: str) -> None:
        with pq.ParquetWriter(tmp, schema) as w:
            for block in blocks:
                w.write_table(block)

    atomic_write(path, write, durable=True)


def write_table(out: Path, finished: Finished, points, varied: list[str], n_segments: int, meta: dict) -> None:
    """``OUT``: one row per point, in point order (varied values, then the run's row)."""
    import pyarrow as pa

    metric_names = ["run_id", *METRIC_COLUMNS] + [f"seg{i}_{c}" for i in range(n_segments) for c in SEGMENT_COLUMNS]
    fields = [(n, _metric_type(n)) for n in metric_names]
    n = len(finished.index.ids)
    first = points.block(0, 1)
    vtypes = {v: pa.array(first[v]).type for v in varied}
    names = ["run_id", "point", *varied, *metric_names[1:]]
    schema = pa.schema([(c, vtypes.get(c) or _metric_type(c)) for c in names],
                       metadata={META_KEY: json.dumps(meta, default=str)})

    def blocks():
        for a in range(0, n, TABLE_BLOCK):
            b = min(n, a + TABLE_BLOCK)
            pos, parts = [], []
            for src, sel, rows in finished.pieces(a, b):
                parts.append(_conform(src.take(rows), fields))
                pos.append(sel)
            finished.release()
            block = pa.concat_tables(parts).take(pa.array(np.argsort(np.concatenate(pos), kind="stable")))
            cols = {"point": pa.array(np.arange(a, b, dtype=np.int64))}
            cols.update({v: pa.array(vals, type=vtypes[v]) for v, vals in points.block(a, b).items()})
            yield pa.table([cols[c] if c in cols else block[c] for c in names], schema=schema)

    _stream(out, schema, blocks())


def write_traces(path: Path, finished: Finished, samples_per_run: int, meta: dict) -> None:
    """``OUT.traces``: every run's samples, in point then time order, with ``point``."""
    import pyarrow as pa
    import pyarrow.compute as pc

    fields = [("run_id", pa.string()), ("point", pa.int64())] + [
        (c, pa.float64() if c == "t_s" else pa.float32()) for c in TRACE_COLUMNS]
    schema = pa.schema([pa.field(n, t) for n, t in fields], metadata={META_KEY: json.dumps(meta)})
    n = len(finished.index.ids)
    step = max(1, TRACE_BLOCK_SAMPLES // max(1, samples_per_run))

    def blocks():
        for a in range(0, n, step):
            parts = []
            for src, sel, rows in finished.pieces(a, min(n, a + step)):
                if src.traces is None:
                    continue  # failed runs (only they count as done without a trace)
                t = src.traces_of(finished.index.ids[a + sel], rows)
                pts = finished.index.points(_ids(t["run_id"]))
                t = t.drop_columns([c for c in ("point",) if c in t.column_names])
                parts.append(_conform(t.append_column("point", pa.array(pts)), fields))
            finished.release()
            if not parts:
                continue
            block = pa.concat_tables(parts)
            order = pc.sort_indices(block, sort_keys=[("point", "ascending"), ("t_s", "ascending")])
            yield block.take(order)

    _stream(path, schema, blocks())
