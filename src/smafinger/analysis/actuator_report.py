"""Predictions of bench runs with a parameter set, the report and a figure per run.

Every run, fitted or held out, open or closed loop, is simulated with the same set. The offset
of its position (or angle) sensor is:

- ``fitted``: a fitted run's offset from the fit (profiled least squares, with its stderr);
- ``baseline``: a held-out run's offset measured on its own samples recorded while the model
  is still at rest (before the drive or reference first leaves its rest value, or at that
  instant), with no use of the model's prediction: a held-out run is predicted, not fitted (one
  with no such sample is refused: :meth:`~.bench_runs.BenchRun.check_baseline`);
- ``none``: the sensor is taken as calibrated (``--offset none``).

Each run's ``rms_offset_fitted_*`` also gives the RMS error with the offset that suits the run
best: the part of the error that no choice of offset removes.

Each run is also simulated at half the fit's step (:mod:`smafinger.step_check`): its
``step_check`` says whether the model at this set has converged at that step, since a fit to a
trajectory that has not would fit the step's error too (:func:`step_notes`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Sequence

import numpy as np

from ..engine.batch import iter_batch
from ..parameters import ParameterSet
from ..step_check import StepCheck, compare, half_step, samples_per_sample
from .actuator_eval import coordinate_signal
from .bench_runs import MIN_NOISE_SAMPLES, BenchRun, coordinate_column, output_si_name
from .fit_uncertainty import lag1_autocorrelation

#: SI output -> (factor to display units, display unit, axis label)
DISPLAY = {"position_m": (1e3, "mm", "Position"), "theta_rad": (180.0 / math.pi, "deg", "Angle")}
OFFSET_POLICIES = ("per-run", "none")
#: warn when the fitted runs' RMS exceeds their baseline noise by this factor
MISFIT_WARN = 1.5
#: with no noise measured, warn when a fitted run's residuals have a lag-1 autocorrelation above
#: this: a slow curve, not noise (rho of white noise is near 0; a smooth misfit sampled densely
#: is near 1, and its sum of squares says nothing by itself about the sensor)
RHO_MISFIT = 0.9


def unit_suffix(p: ParameterSet) -> str:
    """The SI unit of the set's output, as report keys end (``m`` or ``rad``)."""
    return output_si_name(p).rsplit("_", 1)[-1]


@dataclass(frozen=True)
class RunPrediction:
    """One run simulated with a set and compared with what was measured (SI).

    ``model`` is the simulated output at the sample times, ``curve`` (times, values) on the
    simulation grid; both ``None`` and ``error`` set when the simulation failed.
    """

    run: BenchRun
    offset: float
    offset_method: str
    offset_stderr: float | None
    model: np.ndarray | None
    curve: tuple[np.ndarray, np.ndarray] | None
    error: str | None = None
    #: the run against the same run at half the step (None where either failed)
    step: StepCheck | None = None
    #: why the run at half the step failed (None: it did not, or it was not made)
    step_error: str | None = None

    @property
    def residuals(self) -> np.ndarray | None:
        """Simulated + offset - measured, at the sample times."""
        if self.model is None:
            return None
        return self.model + self.offset - self.run.samples.values

    def stats(self) -> dict[str, float | None]:
        r = self.residuals
        if r is None:
            return {"rms": None, "max_abs": None, "rms_offset_fitted": None, "lag1": None}
        centred = r - r.mean()
        return {"rms": float(np.sqrt(np.mean(r**2))), "max_abs": float(np.max(np.abs(r))),
                "rms_offset_fitted": float(np.sqrt(np.mean(centred**2))), "lag1": lag1_autocorrelation(r)}


def _signal_and_substeps(result, column: str) -> tuple[np.ndarray, int]:
    """The batch workers' ``reduce`` of a run at half the step: its coordinate and its sub-step
    count (the check's refinement, :mod:`smafinger.step_check`)."""
    return coordinate_signal(result, column), int(result.substeps)


