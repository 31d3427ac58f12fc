"""MATLAB ``.mat`` recordings (v4 and v5/v7, as :func:`scipy.io.loadmat` reads them).

Which variables hold signals, and under what source name:

- **Structure With Time** (Simulink "To Workspace", Scope): a struct with ``time`` (N x 1) and
  ``signals`` (a struct, or struct array, with ``values`` N x K, and often ``dimensions``,
  ``label``, ``blockName``). One column in all: the source is the variable's name; several
  (K > 1 or several signals): ``VAR(1)``, ``VAR(2)``, ... counting columns across the signals.
- **Array**: an N x 2 matrix ``[time, value]`` (a 2 x N matrix with N > 2, as the "To File"
  block writes it, is read the same way).
- **Table-like struct** (``write_mat(..., layout="table")``): a struct with ``time`` and one
  N-vector field per signal; each field is a source under its own name.
- **Plain vector**: its times come from the time vector variable ``t_s`` (or the one mapped
  to ``t_s``, e.g. ``--map t_s=tout``), times that mapping's scale.

The first three carry their own time, read in seconds as saved. A mapping that names ``t_s``
too must give the same times for the signals read from them, else the signal is refused
(``t_s=t_ms*1e-3`` beside a ``[time, value]`` array saved in ms would otherwise be ignored,
and an N x 2 array holding two signals, not ``[time, value]``, read with its first column as
time). A 2 x 2 matrix is refused: whether it holds its samples by rows or by columns is not
known.

A struct named ``provenance`` is returned in ``meta``; other variables are listed as ignored.
A variable that cannot be a signal is refused only if a signal is asked of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .mapping import SignalMap, Source
from .signals import TIME, RawSignal, RecordingError

#: how an N x 2 (or 2 x N) matrix is read, in messages
ARRAY = "an N x 2 [time, value] array"


@dataclass(frozen=True)
class _Entry:
    where: str
    t_s: np.ndarray | None = None
    values: np.ndarray | None = None
    error: str = ""
    own_time: str = ""  #: the layout that carries its own time ("" for a plain vector)


class MatFile:
    """The signal sources of one ``.mat`` file (see the module docstring)."""

    what = "variable"

    def __init__(self, path, entries: dict[str, _Entry], meta: dict,
                 mapped_time: tuple[Source, np.ndarray | None] | None = None):
        self.path, self._entries, self.meta = str(path), entries, meta
        self.names = tuple(entries)
        self._mapped_time = mapped_time  #: (source, its times in s, None if no vector) if the mapping names t_s

    def signal(self, source: Source) -> RawSignal:
        """The source's values times ``source.scale``, on its own time; refuses a bad variable,
        and one that carries its own time unlike the time the mapping names."""
        e = self._entries[source.name]
        if e.error:
            raise RecordingError(f"{e.where}: {e.error}")
        if e.own_time and self._mapped_time is not None:
            _check_own_time(e, *self._mapped_time)
        rows = np.arange(1, e.values.size + 1)
        return RawSignal(e.where, e.t_s, e.values * source.scale, rows, "sample", None)


def open_mat(path, smap: SignalMap) -> MatFile:
    """Read a ``.mat`` file and list its signal sources.

    Raises
    ------
    RecordingError
        If the file is not a MATLAB file scipy can read (a v7.3 file gets the hint to save
        with ``-v7``).
    """
    import zlib

    from scipy.io import loadmat
    from scipy.io.matlab import MatReadError

    try:
        data = loadmat(path, squeeze_me=False, struct_as_record=False, chars_as_strings=True)
    except NotImplementedError:
        raise RecordingError(f"{path}: a MATLAB v7.3 (HDF5) file, which scipy cannot read; "
                             f"save it with save(..., '-v7')") from None
    except (MatReadError, ValueError, TypeError, IndexError, KeyError, EOFError, OSError, zlib.error,
            UnboundLocalError) as exc:
        # what scipy raises on a file that is not a MAT-file, or is truncated or corrupt (an
        # UnboundLocalError on some damaged headers: found by an API fuzz)
        raise RecordingError(f"{path}: not a readable MATLAB file ({' '.join(str(exc).split())})") from None
    variables = {k: v for k, v in data.items() if not k.startswith("__")}
    header = data.get("__header__", b"")
    meta = {"format": "mat", "variables": tuple(variables), "block_names": {}, "labels": {}, "ignored": [],
            "header": header.decode("latin-1") if isinstance(header, bytes) else str(header)}
    entries: dict[str, _Entry] = {}
    time_var = smap.source(TIME)
    for var, value in variables.items():
        for name, entry in _sources(path, var, value, variables, time_var, meta):
            if name in entries:  # the same name from two variables: refuse only if it is used
                entry = _Entry(entry.where, error=f"two variables give a signal named {name!r}; "
                                                   f"rename one or map the other")
            entries[name] = entry
    meta["ignored"] = tuple(meta["ignored"])
    mapped_time = (time_var, _time_vector(variables, time_var)) if TIME in smap else None
    return MatFile(path, entries, meta, mapped_time)


def _time_vector(variables, time_var: Source) -> np.ndarray | None:
    """The time vector variable ``time_var`` names, in s (its scale applied); None if there is none."""
    t = variables.get(time_var.name)
    t = _unwrap(t) if t is not None else None
    if not (isinstance(t, np.ndarray) and t.dtype.kind in "iuf" and t.ndim == 2 and min(t.shape) == 1):
        return None
    return t.astype(np.float64).ravel() * time_var.scale


def _check_own_time(e: _Entry, time_var: Source, t: np.ndarray | None) -> None:
    """Refuse a signal that carries its own time (``e.own_time``) when the mapping names a
    ``t_s`` that does not give the same times."""
    if t is not None and t.size == e.t_s.size and np.allclose(t, e.t_s, rtol=1e-9, atol=1e-12):
        return
    got = "no time vector of that name" if t is None else _span(t, "times", "an empty vector")
    raise RecordingError(
        f"{e.where}: is {e.own_time}, with its own time ({_span(e.t_s)}, "
        f"read in seconds as saved), but the mapping names t_s={time_var.to_text()} ({got}); remove t_s from the "
        "mapping, or save the signal as a plain vector beside its time vector")


def _span(t: np.ndarray, noun: str = "samples", empty: str = "no samples") -> str:
    """``t``'s size and range in words, ``empty`` for an empty one (it was indexed: found by an API fuzz)."""
    return f"{t.size} {noun} from {t[0]:g} to {t[-1]:g} s" if t.size else empty


