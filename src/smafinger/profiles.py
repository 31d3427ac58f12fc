"""Target profiles (closed loop) and drive programs (open loop).

A target profile is a piecewise schedule of segments ``(start, target, enable)``. The target is
in the mechanism's user unit (degrees for the joint, metres for the linear actuator); ``enable``
is auto, none, both (all), or a wire's name (upper, lower; wire). A segment's start may be
``None`` ("reach"): it then begins as soon as the previous target is reached (within the
tolerance, for the hold time). Text form, as on the CLI: ``"0:-25,10:-40:none,reach:-55:both"``.
Targets and enable words are checked against the mechanism when the run is built.

A drive program is a piecewise-constant drive per wire: voltages ``"0:8:0,6:0:0"`` (one column
per wire: upper, lower), duties as fractions of the supply V_H (``kind="duty"``, for example
``"0:0.2,5:0"``), or currents in amperes (``kind="current"``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .values import is_real



class ProfileError(ValueError):
    """A profile or voltage program is malformed."""


@dataclass(frozen=True)
class Segment:
    start_s: float | None
    target: float  #: in the mechanism's user unit (deg for the joint, m for the linear actuator)
    enable: str = "auto"

    def __post_init__(self) -> None:
        """Numbers kept as floats (a numpy scalar would reach the summary's JSON), the enable
        word as text: :class:`ProfileError` naming the field otherwise."""
        if self.start_s is not None:
            object.__setattr__(self, "start_s", _real(self.start_s, "profile segment start_s"))
        object.__setattr__(self, "target", _real(self.target, "profile segment target"))
        if not isinstance(self.enable, str):
            raise ProfileError(f"profile segment enable: {self.enable!r} is not a word (auto, none, both, all or a "
                               "wire's name)")

    @property
    def target_deg(self) -> float:
        """The joint's target angle (the target, read as degrees)."""
        return self.target


@dataclass(frozen=True)
class TargetProfile:
    """A closed-loop target schedule: segments, each a target from its start time on.

    :meth:`parse` reads the command line's text, ``"T:TARGET[:ENABLE],..."``: T in seconds (the
    first 0), or ``reach`` to start once the previous target is reached (within the run's
    tolerance for its hold time); TARGET in the mechanism's user unit (degrees for the joint,
    metres for the linear rig); ENABLE which actuators the strategy may use (``auto``, ``upper``,
    ``lower``, ``both`` or ``all``, ``none``; ``wire`` on the linear rig). Validated on construction
    (:class:`ProfileError` naming the segment).
    """

    segments: tuple[Segment, ...]

    def __post_init__(self) -> None:
        if isinstance(self.segments, (str, bytes)) or not isinstance(self.segments, (tuple, list)):
            raise ProfileError(f"profile: segments must be a tuple of Segment, not {type(self.segments).__name__} "
                               "(TargetProfile.parse reads the text form)")
        object.__setattr__(self, "segments", tuple(self.segments))
        for i, s in enumerate(self.segments):
            if not isinstance(s, Segment):
                raise ProfileError(f"profile segment {i}: {s!r} is not a Segment(start_s, target, enable)")
        if not self.segments:
            raise ProfileError("profile: at least one segment is needed")
        if self.segments[0].start_s != 0.0:
            raise ProfileError(f"profile: the first segment must start at 0 s, not {self.segments[0].start_s}")
        last = -math.inf
        for i, s in enumerate(self.segments):
            if not s.enable.replace("-", "").isalnum():
                raise ProfileError(f"profile segment {i}: enable {s.enable!r} is not a word")
            if not math.isfinite(s.target):
                raise ProfileError(f"profile segment {i}: target {s.target} is not finite")
            if s.start_s is not None:
                if not math.isfinite(s.start_s) or s.start_s < 0 or s.start_s <= last:
                    raise ProfileError(f"profile segment {i}: start {s.start_s} s must be finite and after the previous one ({last} s)")
                last = s.start_s

    @classmethod
    def parse(cls, text: str) -> "TargetProfile":
        _text(text, "profile", "0:-25,reach:-55")
        segs = []
        for i, item in enumerate(p for p in text.split(",") if p.strip()):
            parts = [x.strip() for x in item.split(":")]
            if len(parts) not in (2, 3):
                raise ProfileError(f"profile item {i} {item!r}: expected T:ANGLE[:ENABLE]")
            t = None if parts[0].lower() in ("reach", "r") else _float(parts[0], f"profile item {i} time")
            segs.append(Segment(t, _float(parts[1], f"profile item {i} angle"), parts[2].lower() if len(parts) == 3 else "auto"))
        return cls(tuple(segs))

    @classmethod
    def constant(cls, target: float, enable: str = "auto") -> "TargetProfile":
        return cls((Segment(0.0, target, enable),))

    def to_text(self) -> str:
        return ",".join(f"{'reach' if s.start_s is None else repr(s.start_s)}:{s.target!r}:{s.enable}" for s in self.segments)


#: drive program kinds: (unit, largest value)
DRIVE_KINDS = {"voltage": ("V", 100.0), "duty": ("fraction of V_H", 1.0), "current": ("A", 20.0)}


@dataclass(frozen=True)
class VoltageProgram:
    """A piecewise-constant drive per wire: steps ``(start_s, value_1, ..., value_n)``.

    ``kind``: ``voltage`` [V] (the default), ``duty`` (a fraction of the supply V_H, switched at
    the PWM period) or ``current`` [A]. Each step has one value per wire of the mechanism.
    """

    steps: tuple[tuple[float, ...], ...]
    kind: str = "voltage"

    def __post_init__(self) -> None:
        if self.kind not in DRIVE_KINDS:
            raise ProfileError(f"drive program kind {self.kind!r} is not one of {', '.join(DRIVE_KINDS)}")
        rows = "every step needs a time and the same number of values (one per wire)"
        try:
            raw = np.asarray(self.steps)
        except ValueError:  # rows of different lengths
            raise ProfileError(f"drive program: {rows}") from None
        if raw.size == 0:
            raise ProfileError("drive program: at least one step is needed")
        if raw.ndim != 2 or raw.shape[1] < 2:
            raise ProfileError(f"drive program: {rows}; steps must be rows (start_s, value_1, ...), not "
                               f"{_short(self.steps)}")
        if raw.dtype.kind not in "iuf":
            raise ProfileError(f"drive program: steps must hold numbers, not {_short(self.steps)} "
                               "(VoltageProgram.parse reads the text form)")
        a = raw.astype(float)
        object.__setattr__(self, "steps", tuple(map(tuple, a.tolist())))  # floats, as parse makes them
        if a[0, 0] != 0.0:
            raise ProfileError(f"drive program: the first step must start at 0 s, not {float(a[0, 0])!r}")
        # vectorised check of the whole program (a PWM program has thousands of steps);
        # the first bad step found in order gets the message
        t, v = a[:, 0], a[:, 1:]
        unit, top = DRIVE_KINDS[self.kind]
        bad_t = ~np.isfinite(t)
        bad_t[1:] |= ~(t[1:] > t[:-1])
        bad_v = ~(np.isfinite(v) & (v >= 0.0) & (v <= top)).all(axis=1)
        if not (bad_t.any() or bad_v.any()):
            return
        i = int(np.flatnonzero(bad_t | bad_v)[0])
        if bad_t[i]:
            raise ProfileError(f"drive program step {i}: start {t[i]} s must be finite and after the previous one")
        k = int(np.flatnonzero(~(np.isfinite(v[i]) & (v[i] >= 0.0) & (v[i] <= top)))[0])
        raise ProfileError(f"drive program step {i}: value {k + 1} = {v[i, k]} {unit} is outside [0, {top:g}]")

    @property
    def n_wires(self) -> int:
        return len(self.steps[0]) - 1

    @classmethod
    def parse(cls, text: str, kind: str = "voltage") -> "VoltageProgram":
        """``"T:V_1[:V_2...],..."``: a time and one value per wire."""
        _text(text, f"{kind} program", "0:8:0,6:0:0")
        items = [p for p in text.split(",") if p.strip()]
        if not items:
            raise ProfileError(f"{kind} program {text!r}: no steps")
        width = items[0].count(":") + 1
        try:  # fast path: every item is T:V...:V with plain numbers
            flat = np.array(":".join(items).split(":"), dtype=float)
            if (flat.size == width * len(items) and np.isfinite(flat).all()
                    and all(item.count(":") == width - 1 for item in items)):
                return cls(tuple(map(tuple, flat.reshape(-1, width).tolist())), kind)
        except ValueError:
            pass
        steps = []
        for i, item in enumerate(items):
            parts = item.split(":")
            if len(parts) != width or width < 2:
                raise ProfileError(f"{kind} item {i} {item!r}: expected T:VALUE[:VALUE...] with "
                                   f"{max(width - 1, 1)} value(s), as the first item")
            steps.append(tuple(_float(x, f"{kind} item {i}") for x in parts))
        return cls(tuple(steps), kind)

    def arrays(self) -> tuple[np.ndarray, ...]:
        """(start_s, values of wire 1, ..., values of wire n) as float arrays."""
        a = np.asarray(self.steps, dtype=float)
        return tuple(a[:, k].copy() for k in range(a.shape[1]))


#: the open-loop program of any drive kind
DriveProgram = VoltageProgram


def _float(text: str, what: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise ProfileError(f"{what}: {text!r} is not a number") from None
    if not math.isfinite(v):
        raise ProfileError(f"{what}: {text!r} is not finite")
    return v


def _real(value, what: str) -> float:
    """``value`` (a real number, not a bool) as a float; :class:`ProfileError` naming ``what``."""
    if not is_real(value):
        raise ProfileError(f"{what}: {value!r} is not a number")
    return float(value)


def _text(text, what: str, example: str) -> None:
    """:class:`ProfileError` unless ``text`` is a str (the text form, like ``example``)."""
    if not isinstance(text, str):
        raise ProfileError(f"{what}: {_short(text)} is not text (the form {example!r})")


def _short(value) -> str:
    """repr of ``value``, cut to 60 characters (a program can have thousands of steps)."""
    r = repr(value)
    return r if len(r) <= 60 else r[:57] + "..."
