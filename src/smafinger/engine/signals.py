"""The output signals, declared once: recorded field, SI unit, exported name and scale.

A run's outputs are two float64 arrays made from :data:`SIGNALS`, one row per recorded field,
one column per output sample: the mechanism's (fields x samples, rows :data:`MC`) and the
wires' (wires x fields x samples, rows :data:`WC`). Each signal is one contiguous row, so a
metric or an export reads only its own samples. A result exports them as columns named here: ``{wire}`` becomes the
wire's name (``upper``, ``lower``; ``wire`` for the linear actuator) and ``{q}``, ``{q_ref}``,
``{v}``, ``{load}`` the mechanism's names (``theta_deg``, ``theta_ref_deg``, ``omega_deg_s``,
``load_Nm`` for the joint; ``position_m``, ``position_ref_m``, ``velocity_m_s``, ``load_N`` for
the linear actuator). Columns keep their order across versions: new signals go at the end.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..jit import njit
from ..model.resistance import wire_resistance, wire_strain


@dataclass(frozen=True)
class Signal:
    field: str  #: name recorded by the engine
    per_wire: bool
    unit: str  #: SI unit of the recorded value ("q": the coordinate's, rad or m)
    export: str  #: exported column name (a template, see the module docstring)
    scale: str = "1"  #: "1": exported as recorded; "q": times the coordinate's user scale (rad -> deg)
    mechanisms: tuple[str, ...] = ()  #: exported only for these (empty: every mechanism)
    doc: str = ""


SIGNALS: tuple[Signal, ...] = (
    Signal("t", False, "s", "t_s", doc="time"),
    Signal("q", False, "q", "{q}", "q", doc="the mechanism's coordinate (joint angle or slider position)"),
    Signal("q_ref", False, "q", "{q_ref}", "q", doc="its target (theta_F of Eq. 12a)"),
    Signal("v", False, "q/s", "{v}", "q", doc="its rate"),
    Signal("T", True, "degC", "T_{wire}_C", doc="wire temperature (Eq. 11)"),
    Signal("xi", True, "1", "xi_{wire}", doc="martensite fraction (Eqs. 9-10)"),
    Signal("sigma", True, "Pa", "sigma_{wire}_Pa", doc="wire stress (Eqs. 7-8)"),
    Signal("force", True, "N", "force_{wire}_N", doc="wire tension sigma S_w"),
    Signal("arm", True, "m", "arm_{wire}_m", mechanisms=("joint",), doc="moment arm b (Eqs. 4b, 5b)"),
    Signal("spring", True, "m", "spring_{wire}_m", mechanisms=("joint",), doc="tendon spring elongation"),
    Signal("V", True, "V", "V_{wire}_V", doc="the drive at the sample: with the exact PWM the level applied then "
           "(V_H in the on part of a period, V_L in the off part); with the averaged PWM the period's RMS, "
           "sqrt(d V_H^2 + (1 - d) V_L^2) (pwm.averaged_drive), whose square over the heating resistance "
           "R_w L_w is the period's mean power (R_{wire}_ohm is the phase-dependent resistance a sensor "
           "reads, not that one). With the exact PWM, samples on the period grid all fall in the on "
           "part: read the mean power as the slope of electrical_energy_{wire}_J. A current in A with a "
           "current drive"),
    Signal("duty", True, "%", "duty_{wire}", doc="PWM duty DC% (Eq. 12)"),
    # --- added in smafinger 0.2 -------------------------------------------------------------
    Signal("electrical", True, "J", "electrical_energy_{wire}_J",
           doc="electrical energy delivered at the wire's terminals (V^2 / (R_w L_w), or I^2 R_w L_w, over time)"),
    Signal("heat", True, "J", "heat_{wire}_J",
           doc="Joule heat the model puts into the wire (Eq. 11's P' times L_w over time)"),
    Signal("T_case", True, "degC", "T_casing_{wire}_C",
           doc="air inside the actuator casing (two-node thermal model; the ambient otherwise)"),
    Signal("load", False, "q-load", "{load}", doc="net load on the mechanism: M_E of Eq. (1b) or the slider's force"),
    Signal("enabled", True, "1", "enabled_{wire}", doc="1 while the wire's actuator is enabled"),
    Signal("heating", True, "1", "heating_{wire}", doc="1 in its controller's heating phase (Sec. 2.6)"),
    Signal("stuck", False, "1", "stuck", doc="1 while held by static friction or an end stop (Eq. 2)"),
    Signal("segment", False, "1", "segment", doc="index of the profile segment in force"),
    # --- added with the controllers (issue 15) ----------------------------------------------
    Signal("R", True, "ohm", "R_{wire}_ohm",
           doc="whole-wire resistance, phase and temperature dependent (model.resistance): what self-sensing reads"),
)

MECHANISM_FIELDS = tuple(s.field for s in SIGNALS if not s.per_wire)
WIRE_FIELDS = tuple(s.field for s in SIGNALS if s.per_wire)
MECHANISM_DTYPE = np.dtype([(f, np.float64) for f in MECHANISM_FIELDS])
WIRE_DTYPE = np.dtype([(f, np.float64) for f in WIRE_FIELDS])

#: the row of each signal in the arrays the engine writes (fields x samples, and wires x fields x
#: samples); compile-time constants
MechanismColumns = NamedTuple("MechanismColumns", [(f, int) for f in MECHANISM_FIELDS])
WireColumns = NamedTuple("WireColumns", [(f, int) for f in WIRE_FIELDS])
MechanismColumns.__module__ = WireColumns.__module__ = __name__
MC = MechanismColumns(*range(len(MECHANISM_FIELDS)))
WC = WireColumns(*range(len(WIRE_FIELDS)))

#: what a run's metrics and plausibility checks read (``results.compute_metrics``): all a sweep's
#: table needs. A run made with ``record="metrics"`` records these signals alone (the kernel
#: writes 14 of the joint's 35 values a sample); a test checks that its metrics are the same.
#: The casing temperature is among them for the plausibility check's casing warning, so that a
#: sweep's rows give the warnings simulate gives (found by review).
METRIC_FIELDS = ("t", "q", "T", "xi", "sigma", "electrical", "heat", "T_case")
#: what a run records: every signal, or the :data:`METRIC_FIELDS`
RECORD = ("all", "metrics")

#: mechanism label -> names of {q}, {q_ref}, {v}, {load}
COORDINATE_NAMES = {
    "joint": {"q": "theta_deg", "q_ref": "theta_ref_deg", "v": "omega_deg_s", "load": "load_Nm"},
    "linear-bias-spring": {"q": "position_m", "q_ref": "position_ref_m", "v": "velocity_m_s", "load": "load_N"},
}


def columns(mechanism: str, wire_names: tuple[str, ...], q_scale: float) -> list[tuple[str, str, str | int, float]]:
    """Exported columns, in order: (name, recorded field, "mechanism" or wire index, scale)."""
    return list(_columns(mechanism, tuple(wire_names), q_scale))


@functools.lru_cache(maxsize=64)
def _columns(mechanism: str, wire_names: tuple[str, ...], q_scale: float) -> tuple:
    names = COORDINATE_NAMES[mechanism]
    out = []
    for s in SIGNALS:
        if s.mechanisms and mechanism not in s.mechanisms:
            continue
        scale = q_scale if s.scale == "q" else 1.0
        if s.per_wire:
            out += [(s.export.format(wire=w), s.field, i, scale) for i, w in enumerate(wire_names)]
        else:
            out.append((s.export.format(**names), s.field, "mechanism", scale))
    return tuple(out)


def new_outputs(n_samples: int, n_wires: int) -> tuple[np.ndarray, np.ndarray]:
    """Output arrays for a run: the mechanism's (fields x samples) and the wires' (wires x fields
    x samples), float64, rows :data:`MC` and :data:`WC`. Only the time row is set (NaN): a sample
    is recorded whole (:func:`record_sample`), so a NaN time marks a sample not recorded
    (:func:`check_recorded`); the other rows are left as allocated (filling 17 MB for the 60 s
    full cycle cost 1.5 ms a run)."""
    mech = np.empty((len(MECHANISM_FIELDS), n_samples))
    mech[MC.t] = np.nan
    return mech, np.empty((n_wires, len(WIRE_FIELDS), n_samples))


def check_recorded(mech: np.ndarray) -> None:
    """Raise if a sample of the outputs (:func:`new_outputs`) was not recorded (its time is NaN)."""
    missing = int(np.count_nonzero(np.isnan(mech[MC.t])))
    if missing:
        raise RuntimeError(f"internal error: the run ended with {missing} of its {mech.shape[1]} output samples "
                           "not recorded")


def every_signal(record: str) -> bool:
    """Whether a run made with ``record`` (one of :data:`RECORD`) records every signal."""
    if record not in RECORD:
        raise ValueError(f"record = {record!r} is not one of {', '.join(RECORD)}")
    return record == "all"


def structured(mech: np.ndarray, wires: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The outputs as structured arrays, one row per sample (a copy): the mechanism's
    (:data:`MECHANISM_DTYPE`, samples) and the wires' (:data:`WIRE_DTYPE`, samples x wires)."""
    m = np.empty(mech.shape[1], dtype=MECHANISM_DTYPE)
    m.view(np.float64).reshape(m.shape[0], len(MECHANISM_FIELDS))[:] = mech.T
    w = np.empty((wires.shape[2], wires.shape[0]), dtype=WIRE_DTYPE)
    w.view(np.float64).reshape(w.shape[0], w.shape[1], len(WIRE_FIELDS))[:] = wires.transpose(2, 0, 1)
    return m, w