def _sources(path, var, value, variables, time_var: Source, meta):
    where = f"{path}: variable {var!r}"
    s = _unwrap(value)
    if _is_struct(s):
        fields = s._fieldnames
        if "signals" in fields:
            return _simulink(path, var, s, meta)
        if "time" in fields:
            return _table(path, var, s)
        if var == "provenance":
            meta["provenance"] = to_python(s)
        else:
            meta["ignored"].append(var)
        return []
    if isinstance(s, np.ndarray) and s.dtype.kind in "iuf" and s.ndim == 2:
        a = s.astype(np.float64)
        if a.shape == (2, 2):
            return [(var, _Entry(where, error="is a 2 x 2 matrix: whether it is [time, value] by columns or by rows "
                                              "is not known; save at least 3 samples"))]
        if a.shape[1] == 2:
            return [(var, _Entry(where, a[:, 0].copy(), a[:, 1].copy(), own_time=ARRAY))]
        if a.shape[0] == 2 and a.shape[1] > 2:
            return [(var, _Entry(where, a[0].copy(), a[1].copy(), own_time=ARRAY))]
        if min(a.shape) == 1:
            return [(var, _vector(where, a.ravel(), variables, time_var))]
    meta["ignored"].append(var)
    shape = "x".join(map(str, getattr(s, "shape", ()))) or "scalar"
    return [(var, _Entry(where, error=f"is a {shape} {type(s).__name__} of {getattr(s, 'dtype', '?')}, not a "
                                       f"signal: save it as Structure With Time or an N x 2 [time, value] array"))]


def _vector(where, v, variables, time_var: Source) -> _Entry:
    t = _time_vector(variables, time_var)
    if t is None:
        return _Entry(where, error=f"is a plain vector and there is no time vector {time_var.name!r}; "
                                   f"map one (e.g. --map t_s=tout) or save as Structure With Time")
    if t.size != v.size:
        return _Entry(where, error=f"has {v.size} samples but the time vector {time_var.name!r} has {t.size}")
    return _Entry(where, t, v)


