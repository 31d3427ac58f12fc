"""Writing files safely: never half-written, several outputs all or none, the user's umask kept.

Every file smafinger writes goes through :class:`Outputs` (or :func:`atomic_write`, one file):

- each output is first checked (its folder exists and is writable, it is not a folder), so a
  bad path is refused with :class:`OutputError` naming it before anything is written;
- each is written to a temporary beside it, ``.NAME.HOST-PID.XXXXXXXX.tmp`` (the writer
  creates it, so it gets the usual permissions, not the 0600 of :func:`tempfile.mkstemp`);
- only when every one was written are they renamed into place, one after the other; on any
  error (Ctrl-C included) the temporaries are removed and no output is touched;
- ``durable=True`` also flushes each file and its folder to disk (``fsync``), so a finished
  file survives a crash or a power cut.

A temporary left by a killed process is recognised by its name (this host, a process that
is gone) and removed by :func:`clean_stale_temporaries`.

JSON outputs are made by :func:`json_text`: numbers rounded to :data:`JSON_DIGITS`
significant digits (float noise such as 6.2170000000000005 goes), non-finite ones as null.
"""

from __future__ import annotations

import json
import math
import os
import re
import socket
import time
import uuid
from pathlib import Path
from typing import Any, Callable

import numpy as np

#: this host, as it appears in temporary names
HOST = re.sub(r"[^A-Za-z0-9_]", "_", socket.gethostname())[:40] or "host"
#: a temporary of smafinger 0.1 (no host or pid in its name) is stale after this long [s]
LEGACY_TMP_AGE_S = 3600.0
#: significant digits of the numbers in JSON outputs: float noise goes, and a time below
#: 1000 s keeps the engine's 1 ns clock
JSON_DIGITS = 12


class OutputError(ValueError):
    """An output path cannot be written (its folder is missing, it is a folder, ...)."""


# ---------------------------------------------------------------------------------------
# writing
# ---------------------------------------------------------------------------------------
def temp_path(path: str | Path) -> Path:
    """A fresh hidden temporary name beside ``path``: ``.NAME.HOST-PID.XXXXXXXX.tmp``."""
    path = Path(path)
    return path.with_name(f".{path.name}.{HOST}-{os.getpid()}.{uuid.uuid4().hex[:8]}.tmp")


def check_output(path: str | Path, what: str | None = None) -> Path:
    """``path`` as a Path if a file can be written there; :class:`OutputError` naming
    ``what`` (e.g. ``--summary``) and the path otherwise."""
    path = Path(path)
    label = f"{what} {path}" if what else f"output file {path}"
    if str(path) in ("", ".") or path.name in ("", ".", ".."):
        raise OutputError(f"{label}: not a file name")
    folder = path.parent
    if not folder.is_dir():
        raise OutputError(f"{label}: folder {folder} does not exist")
    if path.is_dir():
        raise OutputError(f"{label}: is a folder; give a file name")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{label}: folder {folder} is not writable")
    return path


def check_outputs(targets) -> list[Path]:
    """:func:`check_output` of every ``(path, what)``, and no file named twice."""
    seen: set[Path] = set()
    out = []
    for path, what in targets:
        path = check_output(path, what)
        if path.resolve() in seen:
            raise OutputError(f"{what or 'output file'} {path}: the same file is given for two outputs")
        seen.add(path.resolve())
        out.append(path)
    return out


