"""A parsed sweep: its points (generated lazily, block by block), its run template, run ids.

The points are never listed all at once: :meth:`SweepSpec.size` is arithmetic, and
:class:`PointSource` makes the varied values of any block of points on demand (a grid point
from its index, a random sample by advancing the generator, Latin-hypercube samples from
their matrix). :class:`SweepTemplate` holds everything shared by the runs, resolved once
(parameter sets and files included, so that remote workers need no file of this machine);
:class:`PointRecipe` is one run as it travels to a worker, which builds and validates its
:class:`~smafinger.engine.run.RunSpec` there.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..engine.defaults import DEFAULT_PWM, DEFAULT_TOL_M
from ..engine.run import RunSpec, make_spec
from ..parameters import ParameterError, ParameterSet, resolve
from ..profiles import ProfileError

#: bump when the meaning of a run's canonical spec (and so of run_id) changes
RUN_ID_SCHEMA = 1
MODES = ("grid", "list", "random", "lhs")
#: run settings (make_spec arguments) that a sweep may set in [base] or vary
RUN_KEYS = {
    "params": str, "strategy": str, "profile": str, "voltage": str, "t_end_s": float,
    "dt_s": float, "method": str, "output_interval_s": float, "tol_deg": float,
    "hold_s": float, "independent_wait": bool, "pwm": str, "drive": str, "tol_m": float,
}
#: sweeps with more runs are refused before anything is made (``--max-runs`` raises it)
DEFAULT_MAX_RUNS = 1_000_000
#: errors that make a point invalid (a refusal naming the point), not a failed run
SPEC_ERRORS = (ParameterError, ProfileError, ValueError, TypeError)


class SweepSpecError(ValueError):
    """The sweep spec is malformed; the message names the field and the value."""


@dataclass(frozen=True)
class Vary:
    """One varied name: the fields it sets and its values (or its range, for sampling)."""

    name: str
    fields: tuple[str, ...]
    values: tuple | None = None
    low: float | None = None
    high: float | None = None
    log: bool = False


@dataclass(frozen=True)
class Run:
    point: int
    run_id: str
    values: dict
    spec: RunSpec


# ---------------------------------------------------------------------------------------
# run identity
# ---------------------------------------------------------------------------------------
def canonical_run(spec: RunSpec) -> dict:
    """Everything that decides a run's outcome, as plain JSON-ready values."""
    v = spec.voltage
    return {
        "schema": RUN_ID_SCHEMA,
        "params": spec.params.to_dict(),
        "strategy": spec.strategy,
        "profile": spec.profile.to_text(),
        # any number of wires; for two wires the text (and so every joint run id) is unchanged
        "voltage": None if v is None else ",".join(":".join(repr(x) for x in step) for step in v.steps),
        "t_end_s": spec.t_end_s, "dt_s": spec.dt_s, "method": spec.method,
        "output_interval_s": spec.output_interval_s, "tol_deg": spec.tol_deg,
        "hold_s": spec.hold_s, "independent_wait": spec.independent_wait,
        # the PWM model, the drive's kind and the linear tolerance only when they are not the
        # defaults: the run ids of earlier sweeps stay valid
        **({} if spec.pwm == DEFAULT_PWM else {"pwm": spec.pwm}),
        **({} if v is None or v.kind == "voltage" else {"drive": v.kind}),
        **({} if spec.tol_m == DEFAULT_TOL_M else {"tol_m": spec.tol_m}),
    }


