"""``read_recording``: a CSV, Parquet or MATLAB file -> a checked :class:`Recording` in SI units."""

from __future__ import annotations

from pathlib import Path

from .mapping import SignalMap, as_signal_map
from .recording import Recording, Series
from .signals import EXTRAS, INPUTS, OUTPUTS, SPEC, TIME, RecordingError, check_signal

#: file suffix (lower case) -> format
FORMATS = {".csv": "csv", ".parquet": "parquet", ".pq": "parquet", ".mat": "mat"}


def read_recording(path, mapping=None) -> Recording:
    """Read one bench run: the input sent, the output measured, optionally T_C and resistance.

    Parameters
    ----------
    path : str or Path
        A ``.csv``, ``.parquet``/``.pq`` or ``.mat`` file (layouts in ``docs/recordings.md``).
    mapping : dict, SignalMap or None
        Which column/variable is which signal, with an optional scale, e.g.
        ``{"duty": "u_pwm", "position_m": ("x_mm", 1e-3)}`` or ``{"position_m": "x_mm*1e-3"}``
        (see :mod:`smafinger.recordings.mapping`). Signals it does not name are looked up by
        their canonical names: ``t_s``, ``duty``/``voltage_V``/``current_A``,
        ``position_m``/``theta_deg``, ``T_C``, ``resistance_ohm``.

    Returns
    -------
    Recording
        Times in seconds, values in SI (duty as a fraction, angles in radians, T in degC).

    Raises
    ------
    RecordingError
        One line naming the file, the column or variable and, where one is at fault, the row:
        missing file, unreadable format, no time, no input, no output, two inputs or two outputs
        that no mapping chooses between, non-monotonic or repeated time, a NaN/inf sample, fewer
        than 2 samples, values outside the plausible range of their signal.
    """
    smap = as_signal_map(mapping)
    path = Path(path)
    fmt = FORMATS.get(path.suffix.lower())
    if not path.exists():
        raise RecordingError(f"{path}: file not found")
    if not path.is_file():
        raise RecordingError(f"{path}: not a file")
    if fmt is None:
        raise RecordingError(f"{path}: unknown format {path.suffix!r}; use one of {', '.join(FORMATS)}")
    source_file = _open(path, fmt, smap)
    chosen = _choose(source_file, smap)
    series = {}
    for name, role in chosen.items():
        spec, src = SPEC[name], smap.source(name)
        raw = source_file.signal(src)
        check_signal(raw, spec, src.name, src.scale)
        series[role] = Series(spec.si_name, raw.t_s, raw.values * spec.to_si, src.name, src.scale)
    meta = dict(source_file.meta)
    meta["sources"] = {name: smap.source(name).to_text() for name in chosen}
    return Recording(str(path), series["input"], series["output"], series.get("T_C"),
                     series.get("resistance_ohm"), meta)


def _open(path: Path, fmt: str, smap: SignalMap):
    if fmt == "csv":
        from .tabular import open_csv
        return open_csv(path, smap)
    if fmt == "parquet":
        from .tabular import open_parquet
        return open_parquet(path, smap)
    from .matread import open_mat
    return open_mat(path, smap)


#: how many names a message lists (a file of a thousand variables gave a 20 kB line; found by review)
LISTED_NAMES = 12


def name_listing(names) -> str:
    """The names, quoted, at most :data:`LISTED_NAMES` of them (then how many more)."""
    names = list(names)
    shown = ", ".join(map(repr, names[:LISTED_NAMES])) or "none"
    return shown + (f" and {len(names) - LISTED_NAMES} more" if len(names) > LISTED_NAMES else "")


def _choose(source_file, smap: SignalMap) -> dict[str, str]:
    """canonical signal name -> role (``input``, ``output``, ``T_C``, ``resistance_ohm``)."""
    names = set(source_file.names)
    what, path = source_file.what, source_file.path
    listing = name_listing(source_file.names)
    for name, src in smap.entries:
        if name != TIME and src.name not in names:
            raise RecordingError(f"{path}: mapping {name}={src.to_text()}: no {what} {src.name!r} "
                                 f"({what}s: {listing})")
    chosen = {}
    for role, kinds in (("input", INPUTS), ("output", OUTPUTS)):
        mapped = [k for k in kinds if k in smap]
        found = mapped or [k for k in kinds if k in names]
        if len(found) > 1:
            if mapped:
                raise RecordingError(f"{path}: the mapping names {len(found)} {role}s ({', '.join(found)}); "
                                     f"keep one")
            raise RecordingError(f"{path}: {len(found)} {role}s found ({', '.join(found)}); "
                                 f"say which with a mapping, e.g. --map {found[0]}={found[0]}")
        if not found:
            raise RecordingError(f"{path}: no {role} {what}: none of {', '.join(kinds)} ({what}s: {listing}); "
                                 f"map one, e.g. --map {kinds[0]}=NAME")
        chosen[found[0]] = role
    for name in EXTRAS:
        if name in smap or name in names:
            chosen[name] = name
    return chosen