def predict_runs(runs: Sequence[BenchRun], p: ParameterSet, pool, fitted_offsets: dict[str, tuple[float, float]]
                 | None = None, policy: str = "per-run", dt_s: float = 1e-3) -> list[RunPrediction]:
    """Simulate every run with ``p`` (one batch) and set its offset (see the module docstring).

    ``fitted_offsets``: file -> (offset, stderr) of the fitted runs.
    """
    if policy not in OFFSET_POLICIES:
        raise ValueError(f"offset policy {policy!r} is not one of {', '.join(OFFSET_POLICIES)}")
    fitted_offsets = fitted_offsets or {}
    column = coordinate_column(p)
    specs, failed = {}, {}
    for k, run in enumerate(runs):
        try:
            specs[k] = run.spec(p, dt_s)
        except ValueError as exc:
            failed[k] = f"{type(exc).__name__}: {exc}"
    keys = list(specs)
    halves = {k: half_step(specs[k]) for k in keys}  # in the same batch: one pass over the pool
    curves: dict[int, tuple[np.ndarray, int]] = {}
    checks: dict[int, tuple[np.ndarray, int]] = {}
    check_failed: dict[int, str] = {}
    for j, ok, value in iter_batch([specs[k] for k in keys] + [halves[k] for k in keys], pool=pool,
                                   reduce=partial(_signal_and_substeps, column=column), record="metrics"):
        k = keys[j % len(keys)]
        if j < len(keys):
            if ok:
                curves[k] = value
            else:
                failed[k] = f"{type(value).__name__}: {value}"
        elif ok:
            checks[k] = value
        else:
            check_failed[k] = f"{type(value).__name__}: {value}"
    out = []
    for k, run in enumerate(runs):
        if policy == "none":
            offset, method, se = 0.0, "none", None
        elif run.file in fitted_offsets and run.role == "fit":
            (offset, se), method = fitted_offsets[run.file], "fitted"
        else:
            offset, method, se = run.baseline_offset(p), "baseline", None
        if k in failed:
            out.append(RunPrediction(run, offset, method, se, None, None, failed[k]))
            continue
        y, substeps = curves[k]
        grid = np.round(np.arange(y.size) * run.output_interval_s, 9)
        step = None
        if k in checks:
            y_check, check_substeps = checks[k]
            step = compare(specs[k], grid, y, y_check[::samples_per_sample(specs[k], halves[k])], halves[k].dt_s,
                           substeps, check_substeps)
        out.append(RunPrediction(run, offset, method, se, run.model_output(y, p), (grid, y / p.coordinate.scale),
                                 step=step, step_error=check_failed.get(k)))
    return out


def _label(pr: RunPrediction) -> str:
    """A run's name and what it is in the command (``fit``, ``validate``, ``replay``)."""
    return f"{Path(pr.run.file).name} ({'replay' if pr.run.mode == 'closed-loop' else pr.run.role})"


def step_notes(predictions: Sequence[RunPrediction], p: ParameterSet, fitted: bool) -> list[str]:
    """A note naming the runs whose model at ``p`` has not converged at the step they were
    simulated at (their error, estimated from the run at half the step, over the coordinate's
    accuracy budget), and one naming those whose run at half the step failed, with why.
    ``fitted``: ``p`` is a fit's (whose values then absorb the error of the fitted runs among
    them)."""
    notes = []
    over = [pr for pr in predictions if pr.step is not None and pr.step.within is False]
    if over:
        factor, unit, _ = DISPLAY[output_si_name(p)]
        shown = factor / p.coordinate.scale  # the check's user unit -> the display unit

        def err(x: float) -> str:
            return f"{shown * x:.3g} {unit}"

        c = over[0].step
        runs = "; ".join(f"{_label(pr)}: {err(pr.step.estimated_rms)} RMS, {err(pr.step.estimated_max)} max"
                         for pr in over)
        tail = ""
        if fitted and any(pr.run.role == "fit" for pr in over):
            tail = "; the fitted values absorb that error too"
        if any(pr.run.mode == "closed-loop" for pr in over):
            tail += ("; a closed loop can amplify differences below any step's error, so a replay's error is "
                     "one run's, not converged (docs/speed.md)")
        notes.append(f"the model at this set has not converged at the {'fit' if fitted else 'run'}'s step "
                     f"(dt_s = {c.dt_s:g}): its error, estimated at {c.factor:.3g}x its difference from the same run "
                     f"at half the step, is over the budget ({err(c.budget_rms)} RMS, {err(c.budget_max)} max) on "
                     f"{runs}{tail}")
    unjudged = [pr for pr in predictions if pr.step is not None and not pr.step.judged]
    if unjudged:
        notes.append("the step check could not judge " + ", ".join(_label(pr) for pr in unjudged) + ": at half the "
                     "step their sub-steps hardly shrank (the PWM edges and the output samples set them)")
    lost = [pr for pr in predictions if pr.step_error is not None]
    if lost:
        notes.append("the run at half the step failed, so the step was not checked, on "
                     + "; ".join(f"{_label(pr)}: {pr.step_error}" for pr in lost))
    return notes


