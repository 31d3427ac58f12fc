"""How a result was made: the run definition, exact, its hash, and the way back to the run.

Every output records :func:`provenance` (the summary JSON, a CSV's sidecar, Parquet schema
metadata, a MATLAB file's ``provenance`` struct, each row's run of a sweep table):

- ``smafinger_version``;
- ``run``: the run definition (:func:`run_definition`): the mechanism, every parameter and
  model option after overrides, the strategy, the target profile, the drive program (its
  kind and steps), ``t_end_s``, ``dt_s``, ``method``, ``pwm``, ``output_interval_s``, the tolerances,
  ``hold_s`` and ``independent_wait``. Numbers are written exactly (shortest round-trip
  form), never rounded;
- ``run_sha256``: the SHA-256 of the definition's canonical JSON (keys sorted, no spaces).

:func:`spec_from_definition` rebuilds the run (``smafinger simulate --from FILE``) and checks
that it has the same hash, so a re-run is the same run: its signal outputs are byte-identical.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

#: bump when the meaning of a run definition changes
SCHEMA = 1
#: provenance keys that describe the file's samples, not the run (``samples_every``: the file
#: keeps every n-th output sample); a re-run (``--from``) writes every sample and leaves them out
FILE_KEYS = ("samples_every",)
#: run definition keys, besides ``schema``, ``mechanism`` and ``parameters``
RUN_KEYS = ("strategy", "profile", "drive", "t_end_s", "dt_s", "method", "pwm", "output_interval_s", "tol_deg",
            "tol_m", "hold_s", "independent_wait")


class ProvenanceError(ValueError):
    """A run definition (or a file meant to hold one) cannot be turned back into a run."""


def program_text(program) -> str:
    """A drive program as its text form ``"T:V_1[:V_2],..."``, every number exact."""
    return ",".join(":".join(repr(float(x)) for x in step) for step in program.steps)


def run_definition(spec) -> dict[str, Any]:
    """Everything that decides a run's outcome, as exact JSON-ready values."""
    p, v = spec.params, spec.voltage
    return {
        "schema": SCHEMA,
        "mechanism": p.mechanism,
        "parameters": p.to_dict(),
        "strategy": spec.strategy,
        "profile": spec.profile.to_text(),
        "drive": None if v is None else {"kind": v.kind, "program": program_text(v)},
        "t_end_s": spec.t_end_s, "dt_s": spec.dt_s, "method": spec.method, "pwm": spec.pwm,
        "output_interval_s": spec.output_interval_s, "tol_deg": spec.tol_deg, "tol_m": spec.tol_m,
        "hold_s": spec.hold_s, "independent_wait": spec.independent_wait,
        # the closed-loop controller (control.params) by label and values; None: the paper's PWM-PID
        "controller": None if spec.controller is None else spec.controller.to_dict(),
    }


def definition_hash(definition: dict) -> str:
    """SHA-256 (hex) of a run definition's canonical JSON."""
    text = json.dumps(definition, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


def provenance(spec, **extra: Any) -> dict[str, Any]:
    """The provenance record of a run (see the module docstring); ``extra`` is added as is
    (e.g. ``scenario="fig12-extension-v1"``)."""
    from . import __version__

    definition = run_definition(spec)
    return {"smafinger_version": __version__, "run": definition, "run_sha256": definition_hash(definition),
            **extra}


def spec_from_definition(definition: Any, where: str = "run definition"):
    """The :class:`~smafinger.engine.run.RunSpec` of a run definition (checked: a wrong or
    missing field raises :class:`ProvenanceError` naming it)."""
    from .engine.run import make_spec
    from .parameters import ParameterError, from_dict

    if not isinstance(definition, dict):
        raise ProvenanceError(f"{where}: not a run definition (a JSON object)")
    if definition.get("schema") != SCHEMA:
        raise ProvenanceError(f"{where}: schema {definition.get('schema')!r} is not {SCHEMA} "
                              "(written by another version of smafinger)")
    missing = [k for k in ("mechanism", "parameters", *RUN_KEYS) if k not in definition]
    if missing:
        raise ProvenanceError(f"{where}: missing {', '.join(missing)}")
    params = definition["parameters"]
    if not isinstance(params, dict):
        raise ProvenanceError(f"{where}: parameters = {params!r} is not a table of values")
    drive = definition["drive"]
    if drive is not None and not (isinstance(drive, dict) and set(drive) == {"kind", "program"}):
        raise ProvenanceError(f"{where}: drive = {drive!r} is not {{kind, program}} or null")
    try:
        p = from_dict({"mechanism": definition["mechanism"], **params}, record=True)
        run = {k: definition[k] for k in RUN_KEYS if k != "drive"}
        for k in ("dt_s", "method", "pwm"):  # null would mean "the default", which may change
            if run[k] is None:
                raise ProvenanceError(f"{where}: {k} = null: a run definition names its numerics")
        from .engine.numerics import unstable_step

        if (why := unstable_step(p, run["method"], run["dt_s"], advice=False)) is not None:
            raise ProvenanceError(f"{where}: {why}, so the recorded run went unstable and its results are wrong "
                                  "(made before such steps were refused): simulate its parameters again, without "
                                  "--from, at the default step")
        return make_spec(p, voltage=None if drive is None else drive["program"],
                         drive="voltage" if drive is None else drive["kind"],
                         controller=_controller(definition.get("controller")), **run)
    except (ParameterError, ValueError, TypeError) as exc:
        raise ProvenanceError(f"{where}: {exc}") from None


def _controller(entry: Any):
    """The controller object of a definition's ``controller`` entry (None: the paper's PWM-PID)."""
    from .control.params import controller_from

    if entry is None:
        return None
    if not isinstance(entry, dict) or not isinstance(entry.get("controller"), str):
        raise ValueError(f"controller = {entry!r} is not {{controller: LABEL, ...values}} or null")
    values = {k: v for k, v in entry.items() if k != "controller"}
    return controller_from(entry["controller"]).replace(**values)


def spec_from_provenance(record: Any, where: str = "provenance"):
    """The run of a provenance record, checked against its hash (:class:`ProvenanceError` if
    the definition was edited or is not reproduced exactly)."""
    if not isinstance(record, dict) or "run" not in record:
        raise ProvenanceError(f"{where}: no run definition (expected a 'run' entry)")
    spec = spec_from_definition(record["run"], f"{where}: run")
    want = record.get("run_sha256")
    got = run_definition(spec)
    written = record["run"].get("controller") if isinstance(record["run"], dict) else None
    if isinstance(written, dict) and "calibration" not in written and isinstance(got["controller"], dict):
        # written before definitions held the resistance controller's calibration: it was made anew
        # for the set when the run was built, as it is again now
        got["controller"].pop("calibration", None)
    if want is not None and definition_hash(got) != want:
        raise ProvenanceError(f"{where}: the run rebuilt from its definition does not match run_sha256 "
                              f"{want} (the definition was edited, or made by another smafinger version)")
    return spec
