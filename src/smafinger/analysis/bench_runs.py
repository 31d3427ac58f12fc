"""Bench runs ready to simulate: an open-loop recording, or a closed-loop run to replay.

A :class:`BenchRun` holds what one recorded run needs to be simulated with any parameter set of
its mechanism, and compared with what was measured:

- *open loop*: the recorded input (``duty``, ``voltage_V`` or ``current_A``) becomes the drive
  program of one wire (zero-order hold, a step per change, as
  :func:`~smafinger.recordings.input_program` gives it);
- *closed loop* (replay): a recorded reference (``position_ref_m`` or ``theta_ref_deg`` by
  default) becomes a target profile with a segment per change, and the rig's controller
  (:class:`RigController`) drives the wire.

Times start at the first input sample (open loop) or the first reference sample (closed
loop). The simulator reports on a grid whose interval divides the output's sample period when
it can (:func:`output_interval_for`), so the model is compared at the measured instants
without interpolation.

The measured output is the mechanism's coordinate plus a sensor offset per run. The model
starts every run at rest at its initial coordinate, so the samples recorded before the drive
(or the reference) first leaves its rest value, or at that instant, measure that offset directly
(:attr:`BenchRun.baseline`). A run whose output was first sampled after that has no baseline:
its offset cannot be measured (:meth:`BenchRun.baseline_offset` refuses it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..engine.run import DEFAULT_DT_S, RunSpec, make_spec
from ..engine.signals import COORDINATE_NAMES
from ..parameters import ParameterSet
from ..parameters.mechanisms import JointParameters, LinearActuatorParameters
from ..profiles import Segment, TargetProfile, VoltageProgram
from ..recordings import (OutputSamples, Recording, RecordingError, input_program, output_on_grid,
                          read_recording)
from ..recordings.mapping import SignalMap, Source, as_signal_map, parse_source
from ..recordings.signals import SPEC

#: recorded input kind -> the simulator's drive kind
DRIVE_OF_INPUT = {"duty": "duty", "voltage_V": "voltage", "current_A": "current"}
#: candidate output intervals, as multiples of the step, largest first
INTERVAL_STEPS = (100, 50, 20, 10, 5, 2, 1)
#: mechanism -> its controller gain fields (% per SI unit of error, Eq. 12a)
GAIN_FIELDS = {
    JointParameters.mechanism: ("K_P_per_rad", "K_V_s_per_rad", "K_I_per_rad_s"),
    LinearActuatorParameters.mechanism: ("K_P_per_m", "K_V_s_per_m", "K_I_per_m_s"),
}
ROLES = ("fit", "validate")
#: baseline samples needed to estimate the sensor's noise
MIN_NOISE_SAMPLES = 5
MODES = ("open-loop", "closed-loop")


class BenchRunError(RecordingError):
    """A run cannot be simulated as given (one line naming the file or the option)."""


def coordinate_column(p: ParameterSet) -> str:
    """The simulator's and the file's name of the mechanism's coordinate (``position_m``, ``theta_deg``)."""
    return COORDINATE_NAMES[p.mechanism]["q"]


def reference_column(p: ParameterSet) -> str:
    """The default reference column of a closed-loop file (``position_ref_m``, ``theta_ref_deg``)."""
    return COORDINATE_NAMES[p.mechanism]["q_ref"]


def output_si_name(p: ParameterSet) -> str:
    """The recording's SI output name for the set's mechanism (``position_m``, ``theta_rad``)."""
    return SPEC[coordinate_column(p)].si_name


def rest_coordinate_si(p: ParameterSet) -> float:
    """Where the model starts every run, at rest [m or rad]."""
    return p.to_si(p.initial_target)