def files_report(predictions: Sequence[RunPrediction], p: ParameterSet,
                 figures: dict[str, str] | None = None) -> list[dict]:
    """The report's ``files``: per run its file, role, mode, errors, offset and figure."""
    u = unit_suffix(p)
    figures = figures or {}
    rows = []
    for pr in predictions:
        st = pr.stats()
        row = {"file": pr.run.file, "role": pr.run.role, "mode": pr.run.mode, "n_samples": pr.run.n_samples,
               f"rms_{u}": st["rms"], f"max_abs_{u}": st["max_abs"], f"offset_{u}": pr.offset,
               "offset_method": pr.offset_method, f"offset_stderr_{u}": pr.offset_stderr,
               f"rms_offset_fitted_{u}": st["rms_offset_fitted"], "lag1_autocorrelation": st["lag1"],
               "baseline_samples": int(pr.run.baseline.sum()), f"noise_{u}": pr.run.baseline_noise(),
               "figure": figures.get(pr.run.file)}
        if pr.run.mode == "closed-loop":
            row[f"reference_offset_{u}"] = pr.run.reference_offset
        if pr.step is not None:
            row["step_check"] = pr.step.to_dict()
        elif pr.step_error is not None:
            row["step_check"] = {"error": pr.step_error}
        if pr.error:
            row["error"] = pr.error
        rows.append(row)
    return rows


#: the report's summary groups: name -> (role, mode) of its runs
SUMMARY_GROUPS = {"fit": ("fit", "open-loop"), "validate": ("validate", "open-loop"),
                  "replay": ("validate", "closed-loop")}


def role_summary(predictions: Sequence[RunPrediction], p: ParameterSet) -> dict:
    """RMS and largest error over all samples of the fitted runs (``fit``), the held-out
    open-loop runs (``validate``) and the closed-loop replays (``replay``), with the sensor noise
    measured on their baselines (pooled) and the ratio: near 1 the runs are predicted to the noise
    level; well above, the model misses something (or the fit a better minimum)."""
    u = unit_suffix(p)
    out = {}
    for group, (role, mode) in SUMMARY_GROUPS.items():
        members = [pr for pr in predictions if (pr.run.role, pr.run.mode) == (role, mode)]
        if not members:
            continue
        if any(pr.residuals is None for pr in members):
            out[group] = {f"rms_{u}": None, f"max_abs_{u}": None, "failed": True}
            continue
        r = np.concatenate([pr.residuals for pr in members])
        rms = float(np.sqrt(np.mean(r**2)))
        noise = [x for x in (pr.run.baseline_noise() for pr in members) if x is not None]
        pooled = float(np.sqrt(np.mean(np.square(noise)))) if noise else None
        out[group] = {f"rms_{u}": rms, f"max_abs_{u}": float(np.max(np.abs(r))), "n_runs": len(members),
                      "n_samples": int(r.size), f"noise_{u}": pooled,
                      "rms_over_noise": rms / pooled if pooled else None}
    return out


