"""Controllers at the API edge: validated parameter objects, each building its compiled record.

A controller is chosen by label (:data:`CONTROLLERS`) and set by name, like a parameter set:
``controller_from("sliding-mode", ["phi_q_per_s=0.05"])``. Every value is checked on
construction (:class:`~smafinger.parameters.ParameterError` naming the field, the value and its
range). ``q`` in a field name is the mechanism's coordinate in SI (rad for the joint, m for a
slider): ``K_P_per_q`` is DC% per rad of error on the joint. A field left ``None`` takes a
value derived from the parameter set (each field's doc says how), so one controller object
fits both mechanisms. :meth:`ControllerParameters.record` builds the compiled record
(:mod:`.interface`) for a set.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from ..model.records import Controller
from ..parameters.base import ParameterSet, checked_real
from ..values import one_or_many
from ..parameters.errors import ParameterError
from .calibration import ResistanceCalibration, calibrate
from .chain import NO_SHAPING, ControlChain, Estimator, Law, PIDGains
from .fuzzy import FuzzyPID
from .rapid import RapidHeating
from .selfsensing import ResistanceMap
from .sensing import Sensors
from .sliding import SlidingMode

#: placeholders for the parts of a chain its law or estimator does not use
UNUSED_FUZZY = FuzzyPID(0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
UNUSED_SLIDING = SlidingMode(0.0, 0.0, 1.0, 0.0)


def unused_map(n_wires: int) -> ResistanceMap:
    return ResistanceMap((1.0,) * n_wires, 0.0, (0.0,) * n_wires, (0.0,) * n_wires, (0.0,) * n_wires, 0.0)


def chain(p: ParameterSet, sensors: Sensors, law: Law, *, pid: PIDGains = PIDGains(0.0, 0.0, 0.0),
          fuzzy: FuzzyPID = UNUSED_FUZZY, sliding: SlidingMode = UNUSED_SLIDING,
          rmap: ResistanceMap | None = None, shaping: RapidHeating = NO_SHAPING) -> ControlChain:
    """A :class:`~.chain.ControlChain` for set ``p``: the estimator is the resistance map if given."""
    estimator = Estimator.SENSOR if rmap is None else Estimator.RESISTANCE
    rmap = unused_map(len(p.wire_names)) if rmap is None else rmap
    return ControlChain(sensors, estimator, rmap, law, pid, fuzzy, sliding, shaping)


def _num(lo: float, hi: float, doc: str, default: float | None = None) -> Any:
    """A float field in [lo, hi]; ``None`` (the default unless given) means derived from the set."""
    return field(default=default, metadata={"range": (lo, hi), "doc": doc})


@dataclass(frozen=True, kw_only=True)
class ControllerParameters:
    """Base: validation, copies with changes, and the record for a parameter set."""

    label: ClassVar[str] = ""
    #: what it is and where it comes from (one line)
    source: ClassVar[str] = ""
    sensors: ClassVar[Sensors] = Sensors(position=True, temperature=False)

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if "range" not in f.metadata:
                continue
            if v is None:
                if f.default is None:  # None: derived from the parameter set
                    continue
                # a field with a value of its own has no None (it failed mid-run: found by an API fuzz)
                raise ParameterError(f"{self.label}: {f.name} = None: give a number (default {f.default!r})")
            lo, hi = f.metadata["range"]  # checked as a set's fields are (np.float32 was refused)
            object.__setattr__(self, f.name, checked_real(f.name, v, lo, hi, prefix=f"{self.label}: "))

    @classmethod
    def field_names(cls) -> list[str]:
        return [f.name for f in fields(cls) if "range" in f.metadata]

    def replace(self, **changes: Any) -> "ControllerParameters":
        """A validated copy with some fields changed."""
        unknown = sorted(set(changes) - {f.name for f in fields(self)})
        if unknown:
            raise ParameterError(f"{self.label}: unknown controller parameter(s) {', '.join(unknown)} "
                                 f"(known: {', '.join(self.field_names())})")
        return dataclasses.replace(self, **changes)

    def with_overrides(self, assignments: list[str] | tuple[str, ...]) -> "ControllerParameters":
        """Apply ``NAME=VALUE`` strings (``--controller-set``)."""
        changes: dict[str, Any] = {}
        for a in one_or_many(assignments):
            if "=" not in a:
                raise ParameterError(f"controller override {a!r} is not of the form NAME=VALUE")
            key, raw = (s.strip() for s in a.split("=", 1))
            try:
                changes[key] = None if raw.lower() == "none" else float(raw)
            except ValueError:
                raise ParameterError(f"{self.label}: {key} = {raw!r} is not a number") from None
        return self.replace(**changes)

    def to_dict(self) -> dict[str, Any]:
        """The label and every numeric field (``None``: derived from the set)."""
        return {"controller": self.label, **{n: getattr(self, n) for n in self.field_names()}}

    def describe(self) -> str:
        """The label and the fields given explicitly, e.g. ``sliding-mode(phi_q_per_s=0.05)``."""
        given = [f"{n}={getattr(self, n):g}" for n in self.field_names() if getattr(self, n) is not None]
        return f"{self.label}({', '.join(given)})" if given else self.label

    def prepared(self, p: ParameterSet) -> "ControllerParameters":
        """This controller with whatever it needs from set ``p`` resolved once (a calibration)."""
        return self

    def record(self, p: ParameterSet, base: Controller):
        """The compiled record for set ``p`` (``base``: the set's own PID gains, SI)."""
        raise NotImplementedError

    # helpers ---------------------------------------------------------------------------
    def _or(self, name: str, default: float) -> float:
        v = getattr(self, name)
        return default if v is None else v

    def _gains(self, base: Controller) -> tuple[float, float, float]:
        return (self._or("K_P_per_q", base.K_P), self._or("K_V_s_per_q", base.K_V),
                self._or("K_I_per_q_s", base.K_I))


_KP = "proportional gain [% per q]; None: the set's K_P"
_KV = "derivative gain [% s per q]; None: the set's K_V"
_KI = "integral gain [% per q s]; None: the set's K_I"


@dataclass(frozen=True, kw_only=True)
class PaperPID(ControllerParameters):
    label: ClassVar[str] = "pid"
    source: ClassVar[str] = "the paper's PWM-PID, Eq. (12) and Sec. 2.6 (Gilardi et al. 2010)"

    K_P_per_q: float | None = _num(0.0, 1e9, _KP)
    K_V_s_per_q: float | None = _num(0.0, 1e9, _KV)
    K_I_per_q_s: float | None = _num(0.0, 1e9, _KI)

    def record(self, p: ParameterSet, base: Controller) -> Controller:
        return Controller(*self._gains(base))


@dataclass(frozen=True, kw_only=True)
class FuzzyPIDParameters(ControllerParameters):
    label: ClassVar[str] = "fuzzy-pid"
    source: ClassVar[str] = ("fuzzy PWM-PID (Ko et al., Mechatronics 2011) with the gain scheduler of Zhao, "
                             "Tomizuka and Isaka (IEEE TSMC 1993)")

    K_P_min_per_q: float | None = _num(0.0, 1e9, "smallest scheduled K_P; None: half the set's K_P")
    K_P_max_per_q: float | None = _num(0.0, 1e9, "largest scheduled K_P; None: twice the set's K_P")
    K_V_min_s_per_q: float | None = _num(0.0, 1e9, "smallest scheduled K_V; None: a quarter of the set's K_V")
    K_V_max_s_per_q: float | None = _num(1e-9, 1e9, "largest scheduled K_V; None: the set's K_V")
    e_span_q: float | None = _num(1e-9, 1e3, "error of the outer fuzzy sets [q]; None: 300 / K_P of the set")
    de_span_q_s: float | None = _num(1e-9, 1e4, "error rate of the outer sets [q/s]; None: 300 / K_V of the set")

    def record(self, p: ParameterSet, base: Controller) -> ControlChain:
        kp = base.K_P if base.K_P > 0.0 else 1.0
        kv = base.K_V if base.K_V > 0.0 else 1.0
        r = FuzzyPID(self._or("K_P_min_per_q", 0.5 * base.K_P), self._or("K_P_max_per_q", 2.0 * base.K_P),
                     self._or("K_V_min_s_per_q", 0.25 * base.K_V), self._or("K_V_max_s_per_q", base.K_V),
                     self._or("e_span_q", 300.0 / kp), self._or("de_span_q_s", 300.0 / kv))
        for lo, hi in (("K_P_min", "K_P_max"), ("K_V_min", "K_V_max")):
            if getattr(r, lo) > getattr(r, hi):
                raise ParameterError(f"{self.label}: {lo} = {getattr(r, lo):g} exceeds {hi} = {getattr(r, hi):g}")
        if r.K_V_max <= 0.0:
            raise ParameterError(f"{self.label}: K_V_max = {r.K_V_max:g} must be positive (K_I = K_P^2 / (alpha K_V))")
        return chain(p, self.sensors, Law.FUZZY_PID, fuzzy=r)


@dataclass(frozen=True, kw_only=True)
class SlidingModeParameters(ControllerParameters):
    label: ClassVar[str] = "sliding-mode"
    source: ClassVar[str] = ("sliding mode with a boundary layer (Slotine and Li 1991; for SMA: Grant and "
                             "Hayward 1997, Elahinia and Ashrafiuon 2002)")

    lambda_per_s: float | None = _num(0.0, 1e4, "surface weight of the error [1/s]; None: K_P / K_V of the set")
    lambda_I_per_s2: float | None = _num(0.0, 1e6, "surface weight of the error integral [1/s^2]; None: K_I / K_V")
    phi_q_per_s: float | None = _num(1e-9, 1e6, "boundary-layer half-width [q/s]; None: K_pct / K_V of the set")
    K_pct: float = _num(0.0, 100.0, "switching gain [%]", default=100.0)

    def record(self, p: ParameterSet, base: Controller) -> ControlChain:
        kv = base.K_V if base.K_V > 0.0 else 1.0
        # the defaults make the law inside its boundary layer the set's own PID (Eq. 12a)
        sm = SlidingMode(self._or("lambda_per_s", base.K_P / kv), self._or("lambda_I_per_s2", base.K_I / kv),
                         self._or("phi_q_per_s", (self.K_pct or 100.0) / kv), self.K_pct)
        return chain(p, self.sensors, Law.SLIDING_MODE, sliding=sm)


@dataclass(frozen=True, kw_only=True)
class RapidHeatingParameters(ControllerParameters):
    label: ClassVar[str] = "rapid-heating"
    source: ClassVar[str] = ("temperature-limited rapid heating and antagonist pre-heating around a PID (Teh and "
                             "Featherstone, IJRR 2008)")
    sensors: ClassVar[Sensors] = Sensors(position=True, temperature=True)

    K_P_per_q: float | None = _num(0.0, 1e9, _KP)
    K_V_s_per_q: float | None = _num(0.0, 1e9, _KV)
    K_I_per_q_s: float | None = _num(0.0, 1e9, _KI)
    boost_V: float | None = _num(0.0, 100.0, "drive of the rapid-heating pulse [V]; None: 1.5 V_H")
    boost_until_C: float | None = _num(-100.0, 400.0, "pulse while the wire is below this [degC]; None: A_S0_C")
    T_max_C: float | None = _num(-100.0, 400.0, "no duty at or above this wire temperature [degC]; None: A_F0_C + 4")
    preheat_C: float | None = _num(-100.0, 400.0, "standby temperature of an idle wire [degC]; None: no pre-heating")
    preheat_duty_pct: float = _num(0.0, 100.0, "duty of the pre-heating [%]", default=30.0)

    def record(self, p: ParameterSet, base: Controller) -> ControlChain:
        shaping = RapidHeating(self._or("boost_V", 1.5 * p.V_H_V), self._or("boost_until_C", p.A_S0_C),
                               self._or("T_max_C", p.A_F0_C + 4.0), self._or("preheat_C", -math.inf),
                               self.preheat_duty_pct)
        return chain(p, self.sensors, Law.PID, pid=PIDGains(*self._gains(base)), shaping=shaping)


@dataclass(frozen=True, kw_only=True)
class ResistanceFeedbackParameters(ControllerParameters):
    label: ClassVar[str] = "resistance"
    source: ClassVar[str] = ("self-sensing: the PID on a position estimated from the wires' resistance (Ikuta et al. "
                             "1988, Ma et al. 2004)")
    sensors: ClassVar[Sensors] = Sensors(position=False, temperature=False)

    K_P_per_q: float | None = _num(0.0, 1e9, _KP)
    K_V_s_per_q: float | None = _num(0.0, 1e9, _KV)
    K_I_per_q_s: float | None = _num(0.0, 1e9, _KI)
    rate_tau_s: float = _num(0.0, 10.0, "time constant of the rate estimate's filter [s]", default=0.05)
    #: the resistance-to-position map; None: calibrated for the set when the record is built
    calibration: ResistanceCalibration | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        cal = self.calibration
        if isinstance(cal, dict):  # as to_dict writes it (a run definition read back)
            try:
                cal = ResistanceCalibration(**{k: tuple(v) if isinstance(v, list) else v for k, v in cal.items()})
            except TypeError as exc:
                raise ParameterError(f"{self.label}: calibration = {self.calibration!r} is not a calibration "
                                     f"({exc})") from None
            object.__setattr__(self, "calibration", cal)
        elif cal is not None and not isinstance(cal, ResistanceCalibration):
            raise ParameterError(f"{self.label}: calibration = {cal!r} is not a ResistanceCalibration")

    def to_dict(self) -> dict[str, Any]:
        """As every controller's, and the calibration if one was given (its fields): a run's
        definition must hold it, or a re-run would calibrate anew. Left out when the record
        calibrates for the set, as before it was written."""
        out = super().to_dict()
        if self.calibration is not None:
            out["calibration"] = dataclasses.asdict(self.calibration)
        return out

    def prepared(self, p: ParameterSet) -> "ResistanceFeedbackParameters":
        """Calibrated for ``p`` (:func:`~.calibration.calibrate`: a dozen short runs) if not yet."""
        return self if self.calibration is not None else self.replace(calibration=calibrate(p))

    def record(self, p: ParameterSet, base: Controller) -> ControlChain:
        cal = self.prepared(p).calibration
        if cal.wires != tuple(p.wire_names):
            raise ParameterError(f"{self.label}: the calibration is for wires {', '.join(cal.wires)}, the set "
                                 f"{p.name!r} has {', '.join(p.wire_names)}")
        rmap = ResistanceMap(cal.R_ref_ohm, cal.c0, cal.c1, cal.c2, cal.c3, self.rate_tau_s)
        return chain(p, self.sensors, Law.PID, pid=PIDGains(*self._gains(base)), rmap=rmap)


#: label -> parameter class
CONTROLLERS: dict[str, type[ControllerParameters]] = {
    c.label: c for c in (PaperPID, FuzzyPIDParameters, SlidingModeParameters, RapidHeatingParameters,
                         ResistanceFeedbackParameters)
}


def controller_from(controller: str | ControllerParameters | None,
                    assignments: list[str] | tuple[str, ...] = ()) -> ControllerParameters:
    """A controller object from a label (or an object, or None: the paper's PID), then ``NAME=VALUE``s."""
    if controller is None:
        obj: ControllerParameters = PaperPID()
    elif isinstance(controller, ControllerParameters):
        obj = controller
    elif isinstance(controller, str) and controller in CONTROLLERS:
        obj = CONTROLLERS[controller]()
    else:
        raise ParameterError(f"controller = {controller!r} is not one of {', '.join(CONTROLLERS)}")
    return obj.with_overrides(assignments) if assignments else obj
