"""The output signals, declared once: recorded field, SI unit, exported name and scale.

The engine records, per run, one array per signal: :class:`MechanismOutputs` (one value per
output sample) and :class:`WireOutputs` (one row per sample, one column per wire), both
NamedTuples made from :data:`SIGNALS`; a result keeps them as two structured arrays
(:data:`MECHANISM_DTYPE`, :data:`WIRE_DTYPE`). A result exports them as columns named here: ``{wire}`` becomes the
wire's name (``upper``, ``lower``; ``wire`` for the linear actuator) and ``{q}``, ``{q_ref}``,
``{v}``, ``{load}`` the mechanism's names (``theta_deg``, ``theta_ref_deg``, ``omega_deg_s``,
``load_Nm`` for the joint; ``position_m``, ``position_ref_m``, ``velocity_m_s``, ``load_N`` for
the linear actuator). Columns keep their order across versions: new signals go at the end.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit


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
    Signal("V", True, "V", "V_{wire}_V", doc="voltage (current, in A, with a current drive) at the sample"),
    Signal("duty", True, "%", "duty_{wire}", doc="PWM duty DC% (Eq. 12)"),
    # --- added in smafinger 0.2 -------------------------------------------------------------
    Signal("energy", True, "J", "energy_{wire}_J", doc="electrical energy delivered at the wire's terminals"),
    Signal("load", False, "q-load", "{load}", doc="net load on the mechanism: M_E of Eq. (1b) or the slider's force"),
    Signal("enabled", True, "1", "enabled_{wire}", doc="1 while the wire's actuator is enabled"),
    Signal("heating", True, "1", "heating_{wire}", doc="1 in its controller's heating phase (Sec. 2.6)"),
    Signal("stuck", False, "1", "stuck", doc="1 while held by static friction or an end stop (Eq. 2)"),
    Signal("segment", False, "1", "segment", doc="index of the profile segment in force"),
)

MECHANISM_FIELDS = tuple(s.field for s in SIGNALS if not s.per_wire)
WIRE_FIELDS = tuple(s.field for s in SIGNALS if s.per_wire)
MECHANISM_DTYPE = np.dtype([(f, np.float64) for f in MECHANISM_FIELDS])
WIRE_DTYPE = np.dtype([(f, np.float64) for f in WIRE_FIELDS])

#: what the engine writes: one float64 array per signal (wires: samples x wires)
MechanismOutputs = NamedTuple("MechanismOutputs", [(f, np.ndarray) for f in MECHANISM_FIELDS])
WireOutputs = NamedTuple("WireOutputs", [(f, np.ndarray) for f in WIRE_FIELDS])
MechanismOutputs.__module__ = WireOutputs.__module__ = __name__

#: mechanism label -> names of {q}, {q_ref}, {v}, {load}
COORDINATE_NAMES = {
    "joint": {"q": "theta_deg", "q_ref": "theta_ref_deg", "v": "omega_deg_s", "load": "load_Nm"},
    "linear-bias-spring": {"q": "position_m", "q_ref": "position_ref_m", "v": "velocity_m_s", "load": "load_N"},
}


def columns(mechanism: str, wire_names: tuple[str, ...], q_scale: float) -> list[tuple[str, str, str | int, float]]:
    """Exported columns, in order: (name, recorded field, "mechanism" or wire index, scale)."""
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
    return out


def new_outputs(n_samples: int, n_wires: int) -> tuple[MechanismOutputs, WireOutputs]:
    """Empty (NaN) output arrays for a run."""
    return (MechanismOutputs(*(np.full(n_samples, np.nan) for _ in MECHANISM_FIELDS)),
            WireOutputs(*(np.full((n_samples, n_wires), np.nan) for _ in WIRE_FIELDS)))


def as_structured(mech: MechanismOutputs, wires: WireOutputs) -> tuple[np.ndarray, np.ndarray]:
    """The recorded arrays as two structured arrays (what a result keeps)."""
    m = np.empty(len(mech.t), dtype=MECHANISM_DTYPE)
    for f in MECHANISM_FIELDS:
        m[f] = getattr(mech, f)
    w = np.empty(wires.T.shape, dtype=WIRE_DTYPE)
    for f in WIRE_FIELDS:
        w[f] = getattr(wires, f)
    return m, w


@njit(cache=True, inline="always")
def record_sample(mo, wo, i, t_s, state, aux, q_target, segment, stuck, cmds, drives):
    """Write output sample ``i``: every signal (a test checks none is left NaN)."""
    mo.t[i] = t_s
    mo.q[i] = state.q
    mo.q_ref[i] = q_target
    mo.v[i] = state.v
    mo.load[i] = aux.load
    mo.stuck[i] = 1.0 if stuck else 0.0
    mo.segment[i] = segment
    for w in range(len(state.wires)):
        ws = state.wires[w]
        wa = aux.wires[w]
        wo.T[i, w] = ws.T_C
        wo.xi[i, w] = wa.xi
        wo.sigma[i, w] = wa.sigma_Pa
        wo.force[i, w] = wa.force_N
        wo.arm[i, w] = wa.arm_m
        wo.spring[i, w] = wa.spring_m
        wo.V[i, w] = drives[w]
        wo.duty[i, w] = cmds[w].duty
        wo.energy[i, w] = ws.electrical_J
        wo.enabled[i, w] = 1.0 if cmds[w].enabled else 0.0
        wo.heating[i, w] = 1.0 if cmds[w].heating else 0.0