def fsync_dir(folder: Path) -> None:
    """Flush a folder's entries to disk (no-op where folders cannot be opened)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # pragma: no cover - platforms without directory handles
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover
        pass
    finally:
        os.close(fd)


def _fsync_file(path: Path) -> None:
    with open(path, "rb+") as f:
        os.fsync(f.fileno())


class Outputs:
    """Several output files written together: all of them, or none.

    >>> out = Outputs()
    >>> out.add("a.json", lambda tmp: Path(tmp).write_text("{}"), "--summary")  # doctest: +SKIP
    >>> out.commit()                                                            # doctest: +SKIP

    ``add`` checks the path at once (:class:`OutputError`); ``commit`` calls every
    ``write(tmp)`` (which must create the file ``tmp``), then renames them all into place.
    """

    def __init__(self, durable: bool = False):
        self.durable = durable
        self._items: list[tuple[Path, Callable[[str], object]]] = []

    def add(self, path: str | Path, write: Callable[[str], object], what: str | None = None) -> "Outputs":
        path = check_outputs([*((p, None) for p in self.paths), (path, what)])[-1]
        self._items.append((path, write))
        return self

    @property
    def paths(self) -> list[Path]:
        return [p for p, _ in self._items]

    def commit(self) -> list[Path]:
        """Write every output to its temporary, then rename them all; returns the paths."""
        staged: list[tuple[Path, Path]] = []
        try:
            for path, write in self._items:
                tmp = temp_path(path)
                staged.append((tmp, path))
                write(str(tmp))
                if not tmp.is_file():
                    raise OutputError(f"{path}: the writer made no file")
                if self.durable:
                    _fsync_file(tmp)
            for tmp, path in staged:
                os.replace(tmp, path)
            if self.durable:
                for folder in {path.parent for _, path in staged}:
                    fsync_dir(folder)
            staged = []
        finally:
            for tmp, _ in staged:
                tmp.unlink(missing_ok=True)
        return self.paths


def atomic_write(path: str | Path, write: Callable[[str], object], durable: bool = False) -> None:
    """Write one file via a temporary beside it, then rename: never half-written."""
    Outputs(durable).add(path, write).commit()


def atomic_write_text(path: str | Path, text: str) -> None:
    atomic_write(path, lambda tmp: Path(tmp).write_text(text))


# ---------------------------------------------------------------------------------------
# stale temporaries
# ---------------------------------------------------------------------------------------
def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True
    return True


def clean_stale_temporaries(folder: Path, names: list[str], now: float | None = None) -> list[Path]:
    """Remove the temporaries of files named by ``names`` (regular expressions) in ``folder``
    whose writer is gone; returns them.

    Ours: ``.NAME.HOST-PID.XXXXXXXX.tmp`` (removed if HOST is this host and PID is not a
    live process) and ``.NAME.XXXXXXXXXXXX.tmp`` of smafinger 0.1 (removed after
    :data:`LEGACY_TMP_AGE_S`). Nothing else is touched.
    """
    if not folder.is_dir():
        return []
    now = time.time() if now is None else now
    alt = "|".join(names)
    ours = re.compile(rf"^\.(?:{alt})\.(?P<host>[A-Za-z0-9_]+)-(?P<pid>\d+)\.[0-9a-f]{{8}}\.tmp$")
    legacy = re.compile(rf"^\.(?:{alt})\.[0-9a-f]{{12}}\.tmp$")
    removed = []
    for f in folder.iterdir():
        m = ours.match(f.name)
        if m:
            stale = m["host"] == HOST and not _pid_alive(int(m["pid"]))
        else:
            try:
                stale = bool(legacy.match(f.name)) and now - f.stat().st_mtime > LEGACY_TMP_AGE_S
            except OSError:
                stale = False
        if stale:
            try:
                f.unlink()
                removed.append(f)
            except OSError:
                pass
    return removed


# ---------------------------------------------------------------------------------------
# JSON
# ---------------------------------------------------------------------------------------
def json_ready(obj: Any, digits: int | None = JSON_DIGITS) -> Any:
    """``obj`` as plain JSON values: floats rounded to ``digits`` significant digits (``None``:
    kept exactly), non-finite ones as ``None``, numpy scalars and arrays, tuples and paths
    as Python values."""
    if isinstance(obj, dict):
        return {str(k): json_ready(v, digits) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [json_ready(v, digits) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        if not math.isfinite(x):
            return None
        return x if digits is None else float(f"{x:.{digits}g}")
    if isinstance(obj, Path):
        return str(obj)
    return obj


def json_text(obj: Any, digits: int | None = JSON_DIGITS) -> str:
    """``obj`` as indented JSON text (see :func:`json_ready`), ending in a newline."""
    return json.dumps(json_ready(obj, digits), indent=2, allow_nan=False) + "\n"


def write_json(path: str | Path, obj: Any, digits: int | None = JSON_DIGITS) -> None:
    """:func:`json_text` of ``obj``, written atomically."""
    text = json_text(obj, digits)
    atomic_write(path, lambda tmp: Path(tmp).write_text(text))
