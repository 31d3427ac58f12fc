"""The control laws' anti-windup (Eq. 12a's conditional integration) against each law's own limit."""

import numpy as np
import pytest

from smafinger import simulate
from dataclasses import dataclass
from typing import ClassVar

from smafinger.control.params import FuzzyPIDParameters, RapidHeatingParameters, SlidingModeParameters
from smafinger.control.sensing import Sensors
from smafinger.parameters import get

CYCLE = ("cooperative", "0:-25,reach:-55,reach:-40")
REF = dict(t_end_s=20.0, method="rk4", dt_s=1e-3, pwm="exact")


def _with_anti_windup(mode: str):
    p = get("paper2010")
    return p.replace(options=p.options.replace(anti_windup=mode))


@pytest.mark.parametrize("K_pct", [50.0, 98.58])
def test_sliding_mode_anti_windup_freezes_the_integral_at_its_own_gain(K_pct):
    """The sliding law's output stops at +-K (Eq. SM2), below the PID's 100 %. Anti-windup took
    only +-100 % as saturated, so with K < 100 'clamp' ran bit-identical to 'none' (found by
    review; 98.58 is the bench's tuned K): the duties now differ, as they do at K = 100."""
    c = SlidingModeParameters(K_pct=K_pct)
    free = simulate(_with_anti_windup("none"), *CYCLE, controller=c, **REF)
    clamped = simulate(_with_anti_windup("clamp"), *CYCLE, controller=c, **REF)
    assert np.max(np.abs(free.duty_upper - clamped.duty_upper)) > 1.0
    assert np.max(np.abs(free.theta_deg - clamped.theta_deg)) > 0.1
    assert np.max(free.duty_upper) == pytest.approx(K_pct) and np.max(clamped.duty_upper) == pytest.approx(K_pct)


@dataclass(frozen=True, kw_only=True)
class BlindRapidHeating(RapidHeatingParameters):
    """Rapid heating reading the angle it does not declare (module level: the interpreted engine
    pickles the run to its child process)."""

    sensors: ClassVar[Sensors] = Sensors(position=False, temperature=True)


@dataclass(frozen=True, kw_only=True)
class BlindFuzzy(FuzzyPIDParameters):
    sensors: ClassVar[Sensors] = Sensors(position=False, temperature=True)


def test_a_controller_that_reads_an_undeclared_sensor_stops_the_run_at_once():
    """Its NaN duty left the wire off to the end without a word (found by review; the sensing
    module's docstring promised the stop)."""
    from smafinger.engine.run import DutyNotANumber

    with pytest.raises(DutyNotANumber, match=r"not a number at t = 0 s \(controller 'rapid-heating'"):
        simulate("paper2010", "independent", "0:-25", t_end_s=1.0, controller=BlindRapidHeating())
    assert simulate("paper2010", "independent", "0:-25", t_end_s=1.0,
                    controller=RapidHeatingParameters()).metrics  # seeing, it runs
    for engine in ("compiled", "interpreted"):  # plain Python divided by the rules' zero weight
        with pytest.raises(DutyNotANumber, match=r"not a number at t = 0 s \(controller 'fuzzy-pid'"):
            simulate("paper2010", "independent", "0:-25", t_end_s=0.01, controller=BlindFuzzy(), engine=engine)


@pytest.mark.parametrize("change, needle", [
    (dict(R_ref_ohm=(0.0, 3.7)), "R_ref_ohm = \\(0.0, 3.7\\) must be above 0"),
    (dict(R_ref_ohm=(-3.7, 3.7)), "must be above 0"),
    (dict(c0=float("nan")), "c0 = nan holds nan, not a finite number"),
    (dict(c1=(-3.0,)), "c1 = \\(-3.0,\\) needs one value per wire \\(2\\)"),
    (dict(wires=("upper",)), "needs one value per wire \\(1\\)"),
])
def test_a_resistance_calibration_that_cannot_estimate_is_refused(change, needle):
    """Found by review: R_ref 0 or a NaN coefficient ran with a NaN duty, a short tuple was an IndexError."""
    import dataclasses

    from smafinger.control.calibration import ResistanceCalibration
    from smafinger.control.params import ResistanceFeedbackParameters
    from smafinger.parameters import ParameterError

    good = dict(wires=("upper", "lower"), R_ref_ohm=(3.7, 3.7), c0=-0.7, c1=(1.0, -1.0), c2=(0.0, 0.0),
                c3=(0.0, 0.0), rms_error=0.001, max_error=0.004)
    ResistanceCalibration(**good)
    with pytest.raises(ParameterError, match=needle):
        ResistanceCalibration(**{**good, **change})
    with pytest.raises(ParameterError, match=needle):  # as a run definition read back gives it
        ResistanceFeedbackParameters(calibration={**good, **{k: list(v) if isinstance(v, tuple) else v
                                                             for k, v in change.items()}})
    assert dataclasses.asdict(ResistanceCalibration(**good))["c0"] == -0.7