@dataclass(frozen=True)
class RigController:
    """The rig's PID as it ran: gains in duty (a fraction of V_H) per SI unit of error.

    ``K_P`` [1/m or 1/rad], ``K_V`` [s/m or s/rad], ``K_I`` [1/(m s) or 1/(rad s)]; ``None``
    keeps the parameter set's gain. The duty is clamped to [0, ``duty_max``].
    """

    K_P: float | None = None
    K_V: float | None = None
    K_I: float | None = None
    duty_max: float = 1.0

    def __post_init__(self) -> None:
        for name in ("K_P", "K_V", "K_I"):
            v = getattr(self, name)
            if v is not None and not (math.isfinite(v) and v >= 0):
                raise BenchRunError(f"controller gain {name} = {v!r} must be a finite number >= 0")
        if not (math.isfinite(self.duty_max) and 0.0 < self.duty_max <= 1.0):
            raise BenchRunError(f"duty_max = {self.duty_max!r} must be in (0, 1] (a fraction of V_H)")

    def apply(self, p: ParameterSet) -> ParameterSet:
        """The set as the engine must see it to run this controller.

        The engine's Eq. (12a) gives DC% in [0, 100] of the supply V_H. A clamp at
        ``duty_max`` < 1 is the same mean Joule power (duty x V_H^2, Eq. 11) as a full-range
        duty of a supply sqrt(duty_max) V_H with the gains divided by ``duty_max``: exact for
        the power averaged over a PWM period (needs V_L = 0). The error integral is never
        reset (a sampled reference is not a sequence of targets: ``integral_reset = never``).
        """
        if self.duty_max < 1.0 and p.V_L_V > 0.0:
            raise BenchRunError(f"duty_max = {self.duty_max:g} needs V_L_V = 0 (the set has {p.V_L_V:g} V)")
        changes = {}
        for name, fld in zip(("K_P", "K_V", "K_I"), GAIN_FIELDS[p.mechanism]):
            rig = getattr(self, name)
            percent = getattr(p, fld) if rig is None else 100.0 * rig
            changes[fld] = percent / self.duty_max
        return p.replace(V_H_V=p.V_H_V * math.sqrt(self.duty_max), integral_reset="never", **changes)


@dataclass(frozen=True)
class BenchRun:
    """One recorded run, ready to simulate with any set of its mechanism.

    Attributes
    ----------
    file, role, mode : str
        The file, ``fit`` or ``validate``, ``open-loop`` or ``closed-loop``.
    recording : Recording
        As read, times shifted so that the run starts at 0 s.
    samples : OutputSamples
        The measured output (SI) located on the simulation grid.
    output_interval_s, t_end_s : float
        The simulation's output grid and length.
    program : VoltageProgram or None
        Open loop: the drive program (the input on one wire, the others off).
    profile : TargetProfile or None
        Closed loop: the reference, in the rig's frame minus :attr:`reference_offset`.
    reference : ndarray or None
        Closed loop: (times, values) of the reference as recorded (SI).
    controller : RigController or None
    baseline : ndarray of bool
        Output samples recorded while the model is still at rest: at or before
        :attr:`rest_end_s`. No sample if the output was first sampled later.
    reference_offset : float
        Closed loop: the sensor offset subtracted from the reference (measured on the baseline).
    rest_end_s : float
        When the drive (open loop) or the reference (closed loop) first leaves its rest value
        [s from the run's start]; 0 for a drive on from its first sample, inf if it never does.
    """

    file: str
    role: str
    mode: str
    recording: Recording
    samples: OutputSamples
    output_interval_s: float
    t_end_s: float
    baseline: np.ndarray
    program: VoltageProgram | None = None
    profile: TargetProfile | None = None
    reference: tuple[np.ndarray, np.ndarray] | None = None
    controller: RigController | None = None
    reference_offset: float = 0.0
    rest_end_s: float = math.inf

    @property
    def n_samples(self) -> int:
        return int(self.samples.values.size)

    def baseline_offset(self, p: ParameterSet) -> float:
        """Sensor offset measured on the baseline: its mean minus the rest coordinate [SI].

        Raises
        ------
        BenchRunError
            No output sample is on the baseline (see :meth:`check_baseline`).
        """
        self.check_baseline()
        return float(np.mean(self.samples.values[self.baseline])) - rest_coordinate_si(p)

    def check_baseline(self) -> None:
        """Refuse a run whose output was first sampled after the drive (or the reference) left
        its rest value: no sample shows the model at rest, so the sensor offset cannot be
        measured, and any sample taken for it would carry part of the motion.

        Raises
        ------
        BenchRunError
            One line naming the file, both times (as in the file) and what to do instead.
        """
        if self.baseline.any():
            return
        t0 = float(self.recording.meta.get("time_origin_s", 0.0))
        if self.mode == "open-loop":
            what, fix = "the drive first turns on", ("record the output from before the drive turns on, give "
                                                     "--offset none (a calibrated sensor), or fit the run (--fit: "
                                                     "its offset is fitted)")
        else:
            what, fix = "the reference first changes", ("record the output from before the reference changes, or "
                                                        "give --offset none (a calibrated sensor: the reference is "
                                                        "the target)")
        raise BenchRunError(f"{self.file}: no output sample before {what} (at t = {self.rest_end_s + t0:.6g} s; "
                            f"the output starts at {float(self.recording.output.t_s[0]) + t0:.6g} s), so its sensor "
                            f"offset cannot be measured: {fix}")

    def baseline_noise(self) -> float | None:
        """Standard deviation of the baseline samples (the sensor's noise while at rest), or
        ``None`` with fewer than :data:`MIN_NOISE_SAMPLES` of them."""
        v = self.samples.values[self.baseline]
        return float(np.std(v, ddof=1)) if v.size >= MIN_NOISE_SAMPLES else None

    def spec(self, p: ParameterSet, dt_s: float = DEFAULT_DT_S) -> RunSpec:
        """The simulation of this run with the set ``p`` (validated)."""
        if self.mode == "open-loop":
            return make_spec(p, "open-loop", voltage=self.program, t_end_s=self.t_end_s, dt_s=dt_s,
                             output_interval_s=self.output_interval_s)
        return make_spec(self.controller.apply(p), "cooperative", profile=self.profile, t_end_s=self.t_end_s,
                         dt_s=dt_s, output_interval_s=self.output_interval_s)

    def model_output(self, on_grid, p: ParameterSet) -> np.ndarray:
        """The simulated coordinate column (on the grid, user units) at the sample times, in SI."""
        return self.samples.model_at(np.asarray(on_grid, dtype=np.float64) / p.coordinate.scale)


