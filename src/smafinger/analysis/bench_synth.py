"""Synthetic bench runs made by the model itself, as a bench would record them.

The model runs at its usual step (1 ms) and reports every millisecond; the "logger" keeps the
drive at ``input_period_s`` (1 kHz) and the coordinate at ``output_period_s`` (100 Hz), adds a
sensor offset and Gaussian noise to the coordinate, and writes a CSV (one time column, empty
cells where a signal has no sample) or a MATLAB file laid out as Simulink's "To Workspace"
blocks save it (a Structure With Time per signal, each at its own rate). Used by the tests and
by ``examples/make_bench_data.py``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..engine.numerics import reference_dt
from ..engine.run import simulate
from ..files import atomic_write
from ..parameters import ParameterSet
from ..profiles import TargetProfile, VoltageProgram
from ..recordings.signals import SPEC
from .bench_runs import RigController, coordinate_column, reference_column

SIM_OUTPUT_S = 1e-3


@dataclass(frozen=True)
class SyntheticRun:
    """A recorded run: the drive at its times, the measured coordinate (SI) at its times.

    ``reference`` (closed loop) is the target as the rig saw it, in the sensor's frame
    (target + offset), at the output times. ``coordinate`` and ``reference_name`` are the file's
    column names (``theta_deg`` is written in degrees). ``truth`` records how it was made.
    """

    t_input_s: np.ndarray
    duty: np.ndarray
    t_output_s: np.ndarray
    output: np.ndarray
    coordinate: str
    reference: np.ndarray | None = None
    reference_name: str = ""
    truth: dict = field(default_factory=dict)


def file_units(name: str, si: np.ndarray) -> np.ndarray:
    """SI values of the canonical signal ``name`` in the file's units (radians -> degrees)."""
    return np.asarray(si) / SPEC[name].to_si


def _grid(period_s: float, t_end_s: float) -> np.ndarray:
    return np.round(np.arange(round(t_end_s / period_s) + 1) * period_s, 9)


def _logged(result, p: ParameterSet, t_end_s: float, input_period_s: float, output_period_s: float,
            noise: float, offset: float, seed: int):
    """(t_in, duty, t_out, measured coordinate SI) sampled from a 1 ms result."""
    t_in, t_out = _grid(input_period_s, t_end_s), _grid(output_period_s, t_end_s)
    i_in = np.round(t_in / SIM_OUTPUT_S).astype(int)
    i_out = np.round(t_out / SIM_OUTPUT_S).astype(int)
    q = result.signal(coordinate_column(p))[i_out] / p.coordinate.scale
    rng = np.random.default_rng(seed)
    measured = q + offset + noise * rng.standard_normal(q.size)
    return t_in, i_in, t_out, measured


def open_loop_run(p: ParameterSet, duty: str | VoltageProgram, t_end_s: float, *, noise: float = 0.0,
                  offset: float = 0.0, seed: int = 0, input_period_s: float = 1e-3,
                  output_period_s: float = 1e-2) -> SyntheticRun:
    """A run driven by a duty program (``"T:DUTY,..."``, a fraction of V_H, on the first wire)."""
    prog = VoltageProgram.parse(duty, "duty") if isinstance(duty, str) else duty
    r = simulate(p, "open-loop", voltage=prog, drive="duty", t_end_s=t_end_s, output_interval_s=SIM_OUTPUT_S,
                 dt_s=reference_dt(p), engine="compiled")  # the numerics the fits replay runs with (bench_runs)
    t_in, i_in, t_out, measured = _logged(r, p, t_end_s, input_period_s, output_period_s, noise, offset, seed)
    starts, values = prog.arrays()[0], prog.arrays()[1]
    d = values[np.searchsorted(starts, t_in + 1e-12, side="right") - 1]
    truth = {"mode": "open-loop", "duty_program": ",".join(f"{a:g}:{b:g}" for a, b in zip(starts, values)),
             "noise": noise, "offset": offset, "seed": seed}
    return SyntheticRun(t_in, d, t_out, measured, coordinate_column(p), truth=truth)