def test_a_microsecond_pwm_period_calibrates_with_the_averaged_pwm(monkeypatch):
    """Found by review: a resistance-controller run on paper2010 at t_P = 1 us (0.2 s, averaged PWM)
    took 189 s, all of it in the hidden calibration: 12 steps of 12 s with the PWM resolved, two
    sub-steps per period (2 x 10^6 per simulated second). Below 0.1 ms, where the averaged PWM is
    valid for the set, the calibration averages it too: one sub-step per 1 ms step."""
    from smafinger.control import calibration
    from smafinger.engine import run

    real, substeps = run.simulate, []

    def counted(*args, **kwargs):
        spec = run.make_spec(*args, **{k: v for k, v in kwargs.items() if k != "engine"})
        assert (spec.method, spec.dt_s, spec.pwm) == ("rk4", 1e-3, "averaged")  # else hours of edges
        r = real(*args, **kwargs)
        substeps.append(r.substeps)
        return r

    monkeypatch.setattr(run, "simulate", counted)
    fast = calibration.calibrate(get("paper2010").replace(pwm_period_s=1e-6))
    assert len(substeps) == len(calibration.CALIBRATION_TARGETS["joint"])
    assert max(substeps) <= 1.01 * calibration.STEP_S / 1e-3  # a sub-step per step, not 2 x 10^6 per second
    monkeypatch.setattr(run, "simulate", real)
    resolved = calibration.calibrate(get("paper2010"))  # t_P = 1 ms: the PWM resolved, as it always was
    assert fast.rms_error < 0.005 and abs(fast.c0 - resolved.c0) < 1e-4  # rad: the same map, near enough
    # the paper's sets keep their calibrations; a hysteresis rule that follows the ripple keeps the PWM resolved
    assert calibration.calibration_numerics(get("paper2010")).pwm == "exact"
    assert calibration.calibration_numerics(get("authors2020").replace(pwm_period_s=1e-6)).pwm == "exact"


def test_a_calibration_estimates_only_what_it_can():
    """Found by an API fuzz: one wire's 1-D series gave one estimate, a short row an IndexError,
    and one target fitted a cubic to one position (a 1.3 um fit, metres off elsewhere)."""
    from smafinger.control.calibration import ResistanceCalibration, calibrate
    from smafinger.parameters import ParameterError

    one = ResistanceCalibration(wires=("wire",), R_ref_ohm=(10.0,), c0=0.0, c1=(1.0,), c2=(0.0,), c3=(0.0,),
                                rms_error=0.0, max_error=0.0)
    np.testing.assert_allclose(one.estimate(np.array([10.0, 11.0, 12.0])), [0.0, 0.1, 0.2])
    two = ResistanceCalibration(wires=("upper", "lower"), R_ref_ohm=(10.0, 10.0), c0=0.0, c1=(1.0, -1.0),
                                c2=(0.0, 0.0), c3=(0.0, 0.0), rms_error=0.0, max_error=0.0)
    np.testing.assert_allclose(two.estimate(np.array([11.0, 10.0])), [0.1])  # one sample of both wires
    with pytest.raises(ParameterError, match=r"R_ohm has shape \(1, 1\); expected samples x 2 wire\(s\)"):
        two.estimate(np.array([[11.0]]))
    np.testing.assert_allclose(one.estimate(10.5), [0.05])  # one sample of one wire
    for targets in ((), (0.0075,), (0.004, 0.004, 0.008)):
        with pytest.raises(ParameterError, match="has 4 coefficients and needs 4 distinct positions at least"):
            calibrate(get("linear-bias-spring"), targets)
    with pytest.raises(ParameterError, match=r"of 2 wire\(s\) has 7 coefficients"):  # 4 fitted the joint exactly
        calibrate(get("paper2010"), (-34.0, -32.0, -30.0, -28.0))


def test_none_only_where_it_means_from_the_set():
    """K_pct, preheat_duty_pct and rate_tau_s took None and failed mid-run (found by an API fuzz);
    a field whose None means 'derived from the set' still takes it."""
    from smafinger.control.params import CONTROLLERS, PaperPID
    from smafinger.parameters import ParameterError

    refused = []
    for label, cls in CONTROLLERS.items():
        for name in cls().field_names():
            try:
                cls().replace(**{name: None})
            except ParameterError as exc:
                assert f"{name} = None: give a number" in str(exc)
                refused.append(name)
    assert sorted(refused) == ["K_pct", "preheat_duty_pct", "rate_tau_s"]
    assert PaperPID().replace(K_P_per_q=None).K_P_per_q is None