def _simulink(path, var, s, meta):
    where = f"{path}: variable {var!r}"
    columns = []  # (values, label, blockName)
    t, t_error = _time(s)
    for sig in _struct_list(s.signals):
        vals = _unwrap(getattr(sig, "values", None))
        if not (isinstance(vals, np.ndarray) and vals.dtype.kind in "iuf" and vals.ndim == 2):
            shape = getattr(vals, "shape", None)
            return [(var, _Entry(where, error=f"signals.values is not a numeric N x K matrix (shape {shape})"))]
        if vals.shape[0] == 1 and vals.shape[1] > 1 and t is not None and t.size == vals.shape[1]:
            # a 1 x N row as long as the time: one signal (scipy.io.savemat writes a 1-D array as a
            # row; read as N one-sample signals it was "no input variable"; found by review)
            vals = vals.T
        label, block = _text(getattr(sig, "label", "")), _text(getattr(sig, "blockName", ""))
        columns += [(vals[:, j].astype(np.float64), label, block) for j in range(vals.shape[1])]
    if not columns:
        return [(var, _Entry(where, error="has no signals (signals is empty)"))]
    names = [var] if len(columns) == 1 else [f"{var}({k})" for k in range(1, len(columns) + 1)]
    out = []
    for name, (v, label, block) in zip(names, columns):
        w = f"{path}: variable {name!r}"
        meta["block_names"][name] = block or _text(getattr(s, "blockName", ""))
        meta["labels"][name] = label
        if t_error:
            out.append((name, _Entry(w, error=t_error)))
        elif t.size != v.size:
            out.append((name, _Entry(w, error=f"time has {t.size} samples but signals.values has {v.size} rows")))
        else:
            out.append((name, _Entry(w, t, v, own_time="a Structure With Time")))
    return out


def _table(path, var, s):
    t, t_error = _time(s)
    out = []
    for f in s._fieldnames:
        v = _unwrap(getattr(s, f))
        if f == "time" or not (isinstance(v, np.ndarray) and v.dtype.kind in "iuf" and v.ndim == 2
                               and min(v.shape) <= 1):
            continue
        w = f"{path}: variable '{var}.{f}'"
        v = v.astype(np.float64).ravel()
        if t_error:
            out.append((f, _Entry(w, error=t_error)))
        elif t.size != v.size:
            out.append((f, _Entry(w, error=f"has {v.size} samples but {var}.time has {t.size}")))
        else:
            out.append((f, _Entry(w, t, v, own_time="a field of a struct with a time field")))
    return out


def _time(s) -> tuple[np.ndarray | None, str]:
    t = _unwrap(getattr(s, "time", None))
    if not (isinstance(t, np.ndarray) and t.dtype.kind in "iuf") or t.size == 0:
        return None, ("has no time (field 'time' is empty: the block saved 'Structure'; "
                      "save as 'Structure With Time')")
    if t.ndim != 2 or min(t.shape) != 1:
        return None, f"field 'time' is a {'x'.join(map(str, t.shape))} matrix, not a vector"
    return t.astype(np.float64).ravel(), ""


# ---- scipy.io.loadmat's objects --------------------------------------------------------------
def _is_struct(x) -> bool:
    return hasattr(x, "_fieldnames")


def _unwrap(x):
    """A 1 x 1 cell or struct array -> its element (repeatedly)."""
    while isinstance(x, np.ndarray) and x.dtype == object and x.size == 1:
        x = x.flat[0]
    return x


def _struct_list(x) -> list:
    """A struct, a struct array or a cell array of structs -> the structs, in MATLAB order."""
    x = _unwrap(x)
    if _is_struct(x):
        return [x]
    if isinstance(x, np.ndarray) and x.dtype == object:
        return [s for item in x.ravel(order="F") for s in _struct_list(item)]
    return []


def _text(x) -> str:
    x = _unwrap(x)
    if isinstance(x, np.ndarray) and x.dtype.kind == "U":
        return "".join(x.ravel().tolist())
    return x if isinstance(x, str) else ""


def to_python(x):
    """A loaded struct/char/number -> dict / str / int or float / list (for ``meta``)."""
    x = _unwrap(x)
    if _is_struct(x):
        return {f: to_python(getattr(x, f)) for f in x._fieldnames}
    if isinstance(x, np.ndarray):
        if x.dtype.kind == "U":
            return _text(x)
        if x.dtype.kind in "biuf" and x.size == 1:
            return x.ravel()[0].item()
        if x.dtype.kind in "biuf":
            return x.ravel().tolist()
        return [to_python(i) for i in x.ravel(order="F")]
    return x
