"""CSV and Parquet recordings: one time column and one column per signal.

A signal sampled at a lower rate leaves cells empty (CSV) or null (Parquet); each signal keeps
the times of its own non-empty cells. A row whose used cells are all empty is skipped.
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from .mapping import SignalMap, Source
from .reader import name_listing
from .signals import TIME, RawSignal, RecordingError, check_times, describe_row


class TabularFile:
    """A table of columns, each as (float values, present mask), read lazily per column.

    Parameters
    ----------
    path : str
        For messages.
    names : sequence of str
        The column names in file order (must be unique).
    column : callable
        ``column(name) -> (values, present)``: float64 values (anything where absent) and a
        bool mask of the cells that hold a value.
    smap : SignalMap
        Gives the time column (``t_s`` or the mapped one) and its scale.
    row_word, line_offset :
        How rows are named in messages (see :class:`~.signals.RawSignal`).
    meta : dict
        Format facts for :attr:`Recording.meta`.
    """

    what = "column"

    def __init__(self, path, names, column, smap: SignalMap, row_word: str, line_offset: int | None, meta: dict):
        self.path, self.names, self._column = str(path), tuple(names), column
        self.row_word, self.line_offset, self.meta = row_word, line_offset, meta
        dup = [n for n, k in Counter(self.names).items() if k > 1]
        if dup:
            raise RecordingError(f"{self.path}: column {dup[0]!r} appears {self.names.count(dup[0])} times; "
                                 f"names must be unique")
        self.time = smap.source(TIME)
        if self.time.name not in self.names:
            raise RecordingError(
                f"{self.path}: no time column {self.time.name!r} (columns: {name_listing(self.names)}); "
                f"name it t_s (seconds) or map it, e.g. --map t_s=time_ms*1e-3")
        self._t = None

    def _where(self, name: str) -> str:
        return f"{self.path}: column {name!r}"

    def _times(self) -> tuple[np.ndarray, np.ndarray]:
        if self._t is None:
            t, present = self._column(self.time.name)
            t = t * self.time.scale
            rows = np.arange(1, t.size + 1)
            check_times(self._where(self.time.name), t[present], rows[present], self.row_word, self.line_offset)
            self._t = (t, present)
        return self._t

    def signal(self, source: Source) -> RawSignal:
        """The column ``source.name`` times ``source.scale``, on the times of its own cells."""
        t, t_present = self._times()
        v, present = self._column(source.name)
        orphan = present & ~t_present
        if orphan.any():
            i = int(np.flatnonzero(orphan)[0])
            raise RecordingError(f"{self._where(self.time.name)}, {describe_row(i + 1, self.row_word, self.line_offset)}: "
                                 f"time is empty but column {source.name!r} has a value")
        return RawSignal(self._where(source.name), t[present], v[present] * source.scale,
                         np.flatnonzero(present) + 1, self.row_word, self.line_offset)


# ---- CSV ------------------------------------------------------------------------------------
def open_csv(path, smap: SignalMap) -> TabularFile:
    """A comma-separated file with a header line of column names (UTF-8, a BOM is allowed).

    Data row N is file line N + 1. Cells are numbers; an empty cell means "no sample here";
    ``nan``/``inf`` are read as such and refused later as non-finite samples.
    """
    import pandas as pd

    try:
        df = pd.read_csv(path, header=None, dtype=str, keep_default_na=False, skip_blank_lines=False,
                         encoding="utf-8-sig")
    except pd.errors.EmptyDataError:
        raise RecordingError(f"{path}: the file is empty (expected a header line naming t_s and the signals)") from None
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise RecordingError(f"{path}: not a readable CSV file ({_one_line(exc)})") from None
    names = [str(x).strip() for x in df.iloc[0].fillna("")]
    if len(names) == 1 and any(sep in names[0] for sep in ";\t"):
        raise RecordingError(f"{path}: one column {names[0]!r}; the file looks separated by ';' or tabs, "
                             f"save it comma-separated")
    body = df.iloc[1:].fillna("")
    index = {n: j for j, n in enumerate(names)}

    def column(name: str):
        return _parse_cells(path, name, body.iloc[:, index[name]].to_numpy(dtype=str))

    return TabularFile(path, names, column, smap, "data row", 1,
                       {"format": "csv", "columns": tuple(names), "rows": int(body.shape[0])})


def _parse_cells(path, name: str, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    cells = np.char.strip(cells)
    present = cells != ""
    try:
        values = np.where(present, cells, "nan").astype(np.float64)
    except ValueError:  # find the cell (numpy's parser is stricter than float(): use float's)
        values = np.full(cells.size, np.nan)
        for i in np.flatnonzero(present):
            try:
                values[i] = float(cells[i])
            except ValueError:
                raise RecordingError(f"{path}: column {name!r}, {describe_row(int(i) + 1, 'data row', 1)}: "
                                     f"{str(cells[i])!r} is not a number") from None
    return values, present


# ---- Parquet --------------------------------------------------------------------------------
def open_parquet(path, smap: SignalMap) -> TabularFile:
    """A Parquet file with numeric columns; a null cell means "no sample here" (row N is 1-based)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        pf = pq.ParquetFile(path)
        names = pf.schema_arrow.names
    except (pa.ArrowException, OSError) as exc:
        raise RecordingError(f"{path}: not a readable Parquet file ({_one_line(exc)})") from None

    def column(name: str):
        try:
            col = pf.read(columns=[name]).column(0)
        except (pa.ArrowException, OSError) as exc:
            raise RecordingError(f"{path}: column {name!r} cannot be read ({_one_line(exc)})") from None
        if not (pa.types.is_integer(col.type) or pa.types.is_floating(col.type)):
            raise RecordingError(f"{path}: column {name!r} holds {col.type}, not numbers")
        present = ~col.is_null().to_numpy(zero_copy_only=False)
        values = col.cast(pa.float64()).to_numpy(zero_copy_only=False)
        return np.asarray(values, dtype=np.float64), np.asarray(present, dtype=bool)

    return TabularFile(path, names, column, smap, "row", None,
                       {"format": "parquet", "columns": tuple(names), "rows": int(pf.metadata.num_rows)})


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__