def run_id(spec: RunSpec) -> str:
    """16 hex digits of the SHA-256 of the run's canonical spec."""
    text = json.dumps(canonical_run(spec), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


# ---------------------------------------------------------------------------------------
# the template and the recipes
# ---------------------------------------------------------------------------------------
def params_ref(value, base_dir: Path):
    """A parameter-set name, or a .toml path resolved relative to the spec's folder."""
    if isinstance(value, ParameterSet):
        return value
    s = str(value)
    if s.endswith(".toml") and not Path(s).is_absolute():
        cand = base_dir / s
        if cand.exists():
            return str(cand)
    return s


def scenario_spec(name: str) -> RunSpec:
    try:
        from .. import scenarios  # optional module (another part of the project)
    except ImportError:
        raise SweepSpecError(f"[base] scenario = {name!r}: this version of smafinger has no scenarios; "
                             "give params/strategy/profile/voltage instead") from None
    got = scenarios.get(name)
    if isinstance(got, RunSpec):
        return got
    if isinstance(got, dict):
        return make_spec(**got)
    spec = getattr(got, "spec", None)
    if isinstance(spec, RunSpec):
        return spec
    if callable(spec):
        return spec()
    raise SweepSpecError(f"[base] scenario = {name!r}: cannot turn {type(got).__name__} into a run spec")


@dataclass(frozen=True)
class SweepTemplate:
    """What every run of a sweep shares, resolved once in the client (picklable).

    ``run_kw``: the :func:`make_spec` arguments of ``[base]`` (or its scenario) except the
    parameter set; ``params``: the base set with ``[base] set`` applied; ``choices``: for a
    varied ``params``, each named set (with ``set`` applied) or the error resolving it.
    """

    run_kw: dict
    params: Any
    vary: tuple[tuple[str, tuple[str, ...]], ...]
    choices: dict = field(default_factory=dict)

    def build(self, values: dict) -> RunSpec:
        """The validated spec of the point with these varied values (raises on a bad point)."""
        run_kw = dict(self.run_kw)
        params = self.params
        changes = {}
        for name, fields in self.vary:
            x = values[name]
            for f in fields:
                if f == "params":
                    params = self.choices[x]
                elif f in RUN_KEYS:
                    run_kw[f] = x
                else:
                    changes[f] = x
        if isinstance(params, Exception):
            raise params
        if changes:
            params = params.replace(**changes)
        return make_spec(params=params, **run_kw)


@dataclass(frozen=True)
class PointRecipe:
    """One run as it travels to a worker: the shared template and this point's values."""

    template: SweepTemplate
    values: dict

    def build(self) -> RunSpec:
        return self.template.build(self.values)


# ---------------------------------------------------------------------------------------
# points
# ---------------------------------------------------------------------------------------
def _unit_samples(mode: str, n: int, d: int, seed: int | None) -> np.ndarray:
    if mode == "random":
        return np.random.default_rng(seed).random((n, d))
    from scipy.stats import qmc

    try:
        sampler = qmc.LatinHypercube(d=d, rng=seed)
    except TypeError:  # scipy < 1.15
        sampler = qmc.LatinHypercube(d=d, seed=seed)
    return sampler.random(n)


class PointSource:
    """The varied values of any block of a sweep's points, made on demand.

    Grid and list points come from their index; random samples from the seeded generator
    advanced to the block (the same numbers as drawing all at once); Latin-hypercube
    samples need every stratum at once, so their unit matrix (8 bytes per value) is made
    once here.
    """

    def __init__(self, spec: "SweepSpec"):
        self.spec = spec
        self.n = spec.size()
        self.names = [v.name for v in spec.vary]
        self._lhs = (_unit_samples("lhs", spec.samples, len(spec.vary), spec.seed)
                     if spec.mode == "lhs" else None)

    def block(self, start: int, stop: int) -> dict[str, list]:
        """``{name: [value of point start, ..., value of point stop - 1]}`` (Python scalars)."""
        s, vary = self.spec, self.spec.vary
        stop = min(stop, self.n)
        idx = np.arange(start, stop)
        if s.mode == "grid":
            pos = np.unravel_index(idx, tuple(len(v.values) for v in vary)) if len(idx) else [idx] * len(vary)
            return {v.name: [v.values[k] for k in p.tolist()] for v, p in zip(vary, pos)}
        if s.mode == "list":
            return {v.name: list(v.values[start:stop]) for v in vary}
        d = len(vary)
        if s.mode == "random":
            rng = np.random.default_rng(s.seed)
            rng.bit_generator.advance(start * d)
            u = rng.random((len(idx), d))
        else:
            u = self._lhs[start:stop]
        out = {}
        for j, v in enumerate(vary):
            if v.log:
                x = np.exp(np.log(v.low) + u[:, j] * (np.log(v.high) - np.log(v.low)))
            else:
                x = v.low + u[:, j] * (v.high - v.low)
            out[v.name] = x.tolist()
        return out

    def blocks(self, size: int, start: int = 0):
        """``(start, values)`` of consecutive blocks of ``size`` points."""
        for a in range(start, self.n, size):
            yield a, self.block(a, a + size)


# ---------------------------------------------------------------------------------------
# the spec
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SweepSpec:
    base: dict
    vary: tuple[Vary, ...]
    mode: str = "grid"
    samples: int | None = None
    seed: int | None = None
    chunk_size: int | None = None
    traces_interval_s: float = 0.1
    name: str = "sweep"
    source: str = "<dict>"
    base_dir: Path = field(default=Path("."), compare=False)
    save_interval_s: float = 1.0
    #: every run also at half its step (:mod:`smafinger.step_check`): its ``step_error_*`` columns
    check_step: bool = False

    def size(self) -> int:
        """How many runs, computed without making any point."""
        if self.mode == "grid":
            return int(np.prod([len(v.values) for v in self.vary], dtype=object))
        if self.mode == "list":
            return len(self.vary[0].values)
        return int(self.samples)

    def point_source(self) -> PointSource:
        return PointSource(self)

    def points(self) -> list[dict[str, Any]]:
        """The varied values of every point, in sweep order (all in memory: small sweeps)."""
        cols = self.point_source().block(0, self.size())
        names = list(cols)
        return [dict(zip(names, row)) for row in zip(*(cols[n] for n in names))]

    def template(self) -> SweepTemplate:
        """The runs' shared settings, resolved once (raises :class:`SweepSpecError`)."""
        b = self.base
        run_kw = {k: v for k, v in b.items() if k in RUN_KEYS and k != "params"}
        fixed = b.get("set") or {}
        try:
            if "scenario" in b:
                spec = scenario_spec(b["scenario"])
                kw = {f.name: getattr(spec, f.name) for f in dataclasses.fields(spec)}
                params = kw.pop("params")
                if "params" in b:
                    params = resolve(params_ref(b["params"], self.base_dir))
                run_kw = {**kw, **run_kw}
            else:
                params = resolve(params_ref(b.get("params", "paper2010"), self.base_dir))
            params = params.replace(**fixed) if fixed else params
        except ParameterError as exc:
            raise SweepSpecError(f"{self.source}: [base] {exc}") from None
        choices = {}
        for v in self.vary:
            if "params" in v.fields:
                for x in v.values:
                    try:
                        p = resolve(params_ref(x, self.base_dir))
                        choices[x] = p.replace(**fixed) if fixed else p
                    except SPEC_ERRORS as exc:
                        choices[x] = exc
        return SweepTemplate(run_kw, params, tuple((v.name, v.fields) for v in self.vary), choices)

    def point_error(self, point: int, values: dict, exc: BaseException) -> SweepSpecError:
        shown = ", ".join(f"{k} = {v!r}" for k, v in values.items())
        return SweepSpecError(f"{self.source}: point {point} ({shown}): {exc}")

    def duplicate_error(self, first: int, second: int, values: dict) -> SweepSpecError:
        shown = ", ".join(f"{k} = {v!r}" for k, v in values.items())
        return SweepSpecError(f"{self.source}: points {first} and {second} are the same run ({shown}); "
                              "remove the duplicate value")

    def runs(self) -> list[Run]:
        """Every run, validated, in this process (raises :class:`SweepSpecError` naming the
        point). Holds every spec in memory: for small sweeps and tests; :func:`run_sweep`
        validates in the workers instead."""
        template = self.template()
        runs, seen = [], {}
        for i, values in enumerate(self.points()):
            try:
                spec = template.build(values)
            except SPEC_ERRORS as exc:
                raise self.point_error(i, values, exc) from None
            rid = run_id(spec)
            if rid in seen:
                raise self.duplicate_error(seen[rid], i, values)
            seen[rid] = i
            runs.append(Run(i, rid, values, spec))
        return runs

    def canonical(self) -> dict:
        """A JSON-ready description of the sweep (stored in the table's metadata)."""
        return {
            "name": self.name, "mode": self.mode, "samples": self.samples, "seed": self.seed,
            "base": {k: v for k, v in self.base.items()},
            "vary": [{"name": v.name, "fields": list(v.fields),
                      "values": list(v.values) if v.values is not None else None,
                      "min": v.low, "max": v.high, "log": v.log} for v in self.vary],
            # only when on: the canonical form of a sweep without it (its table's metadata) is as before
            **({"check_step": True} if self.check_step else {}),
        }