def output_interval_for(t_s: np.ndarray, dt_s: float = DEFAULT_DT_S, tol_s: float = 1e-7) -> float:
    """The longest output interval (a multiple of ``dt_s`` in :data:`INTERVAL_STEPS`) on whose
    grid every sample time falls (within ``tol_s``); ``dt_s`` if none does (the model is then
    interpolated between grid points)."""
    for k in INTERVAL_STEPS:
        interval = round(k * dt_s, 9)
        phase = np.abs(t_s / interval - np.round(t_s / interval)) * interval
        if (phase <= tol_s).all():
            return interval
    return dt_s


def _grid(rec: Recording, what: str, dt_s: float) -> tuple[float, float, OutputSamples]:
    t_out = rec.output.t_s
    if t_out[0] < -1e-9:
        raise BenchRunError(f"{rec.file}: the output {rec.output.source!r} starts at {t_out[0]:.6g} s, before the "
                            f"first {what} sample; trim the samples before it")
    interval = output_interval_for(t_out, dt_s)
    n = max(1, math.ceil(t_out[-1] / interval - 1e-6))
    t_end = round(max(n * interval, dt_s), 9)
    grid = np.round(np.arange(n + 1) * interval, 9)
    return interval, t_end, output_on_grid(rec, grid)


#: an input that starts at most this fraction of its largest value starts idle (at rest)
IDLE_FRACTION = 0.05


def _rest_mask(t_out: np.ndarray, t_rest: float) -> np.ndarray:
    """The output samples at or before ``t_rest`` (the model is at rest until then, and at it)."""
    return t_out <= t_rest + 1e-9


def drive_program(rec: Recording, p: ParameterSet, wire: str | None = None) -> VoltageProgram:
    """The recorded input as a program on one wire (default: the first), the others off."""
    names = p.wire_names
    wire = names[0] if wire is None else wire
    if wire not in names:
        raise BenchRunError(f"wire {wire!r} is not a wire of a {p.mechanism} ({', '.join(names)})")
    k = names.index(wire)
    steps, last_t = [], -1.0
    for t, v in input_program(rec):
        t = round(t, 9)
        row = [t] + [0.0] * len(names)
        row[1 + k] = v
        if steps and t == last_t:
            steps[-1] = tuple(row)  # two samples in the same nanosecond: the later one holds
        else:
            steps.append(tuple(row))
        last_t = t
    return VoltageProgram(tuple(steps), DRIVE_OF_INPUT[rec.input_kind])


