"""Which column or variable of a file is which canonical signal, and in what scale.

Text form (one ``--map`` option each)::

    NAME=SOURCE            the column/variable SOURCE is the signal NAME, in NAME's units
    NAME=SOURCE*FACTOR     ... and its values times FACTOR are in NAME's units
    NAME=SOURCE/DIVISOR    ... and its values divided by DIVISOR are

``NAME`` is one of ``t_s``, ``duty``, ``voltage_V``, ``current_A``, ``position_m``,
``theta_deg``, ``T_C``, ``resistance_ohm``. The factor is the text after the last ``*`` or
``/`` and must be a finite non-zero number (negative flips a sign convention). Examples:
``position_m=x_mm*1e-3``, ``duty=u_pct/100``, ``t_s=time_ms*0.001``, ``theta_deg=angle*-1``.

In Python a mapping is a dict ``{NAME: SOURCE}``, where SOURCE is the same text form
(``"x_mm*1e-3"``) or a pair ``("x_mm", 1e-3)``; the pair takes the name literally, for a
column whose name itself contains ``*`` or ``/``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from ..values import is_real
from .signals import MAPPABLE, RecordingError


class MappingError(RecordingError):
    """A mapping is malformed (unknown signal, empty source, bad scale, duplicate)."""


@dataclass(frozen=True)
class Source:
    """Where a canonical signal comes from: a column or variable and the scale to its units."""

    name: str
    scale: float = 1.0

    def to_text(self) -> str:
        return self.name if self.scale == 1.0 else f"{self.name}*{self.scale!r}"


@dataclass(frozen=True)
class SignalMap:
    """A validated mapping, canonical signal name -> :class:`Source`.

    Build it with :meth:`from_dict` or :func:`parse_map_options`; ``SignalMap()`` is the empty
    mapping (every signal looked up by its canonical name, scale 1).
    """

    entries: tuple[tuple[str, Source], ...] = ()

    def __post_init__(self) -> None:
        seen = set()
        for name, src in self.entries:
            if name not in MAPPABLE:
                raise MappingError(f"mapping: {name!r} is not a signal name; use one of {', '.join(MAPPABLE)}")
            if name in seen:
                raise MappingError(f"mapping: {name!r} is mapped twice")
            seen.add(name)
            if not isinstance(src.name, str) or not src.name.strip():
                raise MappingError(f"mapping {name}: the source column/variable name is empty")
            if not (isinstance(src.scale, (int, float)) and math.isfinite(src.scale) and src.scale != 0):
                raise MappingError(f"mapping {name}: scale {src.scale!r} must be a finite non-zero number")

    def __contains__(self, name: str) -> bool:
        return any(n == name for n, _ in self.entries)

    def get(self, name: str) -> Source | None:
        """The mapped source of ``name``, or ``None`` if the mapping does not name it."""
        return next((s for n, s in self.entries if n == name), None)

    def source(self, name: str) -> Source:
        """The mapped source of ``name``, or the canonical name itself with scale 1."""
        return self.get(name) or Source(name)

    def to_options(self) -> list[str]:
        """The text form, one ``NAME=SOURCE[*FACTOR]`` per entry (parses back to ``self``)."""
        return [f"{n}={s.to_text()}" for n, s in self.entries]

    @classmethod
    def from_dict(cls, mapping: Mapping[str, str | tuple[str, float]]) -> "SignalMap":
        """From ``{NAME: "SOURCE[*FACTOR]"}`` or ``{NAME: ("SOURCE", FACTOR)}``."""
        if not isinstance(mapping, Mapping):
            raise MappingError(f"mapping must be a dict of signal name -> source, not {type(mapping).__name__}")
        entries = []
        for name, value in mapping.items():
            if isinstance(value, tuple) and len(value) == 2:
                src, scale = value
                if not is_real(scale):  # numpy's numbers too (np.float32 was refused)
                    raise MappingError(f"mapping {name}: scale {scale!r} is not a number")
                entries.append((name, Source(src, float(scale))))
            elif isinstance(value, str):
                entries.append((name, parse_source(value, f"mapping {name}")))
            else:
                raise MappingError(f"mapping {name}: {value!r} is neither 'SOURCE[*FACTOR]' nor (SOURCE, FACTOR)")
        return cls(tuple(entries))


def parse_source(text: str, what: str) -> Source:
    """``"x_mm*1e-3"`` -> ``Source("x_mm", 1e-3)``; ``"u/100"`` -> ``Source("u", 0.01)``."""
    text = text.strip()
    cut = max(text.rfind("*"), text.rfind("/"))
    if cut < 0:
        return Source(text)
    name, op, num = text[:cut].strip(), text[cut], text[cut + 1:].strip()
    try:
        factor = float(num)
    except ValueError:
        raise MappingError(f"{what}: {num!r} after {op!r} in {text!r} is not a number") from None
    if not math.isfinite(factor) or factor == 0:
        raise MappingError(f"{what}: factor {num!r} in {text!r} must be a finite non-zero number")
    return Source(name, factor if op == "*" else 1.0 / factor)


def parse_map_options(options: Iterable[str]) -> SignalMap:
    """Parse repeated CLI options ``--map NAME=SOURCE[*FACTOR|/DIVISOR]`` into a :class:`SignalMap`.

    Parameters
    ----------
    options : iterable of str
        E.g. ``["position_m=x_mm*1e-3", "duty=u_pwm"]``.

    Raises
    ------
    MappingError
        One line quoting the faulty option (no ``=``, unknown name, empty source, bad factor,
        a name given twice).
    """
    entries = []
    for opt in options:
        name, eq, rhs = opt.partition("=")
        if not eq:
            raise MappingError(f"--map {opt!r}: expected NAME=SOURCE[*FACTOR], e.g. position_m=x_mm*1e-3")
        name = name.strip()
        if name not in MAPPABLE:
            raise MappingError(f"--map {opt!r}: {name!r} is not a signal name; use one of {', '.join(MAPPABLE)}")
        if name in (n for n, _ in entries):
            raise MappingError(f"--map {opt!r}: {name} is mapped twice")
        entries.append((name, parse_source(rhs, f"--map {opt!r}")))
    return SignalMap(tuple(entries))


def as_signal_map(mapping) -> SignalMap:
    """``None``, a dict or a :class:`SignalMap` -> :class:`SignalMap`."""
    if mapping is None:
        return SignalMap()
    if isinstance(mapping, SignalMap):
        return mapping
    return SignalMap.from_dict(mapping)