def closed_loop_run(p: ParameterSet, profile: str, controller: RigController, t_end_s: float, *,
                    noise: float = 0.0, offset: float = 0.0, seed: int = 0, input_period_s: float = 1e-3,
                    output_period_s: float = 1e-2) -> SyntheticRun:
    """A run under the rig's PID tracking ``profile`` (targets in the model's frame, user units);
    the logged duty is what the controller sent, the logged reference the target plus ``offset``."""
    prof = TargetProfile.parse(profile)
    r = simulate(controller.apply(p), "cooperative", profile=prof, t_end_s=t_end_s, output_interval_s=SIM_OUTPUT_S,
                 dt_s=reference_dt(p), engine="compiled")
    t_in, i_in, t_out, measured = _logged(r, p, t_end_s, input_period_s, output_period_s, noise, offset, seed)
    wire = p.wire_names[0]
    duty = np.round(r.signal(f"duty_{wire}")[i_in] / 100.0 * controller.duty_max, 4)  # a 0.01 % PWM resolution
    i_out = np.round(t_out / SIM_OUTPUT_S).astype(int)
    ref = r.signal(reference_column(p))[i_out] / p.coordinate.scale + offset
    truth = {"mode": "closed-loop", "profile": prof.to_text(), "noise": noise, "offset": offset, "seed": seed,
             "K_P": controller.K_P, "K_V": controller.K_V, "K_I": controller.K_I, "duty_max": controller.duty_max}
    return SyntheticRun(t_in, duty, t_out, measured, coordinate_column(p), ref, reference_column(p),
                        {k: v for k, v in truth.items() if v is not None})


def write_csv(path, run: SyntheticRun, digits: int = 7) -> None:
    """``t_s, duty, <coordinate>[, <reference>]``: one row per time of either rate, empty cells
    where a signal has no sample (written atomically)."""
    import pandas as pd

    t = np.union1d(run.t_input_s, run.t_output_s)
    df = pd.DataFrame({"t_s": t})
    df["duty"] = pd.Series(run.duty, index=np.searchsorted(t, run.t_input_s))
    at_out = np.searchsorted(t, run.t_output_s)
    df[run.coordinate] = pd.Series(file_units(run.coordinate, run.output), index=at_out)
    if run.reference is not None:
        df[run.reference_name] = pd.Series(file_units(run.coordinate, run.reference), index=at_out)
    atomic_write(path, lambda tmp: df.to_csv(tmp, index=False, float_format=f"%.{digits}g", na_rep=""))


def write_simulink_mat(path, run: SyntheticRun, names: dict[str, tuple[str, float]],
                       provenance: dict | None = None) -> None:
    """A MATLAB file as Simulink's "To Workspace" blocks (Structure With Time) save it, each
    signal at its own rate. ``names``: signal (``duty``, the coordinate, the reference) ->
    (variable name, factor from the canonical file unit, e.g. ``{"position_m": ("x_mm", 1e3)}``:
    millimetres; ``theta_deg`` is in degrees before the factor)."""
    from scipy.io import savemat

    series = {"duty": (run.t_input_s, run.duty),
              run.coordinate: (run.t_output_s, file_units(run.coordinate, run.output))}
    if run.reference is not None:
        series[run.reference_name] = (run.t_output_s, file_units(run.coordinate, run.reference))
    mdict = {}
    for sig, (var, factor) in names.items():
        t, v = series[sig]
        mdict[var] = {"time": t[:, None], "blockName": f"bench/{var}",
                      "signals": {"values": (v * factor)[:, None], "dimensions": 1.0, "label": var}}
    if provenance:
        mdict["provenance"] = provenance

    def write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            savemat(fh, mdict, format="5", long_field_names=True, do_compression=True, oned_as="column")

    atomic_write(Path(path), write)
