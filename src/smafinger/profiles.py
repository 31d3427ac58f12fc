"""Target profiles (closed loop) and voltage programs (open loop).

A target profile is a piecewise schedule of segments ``(start, target angle, enable)``;
``enable`` is one of auto, upper, lower, both, none. A segment's start may be ``None``
("reach"): it then begins as soon as the previous target is reached (within the tolerance,
for the hold time). Text form, as on the CLI: ``"0:-25,10:-40:none,reach:-55:both"``.

A voltage program is a piecewise-constant voltage per wire: ``"0:8:0,6:0:0"``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .control.strategies import ENABLES


class ProfileError(ValueError):
    """A profile or voltage program is malformed."""


@dataclass(frozen=True)
class Segment:
    start_s: float | None
    target_deg: float
    enable: str = "auto"


@dataclass(frozen=True)
class TargetProfile:
    segments: tuple[Segment, ...]

    def __post_init__(self) -> None:
        if not self.segments:
            raise ProfileError("profile: at least one segment is needed")
        if self.segments[0].start_s != 0.0:
            raise ProfileError(f"profile: the first segment must start at 0 s, not {self.segments[0].start_s}")
        last = -math.inf
        for i, s in enumerate(self.segments):
            if s.enable not in ENABLES:
                raise ProfileError(f"profile segment {i}: enable {s.enable!r} is not one of {', '.join(ENABLES)}")
            if not math.isfinite(s.target_deg) or not -89.0 <= s.target_deg <= 89.0:
                raise ProfileError(f"profile segment {i}: target {s.target_deg} deg is outside [-89, 89]")
            if s.start_s is not None:
                if not math.isfinite(s.start_s) or s.start_s < 0 or s.start_s <= last:
                    raise ProfileError(f"profile segment {i}: start {s.start_s} s must be finite and after the previous one ({last} s)")
                last = s.start_s

    @classmethod
    def parse(cls, text: str) -> "TargetProfile":
        segs = []
        for i, item in enumerate(p for p in text.split(",") if p.strip()):
            parts = [x.strip() for x in item.split(":")]
            if len(parts) not in (2, 3):
                raise ProfileError(f"profile item {i} {item!r}: expected T:ANGLE[:ENABLE]")
            t = None if parts[0].lower() in ("reach", "r") else _float(parts[0], f"profile item {i} time")
            segs.append(Segment(t, _float(parts[1], f"profile item {i} angle"), parts[2].lower() if len(parts) == 3 else "auto"))
        return cls(tuple(segs))

    @classmethod
    def constant(cls, target_deg: float, enable: str = "auto") -> "TargetProfile":
        return cls((Segment(0.0, target_deg, enable),))

    def to_text(self) -> str:
        return ",".join(f"{'reach' if s.start_s is None else repr(s.start_s)}:{s.target_deg!r}:{s.enable}" for s in self.segments)


@dataclass(frozen=True)
class VoltageProgram:
    steps: tuple[tuple[float, float, float], ...]  # (start_s, V_upper, V_lower)

    def __post_init__(self) -> None:
        if not self.steps:
            raise ProfileError("voltage program: at least one step is needed")
        if self.steps[0][0] != 0.0:
            raise ProfileError(f"voltage program: the first step must start at 0 s, not {self.steps[0][0]}")
        # vectorised check of the whole program (a PWM program has thousands of steps);
        # the first bad step found in order gets the message
        a = np.asarray(self.steps, dtype=float).reshape(-1, 3)
        t, vu, vl = a[:, 0], a[:, 1], a[:, 2]
        bad_t = ~np.isfinite(t)
        bad_t[1:] |= ~(t[1:] > t[:-1])
        bad_v = ~(np.isfinite(vu) & (vu >= 0.0) & (vu <= 100.0) & np.isfinite(vl) & (vl >= 0.0) & (vl <= 100.0))
        both = (vu > 0) & (vl > 0)
        if not (bad_t.any() or bad_v.any() or both.any()):
            return
        i = int(np.flatnonzero(bad_t | bad_v | both)[0])
        if bad_t[i]:
            raise ProfileError(f"voltage program step {i}: start {t[i]} s must be after the previous one")
        for name, v in (("V_upper", vu[i]), ("V_lower", vl[i])):
            if not math.isfinite(v) or not 0.0 <= v <= 100.0:
                raise ProfileError(f"voltage program step {i}: {name} = {v} V is outside [0, 100]")
        raise ProfileError(
            f"voltage program step {i} (t = {t[i]} s): both wires heated at once "
            f"({vu[i]} V, {vl[i]} V) would break the interlock"
        )

    @classmethod
    def parse(cls, text: str) -> "VoltageProgram":
        items = [p for p in text.split(",") if p.strip()]
        try:  # fast path: every item is T:V_UPPER:V_LOWER with plain numbers
            flat = np.array(":".join(items).split(":"), dtype=float)
            if (flat.size == 3 * len(items) and np.isfinite(flat).all()
                    and all(item.count(":") == 2 for item in items)):
                return cls(tuple(map(tuple, flat.reshape(-1, 3).tolist())))
        except ValueError:
            pass
        steps = []
        for i, item in enumerate(items):
            parts = item.split(":")
            if len(parts) != 3:
                raise ProfileError(f"voltage item {i} {item!r}: expected T:V_UPPER:V_LOWER")
            steps.append(tuple(_float(x, f"voltage item {i}") for x in parts))
        return cls(tuple(steps))

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(start_s, V_upper, V_lower) as float arrays."""
        a = np.asarray(self.steps, dtype=float).reshape(-1, 3)
        return a[:, 0].copy(), a[:, 1].copy(), a[:, 2].copy()


def _float(text: str, what: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise ProfileError(f"{what}: {text!r} is not a number") from None
    if not math.isfinite(v):
        raise ProfileError(f"{what}: {text!r} is not finite")
    return v