@njit(cache=True, forceinline=True)
def record_sample(mo, wo, i, t_s, state, aux, q_target, segment, stuck, cmds, drives, wires, geom, every_signal):
    """Write output sample ``i`` in the signals' rows: the :data:`METRIC_FIELDS`, and with
    ``every_signal`` all the others (a test checks none is left NaN).

    ``wires``: the model's wire records, ``geom`` the geometry at the state (for the resistance).
    """
    mo[MC.t, i] = t_s
    mo[MC.q, i] = state.q
    if every_signal:
        mo[MC.q_ref, i] = q_target
        mo[MC.v, i] = state.v
        mo[MC.load, i] = aux.load
        mo[MC.stuck, i] = 1.0 if stuck else 0.0
        mo[MC.segment, i] = segment
    for w in range(len(state.wires)):
        ws = state.wires[w]
        wa = aux.wires[w]
        wo[w, WC.T, i] = ws.T_C
        wo[w, WC.xi, i] = wa.xi
        wo[w, WC.sigma, i] = wa.sigma_Pa
        wo[w, WC.electrical, i] = ws.electrical_J
        wo[w, WC.heat, i] = ws.heat_J
        wo[w, WC.T_case, i] = ws.T_case_C
        if not every_signal:
            continue
        wo[w, WC.force, i] = wa.force_N
        wo[w, WC.arm, i] = wa.arm_m
        wo[w, WC.spring, i] = wa.spring_m
        wo[w, WC.V, i] = drives[w]
        wo[w, WC.duty, i] = cmds[w].duty
        wo[w, WC.enabled, i] = 1.0 if cmds[w].enabled else 0.0
        wo[w, WC.heating, i] = 1.0 if cmds[w].heating else 0.0
        strain = wire_strain(wires[w], geom.routes[w][0], wa.spring_m)
        wo[w, WC.R, i] = wire_resistance(wires[w], ws.T_C, wa.xi, strain)