def misfit_notes(predictions: Sequence[RunPrediction], p: ParameterSet) -> list[str]:
    """Whether the fitted runs are predicted to their noise: the report's and the console's notes.

    With a baseline noise measured (:func:`role_summary`), the RMS is judged against it
    (:data:`MISFIT_WARN`). Without (no fitted run has :data:`~.bench_runs.MIN_NOISE_SAMPLES`
    samples at rest before its drive, or those read one value: a quantized sensor, noise 0),
    that is said, and the residuals' shape judges instead:
    a fitted run whose residuals have a lag-1 autocorrelation above :data:`RHO_MISFIT` is a
    curve the model misses, not noise. (With a noise measured, rho is not used: a sensor's own
    filtering also makes its noise slow.)
    """
    fit = role_summary(predictions, p).get("fit")
    if not fit or fit.get("failed"):
        return []
    factor, unit, _ = DISPLAY[output_si_name(p)]
    advice = "a local minimum (try a larger --budget or another --seed) or a model error"
    ratio = fit["rms_over_noise"]
    if ratio is not None:
        return [f"the fitted runs' RMS is {ratio:.2g} times the sensor noise measured before the drive: "
                f"{advice}"] if ratio > MISFIT_WARN else []
    rms = f"the fitted runs' RMS ({factor * fit[f'rms_{unit_suffix(p)}']:.4g} {unit}) could not be judged against the "
    if fit[f"noise_{unit_suffix(p)}"] is None:
        notes = [rms + f"sensor noise: no fitted run has {MIN_NOISE_SAMPLES} or more samples at rest before its drive "
                 "turns on, which measure it (record half a second before switching the drive on)"]
    else:  # measured, and 0: a quantized sensor reading one count at rest (found by review)
        notes = [rms + "sensor noise: the samples at rest before the drive show none (a quantized sensor, reading "
                 "one count)"]
    rho = [(Path(pr.run.file).name, pr.stats()["lag1"]) for pr in predictions
           if (pr.run.role, pr.run.mode) == SUMMARY_GROUPS["fit"]]
    slow = [f"{r:.3g} on {name}" for name, r in rho if r > RHO_MISFIT]
    if slow:
        notes.append(f"the fitted runs' residuals are a slow curve, not noise (lag-1 autocorrelation "
                     f"{', '.join(slow)}; above {RHO_MISFIT:g}): the model misses the data: {advice}")
    return notes


def figure_names(predictions: Sequence[RunPrediction], suffix: str = ".png") -> dict[str, str]:
    """A figure file name per run: its file's stem, made unique with ``-2``, ``-3``..."""
    names, used = {}, set()
    for pr in predictions:
        stem = Path(pr.run.file).stem
        name, k = f"{stem}{suffix}", 1
        while name in used:
            k += 1
            name = f"{stem}-{k}{suffix}"
        used.add(name)
        names[pr.run.file] = name
    return names


def run_figure(pr: RunPrediction, p: ParameterSet):
    """Measured against predicted (sensor frame), the error, and the drive or reference."""
    from ..plotting import _mpl

    plt = _mpl()
    factor, unit, label = DISPLAY[output_si_name(p)]
    run, s = pr.run, pr.run.samples
    fig, ax = plt.subplots(3, 1, figsize=(7.5, 7.0), sharex=True, constrained_layout=True,
                           gridspec_kw={"height_ratios": [3, 1.3, 1.3]})
    ax[0].plot(s.t_s, factor * s.values, ".", ms=2.0, color="0.45", label="measured")
    if pr.curve is not None:
        t, y = pr.curve
        ax[0].plot(t, factor * (y + pr.offset), color="tab:red", lw=1.2, label=f"predicted (offset {pr.offset_method})")
        ax[1].plot(s.t_s, factor * pr.residuals, color="tab:red", lw=0.8)
    ax[0].set_ylabel(f"{label} [{unit}]")
    ax[0].legend(loc="best", fontsize=8)
    ax[1].axhline(0.0, color="0.6", lw=0.6)
    ax[1].set_ylabel(f"error [{unit}]")
    if run.mode == "closed-loop":
        t_ref, v_ref = run.reference
        ax[0].step(t_ref, factor * v_ref, where="post", color="tab:blue", lw=0.9, ls="--", label="reference")
        ax[0].legend(loc="best", fontsize=8)
    inp = run.recording.input
    ax[2].step(inp.t_s, inp.values, where="post", color="tab:green", lw=0.8)
    ax[2].set_ylabel(f"{inp.name} (recorded)")
    ax[2].set_xlabel("Time [s]")
    for a in ax:
        a.grid(True, alpha=0.3)
    st = pr.stats()
    rms = "failed" if st["rms"] is None else f"RMS {factor * st['rms']:.3g} {unit}"
    fig.suptitle(f"{Path(run.file).name}: {run.role}, {run.mode}, {rms}", fontsize=10)
    return fig
