"""Loading and validating bench data for identification.

Two kinds of file:

- **Strain-temperature curves** (material test under constant load), as in the
  ``sma-thermal-cycling`` data set: whitespace-separated, no header (one all-text header line
  is tolerated), ``#`` comments and blank lines ignored, three columns: temperature [degC],
  strain [-] (a fraction, not percent), stress [MPa]. Rows in time order: the heating half first
  (up to the row of maximum temperature), then the cooling half.
- **Angle-vs-time curves** of the joint (the paper's Fig. 9): CSV with a header naming the
  columns time [s] and angle [deg], and optionally voltage [V] (the upper wire's drive).
  Recognised names (case-insensitive, a unit in brackets or after ``_``): ``time``/``t``,
  ``angle``/``theta``, ``voltage``/``v``/``v_upper``. A unit given must be the one the column
  is read in (s, deg, V; :data:`UNITS`): ``angle_rad`` or ``time [ms]`` is refused, not read
  as degrees or seconds. Any other column, a second column for the same quantity and a value
  in a column the header does not name are refused too (a voltage column under another name
  was dropped, and the curve fitted at the default voltage); a column without a name (a
  trailing comma) may stay if it holds no values. Time counts from the switch-on of the wire
  (t = 0): the first row must be at most one sampling interval (its own, to the second row)
  after 0 (:data:`FIRST_TIME_SLACK`), else the curve is refused rather than fitted as a drive
  that started when the logger did (a curve logged from t = 100 s was read as a 103.5 s heating
  program and fitted to nonsense). Subtract the switch-on time from such a log.

Any problem raises :class:`DataError` with one line naming the file, the row and the problem.
"Row N" counts data rows from 1; the file's line number is given too.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..values import is_whole

if TYPE_CHECKING:
    from ..parameters import ParameterSet

#: sensible ranges (inclusive); values outside are refused as bad data
TEMPERATURE_RANGE_C = (-100.0, 300.0)
STRESS_RANGE_MPA = (0.0, 1500.0)
STRAIN_RANGE = (-0.05, 0.2)
ANGLE_RANGE_DEG = (-180.0, 180.0)
VOLTAGE_RANGE_V = (0.0, 100.0)
MAX_TIME_S = 600.0
#: an angle curve's first time may be after 0 (the switch-on) by at most its first sampling
#: interval times this (the slack covers the rounding of logged times)
FIRST_TIME_SLACK = 1.0 + 1e-6

#: smallest strain span of a strain-temperature curve (0.1 % strain: a transformation shows
#: as several percent; the sma-thermal-cycling curves span 4.1-4.6 %)
MIN_STRAIN_SPAN = 1e-3
#: the middle of the strain span, +- this fraction of it: the band where the transformation
#: temperatures of the two halves are compared
MID_BAND = 0.25

#: fewest rows accepted
MIN_ROWS_KINETICS = 20
MIN_ROWS_HALF = 5
MIN_ROWS_JOINT = 10


class DataError(ValueError):
    """Bench data is unusable; the message is one line naming the file, the row and the problem."""


def _where(path, row: int | None = None, line: int | None = None) -> str:
    if row is None:
        return f"{path}" if line is None else f"{path}: line {line}"
    return f"{path}: row {row} (line {line})"


def _read_lines(path: Path) -> list[str]:
    try:
        return path.read_text(encoding="utf-8", errors="replace").splitlines()
    except FileNotFoundError:
        raise DataError(f"{path}: file not found") from None
    except IsADirectoryError:
        raise DataError(f"{path}: is a directory, not a data file") from None
    except OSError as exc:
        raise DataError(f"{path}: cannot read ({exc.strerror or exc})") from None


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _number(path, row, line, column: str, text: str) -> float:
    text = text.strip()
    if text == "":
        raise DataError(f"{_where(path, row, line)}: {column} is missing (empty field)")
    try:
        v = float(text)
    except ValueError:
        raise DataError(f"{_where(path, row, line)}: {column} {text!r} is not a number") from None
    if math.isnan(v):
        raise DataError(f"{_where(path, row, line)}: {column} is NaN")
    if math.isinf(v):
        raise DataError(f"{_where(path, row, line)}: {column} is infinite")
    return v


def _check_range(path, row, line, column: str, v: float, rng: tuple[float, float], unit: str,
                 hint: str = "") -> None:
    lo, hi = rng
    if not lo <= v <= hi:
        raise DataError(f"{_where(path, row, line)}: {column} {v:g}{unit} is outside the sensible "
                        f"range [{lo:g}, {hi:g}]{unit}{hint}")


# ---------------------------------------------------------------------------------------
# strain-temperature curves
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class StrainCurve:
    """One constant-load thermal cycle: heating half ``[0, split]``, cooling half ``[split, n)``."""

    path: str
    T_C: np.ndarray
    strain: np.ndarray  #: the file's values shifted to a minimum of 0 (the sensor's zero; the fit adds an offset)
    stress_Pa: np.ndarray
    split: int  # row index of the maximum temperature (last row of the heating half)

    def __post_init__(self) -> None:
        """Checked as :func:`_samples` says, and a split inside the samples."""
        n = _samples(self, "T_C", "strain", "stress_Pa")
        if not (is_whole(self.split) and 0 <= self.split < n):
            raise DataError(f"{self.path}: split = {self.split!r} is not a row of the curve (0 to {n - 1})")

    @property
    def name(self) -> str:
        return Path(self.path).name

    @property
    def n(self) -> int:
        return len(self.T_C)

    @property
    def stress_MPa_mean(self) -> float:
        return float(np.mean(self.stress_Pa) / 1e6)


KINETICS_COLUMNS = ("temperature", "strain", "stress")


def same_data(named) -> str | None:
    """Why two of ``named``, (label, arrays) pairs, are one data set under two names, or None:
    every array of one equal to the other's (shape and every value). A copy fitted twice weighs
    double, and a copy of a fitted file given to validate is not held out."""
    import hashlib

    seen: dict[str, str] = {}
    for label, arrays in named:
        digest = hashlib.sha256()
        for a in arrays:
            a = np.ascontiguousarray(a, dtype=np.float64)
            digest.update(repr(a.shape).encode() + a.tobytes())
        key = digest.hexdigest()
        if key in seen:
            return (f"{label}: the same data as {seen[key]} (every sample equal); give each data set once, "
                    "with one role")
        seen[key] = label
    return None


def load_strain_curve(path: str | Path) -> StrainCurve:
    """Read and validate a strain-temperature file (see the module docstring)."""
    path = Path(path)
    rows: list[tuple[int, list[str]]] = []  # (line number, fields)
    for ln, text in enumerate(_read_lines(path), start=1):
        s = text.strip()
        if not s or s.startswith("#"):
            continue
        rows.append((ln, s.split()))
    # tolerate one all-text header line
    if rows and not any(_is_number(f) for f in rows[0][1]):
        rows = rows[1:]
    if not rows:
        raise DataError(f"{path}: no data rows (expected columns: temperature [degC], strain [-], stress [MPa])")
    T = np.empty(len(rows))
    e = np.empty(len(rows))
    s = np.empty(len(rows))
    for i, (ln, fields) in enumerate(rows):
        row = i + 1
        if len(fields) < 3:
            missing = ", ".join(KINETICS_COLUMNS[len(fields):])
            raise DataError(f"{_where(path, row, ln)}: {len(fields)} column(s), missing {missing} "
                            f"(expected 3: temperature [degC], strain [-], stress [MPa])")
        if len(fields) > 3:
            raise DataError(f"{_where(path, row, ln)}: {len(fields)} columns, expected 3 "
                            f"(temperature [degC], strain [-], stress [MPa])")
        T[i] = _number(path, row, ln, "temperature", fields[0])
        e[i] = _number(path, row, ln, "strain", fields[1])
        s[i] = _number(path, row, ln, "stress", fields[2])
        _check_range(path, row, ln, "temperature", T[i], TEMPERATURE_RANGE_C, " degC")
        _check_range(path, row, ln, "strain", e[i], STRAIN_RANGE, "",
                     " (give strain as a fraction, not in percent)" if e[i] > STRAIN_RANGE[1] else "")
        _check_range(path, row, ln, "stress", s[i], STRESS_RANGE_MPA, " MPa",
                     " (give stress in MPa)" if s[i] > STRESS_RANGE_MPA[1] else "")
    n = len(rows)
    if n < MIN_ROWS_KINETICS:
        raise DataError(f"{_where(path, n, rows[-1][0])}: too few points: the file ends after {n} "
                        f"data rows, at least {MIN_ROWS_KINETICS} are needed")
    split = int(np.argmax(T))
    if split + 1 < MIN_ROWS_HALF or n - split < MIN_ROWS_HALF:
        half = "heating" if split + 1 < MIN_ROWS_HALF else "cooling"
        raise DataError(
            f"{_where(path, split + 1, rows[split][0])}: the maximum temperature ({T[split]:g} degC) "
            f"leaves too few points for the {half} half (rows must heat first, then cool; at "
            f"least {MIN_ROWS_HALF} rows each)")
    _check_transformation(path, T, e, split)
    # the strain from the curve's minimum: its zero is the sensor's, arbitrary. The shift is for
    # reading only (every curve from 0); the fit takes each curve's austenite level as a fitted
    # offset (kinetics_fit: "Offset"), since with noise the minimum lies below that level
    return StrainCurve(str(path), T, e - float(np.min(e)), s * 1e6, split)


def _check_transformation(path, T: np.ndarray, e: np.ndarray, split: int) -> None:
    """Refuse a curve without a transformation, or one whose halves are swapped.

    A wire transforms at higher temperatures on heating (to austenite, A_S..A_F) than on
    cooling (to martensite, M_S..M_F): in the middle of the strain span the heating half is
    hotter. Rows given in reverse time order show the opposite.
    """
    span = float(e.max() - e.min())
    if span < MIN_STRAIN_SPAN:
        raise DataError(f"{path}: the strain hardly changes (span {span:.3g}; at least {MIN_STRAIN_SPAN:g} "
                        "needed): no phase transformation to fit")
    mid = 0.5 * float(e.max() + e.min())
    band = np.abs(e - mid) <= MID_BAND * span
    heat, cool = band[:split + 1], band[split:]
    if not (heat.any() and cool.any()):
        return
    t_heat, t_cool = float(T[:split + 1][heat].mean()), float(T[split:][cool].mean())
    if t_heat < t_cool:
        raise DataError(f"{path}: the rows look reversed in time: mid-way through its strain change the heating "
                        f"half (rows 1-{split + 1}, up to the maximum temperature) is at {t_heat:.1f} degC, "
                        f"below the cooling half's {t_cool:.1f} degC, but a wire transforms at higher "
                        "temperatures on heating (rows must heat first, then cool)")


def _samples(curve, *names: str) -> int:
    """The number of samples of a curve built in Python, whose fields ``names`` must be 1-D
    finite arrays of one length with samples (an IndexError or numpy's errors came from inside
    the fits: found by an API fuzz); :class:`DataError` naming the field otherwise. The file
    readers say more, with the row."""
    arrays = {name: np.asarray(getattr(curve, name)) for name in names}
    shapes = [a.shape for a in arrays.values()]
    if len(set(shapes)) != 1 or len(shapes[0]) != 1 or shapes[0][0] == 0:
        raise DataError(f"{curve.path}: {', '.join(names)} must be 1-D arrays of one length, with samples "
                        f"(shapes {', '.join(map(str, shapes))})")
    for name, a in arrays.items():
        if not np.all(np.isfinite(a)):
            k = int(np.flatnonzero(~np.isfinite(a))[0])
            raise DataError(f"{curve.path}: {name} has a non-finite sample at row {k} ({float(a[k])!r})")
    return shapes[0][0]


# ---------------------------------------------------------------------------------------
# angle-vs-time curves
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class AngleCurve:
    """A measured joint angle against time (t = 0: the upper wire is switched on)."""

    path: str
    t_s: np.ndarray
    angle_deg: np.ndarray
    voltage_V: np.ndarray | None = None

    def __post_init__(self) -> None:
        """Checked as :func:`_samples` says (a NaN angle made every residual the fit's failure
        value, and the fit reported success)."""
        _samples(self, "t_s", "angle_deg")

    @property
    def name(self) -> str:
        return Path(self.path).name


_ALIASES = {
    "time": ("time", "t"),
    "angle": ("angle", "theta", "phi"),
    "voltage": ("voltage", "v", "v_upper", "voltage_upper", "u", "volt", "volts"),
}
_UNIT_SUFFIX = re.compile(r"(\[.*\]|\(.*\)|_(s|sec|deg|degrees|v|volt|volts|rad)$)")
#: the units each column is read in, as a header may write them (lower case)
UNITS = {"time": ("s", "sec", "secs", "second", "seconds"),
         "angle": ("deg", "degree", "degrees", "°"),
         "voltage": ("v", "volt", "volts")}


def _canonical(name: str) -> str | None:
    key = name.strip().lower()
    key = _UNIT_SUFFIX.sub("", key).strip().strip("_").strip()
    key = key.replace(" ", "_")
    for canon, names in _ALIASES.items():
        if key in names:
            return canon
    return None


def _unit(name: str) -> str | None:
    """The unit a header name gives (in brackets, parentheses or after the last ``_``), lower
    case; None if it gives none."""
    m = _UNIT_SUFFIX.search(name.strip().lower())
    if m is None:
        return None
    return (m.group(2) or m.group(1)[1:-1]).strip()


def load_angle_curve(path: str | Path) -> AngleCurve:
    """Read and validate an angle-vs-time CSV (see the module docstring)."""
    path = Path(path)
    lines = _read_lines(path)
    numbered = [(ln, t) for ln, t in enumerate(lines, start=1) if t.strip() and not t.lstrip().startswith("#")]
    if not numbered:
        raise DataError(f"{path}: empty file (expected a CSV header with columns time [s], angle [deg])")
    head_ln, head_text = numbered[0]
    header = next(csv.reader([head_text]))
    found = ", ".join(repr(h.strip()) for h in header)
    if all(_is_number(h) for h in header):
        raise DataError(f"{_where(path, line=head_ln)}: no time column [s] in the header (found: {found}) "
                        f"(the first line must be a header)")
    names = "; ".join(f"{c}: {', '.join(n)}" for c, n in _ALIASES.items())
    cols: dict[str, int] = {}
    for j, name in enumerate(header):
        if not name.strip():
            continue  # a column without a name (a trailing comma) must hold no values: checked by row
        c = _canonical(name)
        # an unknown column is refused, not skipped: a voltage under another name would be
        # dropped and the curve fitted at the default voltage
        if c is None:
            raise DataError(f"{_where(path, line=head_ln)}: column {name.strip()!r} is not one a curve may have "
                            f"({names}; a unit in brackets or after '_')")
        if c in cols:
            raise DataError(f"{_where(path, line=head_ln)}: column {name.strip()!r} is a second {c} column "
                            f"(after {header[cols[c]].strip()!r})")
        unit = _unit(name)
        if unit is not None and unit not in UNITS[c]:
            raise DataError(f"{_where(path, line=head_ln)}: column {name.strip()!r} is in {unit!r}, but the {c} is "
                            f"read in {UNITS[c][0]}: convert the column to {UNITS[c][0]} and name it so")
        cols[c] = j
    for need, unit in (("time", "s"), ("angle", "deg")):
        if need not in cols:
            raise DataError(f"{_where(path, line=head_ln)}: no {need} column [{unit}] in the header "
                            f"(found: {found})")
    data = numbered[1:]
    n = len(data)
    t = np.empty(n)
    a = np.empty(n)
    has_v = "voltage" in cols
    v = np.empty(n) if has_v else None
    for i, (ln, text) in enumerate(data):
        row = i + 1
        fields = next(csv.reader([text]))
        unnamed = [j + 1 for j, f in enumerate(fields) if f.strip() and (j >= len(header) or not header[j].strip())]
        if unnamed:
            raise DataError(f"{_where(path, row, ln)}: a value in column {unnamed[0]}, which the header does not name "
                            f"(header: {found})")
        for c, arr, unit, rng in (("time", t, "s", None), ("angle", a, " deg", ANGLE_RANGE_DEG),
                                  ("voltage", v, " V", VOLTAGE_RANGE_V)):
            if arr is None:
                continue
            j = cols[c]
            if j >= len(fields):
                raise DataError(f"{_where(path, row, ln)}: {c} column missing ({len(fields)} field(s), "
                                f"header has {len(header)})")
            arr[i] = _number(path, row, ln, c, fields[j])
            if rng is not None:
                _check_range(path, row, ln, c, arr[i], rng, unit)
        if t[i] < 0:
            raise DataError(f"{_where(path, row, ln)}: time {t[i]:g} s is negative "
                            f"(t = 0 is when the wire is switched on)")
        if t[i] > MAX_TIME_S:
            raise DataError(f"{_where(path, row, ln)}: time {t[i]:g} s is beyond {MAX_TIME_S:g} s "
                            f"(give the time in seconds)")
        if i > 0 and not t[i] > t[i - 1]:
            raise DataError(f"{_where(path, row, ln)}: time {t[i]:g} s is not after the previous "
                            f"row's {t[i - 1]:g} s (time must increase)")
    if n < MIN_ROWS_JOINT:
        where = _where(path, n, data[-1][0]) if n else _where(path, line=head_ln)
        raise DataError(f"{where}: too few points: {n} data rows, at least {MIN_ROWS_JOINT} are needed")
    _check_first_time(path, t, data[0][0])
    return AngleCurve(str(path), t, a, v)


def _check_first_time(path, t: np.ndarray, line: int) -> None:
    """Refuse a curve whose time does not count from the switch-on: its first row more than one
    sampling interval (the first one, ``t[1] - t[0]``) after 0 (see the module docstring).

    Parameters
    ----------
    path : path
        The file, for the message.
    t : ndarray
        The curve's times [s], increasing, at least two.
    line : int
        The file's line number of the first data row.
    """
    dt = float(t[1] - t[0])
    if t[0] > FIRST_TIME_SLACK * dt:
        raise DataError(f"{_where(path, 1, line)}: time {t[0]:g} s of the first row is after 0 by more than the "
                        f"first sampling interval ({dt:g} s): t = 0 is when the wire is switched on, so give "
                        f"the time from then (subtract the switch-on time)")


# ---------------------------------------------------------------------------------------
# fitted parameter files
# ---------------------------------------------------------------------------------------
def parameter_file_text(values: dict[str, float], base: "str | ParameterSet", name: str, source: str) -> str:
    """A parameter file (TOML) with fitted values, loadable by ``smafinger simulate --params``.

    ``base`` a registry name: ``base = "NAME"`` plus the fitted fields. ``base`` a set (loaded
    from a file, or with overrides): the complete set with the fitted fields replaced. Either
    way the values are validated (ranges, cross-checks) first: ParameterError if invalid.
    """
    from ..parameters import ParameterSet, get
    from ..parameters.files import overrides_toml

    if isinstance(base, ParameterSet):
        return base.replace(name=name, source=source, **values).to_toml()
    get(base).replace(**values)  # validate
    return overrides_toml(base, {"name": name, "source": source, **values},
                          "smafinger parameter file written by `smafinger identify` (SI units)")
