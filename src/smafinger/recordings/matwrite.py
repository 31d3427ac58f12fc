"""Write signals to a MATLAB ``.mat`` file (v5, as :func:`scipy.io.savemat` writes it), atomically.

Two layouts:

- ``"signals"`` (default): one Simulink "Structure With Time" per signal, as the "To Workspace"
  block saves it: ``VAR.time`` (N x 1), ``VAR.signals.values`` (N x 1),
  ``VAR.signals.dimensions`` (1), ``VAR.signals.label`` (the signal's name),
  ``VAR.blockName``. In MATLAB: ``plot(theta_deg.time, theta_deg.signals.values)``.
- ``"table"``: one struct ``VAR.time`` plus one N x 1 field per signal. In MATLAB:
  ``struct2table(rmfield(recording, 'time'))`` or ``plot(recording.time, recording.theta_deg)``.

Each variable or field name is a valid MATLAB identifier made from the signal's name. Beside
them a ``provenance`` struct holds strings and numbers (the package version always).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..files import atomic_write
from .signals import RecordingError

LAYOUTS = ("signals", "table")
#: MATLAB's iskeyword list: not valid as variable or field names
MATLAB_KEYWORDS = frozenset(
    "break case catch classdef continue else elseif end for function global if otherwise parfor "
    "persistent return spmd switch try while".split())
MAX_NAME = 63  # MATLAB's namelengthmax
BLOCK_NAME = "smafinger"


def matlab_name(name: str) -> str:
    """A valid MATLAB identifier made from ``name``.

    Characters other than letters, digits and ``_`` become ``_``; a name not starting with a
    letter gets an ``x`` in front; a keyword gets a ``_`` behind; at most 63 characters.
    ``"theta_deg"`` and ``"T_upper_C"`` stay as they are; ``"omega (deg/s)"`` becomes
    ``"omega__deg_s_"``.
    """
    ident = re.sub(r"[^A-Za-z0-9_]", "_", str(name))
    if not ident[:1].isalpha():
        ident = "x" + ident
    if ident in MATLAB_KEYWORDS:
        ident += "_"
    return ident[:MAX_NAME]


def write_mat(path, t_s, signals: Mapping[str, np.ndarray], provenance: Mapping | None = None,
              layout: str = "signals", table_name: str = "recording") -> dict[str, str]:
    """Write signals sampled at common times to a MATLAB file, atomically.

    Parameters
    ----------
    path : str or Path
        The ``.mat`` file; it is written to a temporary file in the same directory and renamed
        into place, so that on any error nothing is left behind and an older file is kept.
    t_s : array_like
        N strictly increasing finite times [s].
    signals : mapping of str to array_like
        Signal name -> N values (any float, NaN included, which MATLAB keeps).
    provenance : mapping, optional
        Strings, numbers, booleans, 1-D numeric sequences and nested mappings of those, e.g.
        ``{"command": "smafinger simulate ...", "params": {"h0": 20.0}}``. The package version
        is added as ``smafinger_version`` unless given.
    layout : {"signals", "table"}
        One Structure With Time per signal, or one table-like struct (see the module docstring).
    table_name : str
        The struct's name in the ``"table"`` layout.

    Returns
    -------
    dict
        Signal name -> the MATLAB variable (``"signals"``) or field (``"table"``) name used.

    Raises
    ------
    RecordingError
        Naming the argument at fault: a path not ending in ``.mat``, bad times, a signal of
        the wrong length, two names that make the same MATLAB identifier, a provenance value
        that is not a string or a number, an unknown layout.
    """
    path = Path(path)
    if path.suffix.lower() != ".mat":
        raise RecordingError(f"write_mat: path {str(path)!r} must end in .mat")
    mdict, names = mat_variables(t_s, signals, provenance, layout, table_name)
    atomic_write(path, lambda tmp: save_mat(tmp, mdict))
    return names


def mat_variables(t_s, signals: Mapping[str, np.ndarray], provenance: Mapping | None = None,
                  layout: str = "signals", table_name: str = "recording") -> tuple[dict, dict[str, str]]:
    """The MATLAB variables :func:`write_mat` writes, checked: ``(variables, names)``.

    For writers that stage several files together (:class:`smafinger.files.Outputs`): write
    the variables with :func:`save_mat`.
    """
    from .. import __version__

    if layout not in LAYOUTS:
        raise RecordingError(f"write_mat: layout {layout!r} is not one of {', '.join(LAYOUTS)}")
    t = _times(t_s)
    if layout == "table":
        _check_table_name(table_name)
    reserved = {"provenance"} | ({matlab_name(table_name), "time"} if layout == "table" else set())
    names = _identifiers(signals, reserved)
    columns = {names[k]: _column(k, v, t.size) for k, v in signals.items()}
    prov = _provenance({"smafinger_version": __version__, **dict(provenance or {})}, "provenance")
    if layout == "signals":
        mdict = {}
        for label, var in names.items():
            sig = {"values": columns[var], "dimensions": 1.0, "label": label, "blockName": BLOCK_NAME}
            mdict[var] = {"time": t[:, None], "signals": sig, "blockName": BLOCK_NAME}
    else:
        mdict = {matlab_name(table_name): {"time": t[:, None], **columns}}
    mdict["provenance"] = prov
    return mdict, names


def table_variables(columns: Mapping[str, np.ndarray], provenance: Mapping | None = None,
                    table_name: str = "table") -> dict:
    """A table without a time axis (e.g. a sweep's, one row per run) as MATLAB variables: one
    struct ``table_name`` with an N x 1 field per column (numbers as doubles, text as a cell
    array of strings; ``struct2table(table_name)`` in MATLAB) and the ``provenance`` struct."""
    from .. import __version__

    if not isinstance(columns, Mapping) or not columns:
        raise RecordingError("write_mat: columns must be a non-empty dict of name -> values")
    _check_table_name(table_name)
    names = _identifiers(columns, {"provenance", matlab_name(table_name)})
    n = {len(v) for v in columns.values()}
    if len(n) != 1:
        raise RecordingError(f"write_mat: the columns have different lengths {sorted(n)}")
    fields = {}
    for name, ident in names.items():
        v = np.asarray(columns[name])
        if v.dtype.kind in "biuf":
            fields[ident] = v.astype(np.float64)[:, None]
        else:
            cells = np.empty((len(v), 1), dtype=object)
            cells[:, 0] = ["" if x is None else str(x) for x in v.tolist()]
            fields[ident] = cells
    prov = _provenance({"smafinger_version": __version__, **dict(provenance or {})}, "provenance")
    return {matlab_name(table_name): fields, "provenance": prov}


def _check_table_name(table_name: str) -> None:
    """The table's struct cannot be named as the provenance struct beside it (it was written over,
    a file with no data; found by an API fuzz)."""
    if matlab_name(table_name) == "provenance":
        raise RecordingError(f"write_mat: table_name {table_name!r} is the name of the provenance struct "
                             "written beside the table; choose another")


def save_mat(file: str | Path, mdict: dict) -> None:
    """Write MATLAB variables (from :func:`mat_variables`) to ``file`` as a v5 ``.mat``.

    The file's 116-byte text header names smafinger instead of the time of writing, so that
    the same variables always make the same bytes.
    """
    from scipy.io import savemat

    from .. import __version__

    with open(file, "wb") as fh:
        savemat(fh, mdict, format="5", long_field_names=True, do_compression=True, oned_as="column")
        fh.seek(0)
        fh.write(f"MATLAB 5.0 MAT-file, written by smafinger {__version__}".ljust(116).encode("ascii"))


def _times(t_s) -> np.ndarray:
    t = np.asarray(t_s, dtype=np.float64)
    if t.ndim != 1 or t.size == 0:
        raise RecordingError(f"write_mat: t_s must be a non-empty 1-D array, got shape {t.shape}")
    bad = ~np.isfinite(t)
    bad[1:] |= ~(t[1:] > t[:-1])
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise RecordingError(f"write_mat: t_s[{i}] = {float(t[i])!r} must be finite and after the previous time")
    return t


def _identifiers(signals: Mapping, reserved: set[str]) -> dict[str, str]:
    if not isinstance(signals, Mapping) or not signals:
        raise RecordingError("write_mat: signals must be a non-empty dict of name -> values")
    used: dict[str, str] = {}
    for name in signals:
        ident = matlab_name(name)
        if ident in reserved:
            raise RecordingError(f"write_mat: signal {name!r} would be named {ident!r}, which is taken")
        if ident in used:
            raise RecordingError(f"write_mat: signals {used[ident]!r} and {name!r} both make the MATLAB "
                                 f"name {ident!r}; rename one")
        used[ident] = name
    return {name: ident for ident, name in used.items()}


def _column(name: str, values, n: int) -> np.ndarray:
    try:
        v = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise RecordingError(f"write_mat: signal {name!r} is not numeric") from None
    if v.shape != (n,):
        raise RecordingError(f"write_mat: signal {name!r} has shape {v.shape}, expected ({n},) like t_s")
    return v[:, None]


def _provenance(value, where: str):
    """Check and convert a provenance value for savemat (dicts become structs)."""
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            ident = matlab_name(k)
            if ident in out:
                raise RecordingError(f"write_mat: {where}: keys make the same MATLAB name {ident!r}")
            out[ident] = _provenance(v, f"{where}.{ident}")
        return out
    if isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return np.array([[bool(value)]])  # a MATLAB logical
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        if abs(int(value)) > 2**53:
            raise RecordingError(f"write_mat: {where} = {value} is too large for a MATLAB double")
        return float(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        a = np.asarray(value)
        if a.ndim == 1 and a.dtype.kind in "iuf":
            return a.astype(np.float64)[None, :]
    raise RecordingError(f"write_mat: {where} = {value!r} is not a string, a number or a numeric list")