def load_open_loop(path, mapping, role: str, p: ParameterSet, wire: str | None = None,
                   dt_s: float = DEFAULT_DT_S) -> BenchRun:
    """An open-loop run: the file's input drives one wire; its output is compared.

    Raises
    ------
    RecordingError
        The file cannot be read (see ``docs/recordings.md``), its output is not the set's
        coordinate, or its output starts before its input.
    """
    _check_role(role)
    rec = _read(path, mapping, p).with_time_origin()
    interval, t_end, samples = _grid(rec, "input", dt_s)
    # the baseline (at rest: the offset and the noise are measured there) lasts until the input
    # first changes, if it starts idle (off, or at most IDLE_FRACTION of its largest value: a
    # sensing current); a run whose drive is on from its first sample has none but an output
    # sample at that instant (its whole heating counted as rest gave a 5.5 mm offset and 7.5 mm
    # of "noise"); an output first sampled after the drive came on has none at all
    u = rec.input.values
    on = np.flatnonzero(u != u[0])
    idle = abs(float(u[0])) <= IDLE_FRACTION * float(np.max(np.abs(u)))
    t_rest = (float(rec.input.t_s[on[0]]) if on.size else math.inf) if idle else float(rec.input.t_s[0])
    return BenchRun(str(path), role, "open-loop", rec, samples, interval, t_end,
                    _rest_mask(rec.output.t_s, t_rest), program=drive_program(rec, p, wire), rest_end_s=t_rest)


def load_closed_loop(path, mapping, p: ParameterSet, controller: RigController, reference: str | None = None,
                     dt_s: float = DEFAULT_DT_S, offset: bool = True) -> BenchRun:
    """A closed-loop run to replay: its reference becomes the target profile of the rig's PID.

    ``reference`` is the reference column as ``NAME[*FACTOR]`` (default: ``position_ref_m`` or
    ``theta_ref_deg``), read from the same file with the same checks and units as the output.
    The reference is in the sensor's frame; the target is the reference minus the offset
    measured on the baseline (the samples before the reference first changes, or at that
    instant; a :class:`BenchRunError` if there are none), or the reference itself with
    ``offset=False`` (a calibrated sensor).

    A closed loop can amplify small differences: where the PID drives the wire bang-bang
    through a steep transformation band, a target 1 um off can move a rise by tens of
    milliseconds (``docs/identification.md``).
    """
    smap = as_signal_map(mapping)
    q = coordinate_column(p)
    src = parse_source(reference or reference_column(p), "--reference")
    rec = _read(path, smap, p)
    ref_map = SignalMap(tuple((n, s) for n, s in smap.entries if n != q) + ((q, Source(src.name, src.scale)),))
    ref = read_recording(path, ref_map).output
    t0 = float(ref.t_s[0])
    rec = rec.with_time_origin(t0)
    interval, t_end, samples = _grid(rec, "reference", dt_s)
    t_ref, v_ref = ref.t_s - t0, ref.values
    moved = np.flatnonzero(v_ref != v_ref[0])
    t_rest = float(t_ref[moved[0]]) if moved.size else math.inf
    run = BenchRun(str(path), "validate", "closed-loop", rec, samples, interval, t_end,
                   _rest_mask(rec.output.t_s, t_rest), reference=(t_ref, v_ref), controller=controller,
                   rest_end_s=t_rest)
    offset = run.baseline_offset(p) if offset else 0.0
    return replace(run, reference_offset=offset, profile=reference_profile(t_ref, v_ref - offset, p))


def reference_profile(t_s: np.ndarray, values_si: np.ndarray, p: ParameterSet) -> TargetProfile:
    """A sampled reference (SI) as a target profile: a segment per change, times to the nanosecond."""
    t = np.round(np.asarray(t_s, dtype=np.float64), 9)
    v = np.asarray(values_si, dtype=np.float64) * p.coordinate.scale
    keep = np.ones(v.size, dtype=bool)
    keep[1:] = v[1:] != v[:-1]
    segs = [Segment(0.0, float(v[0]))]
    segs += [Segment(float(ti), float(vi)) for ti, vi in zip(t[keep][1:], v[keep][1:])]
    return TargetProfile(tuple(segs))


def _read(path, mapping, p: ParameterSet) -> Recording:
    rec = read_recording(path, mapping)
    want = output_si_name(p)
    if rec.output_name != want:
        raise BenchRunError(f"{path}: the output is {rec.output_name} but a {p.mechanism} set "
                            f"({p.name}) moves {want}; check --params or the mapping")
    return rec


def _check_role(role: str) -> None:
    if role not in ROLES:
        raise BenchRunError(f"role {role!r} is not one of {', '.join(ROLES)}")
