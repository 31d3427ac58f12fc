"""The fit's objective: every run simulated with a candidate set, on the batch engine.

For a point u of the unit box (:class:`~.free_params.FreeBox`) each fitted run is simulated
(:func:`~smafinger.engine.batch.iter_batch`: in this process, in local worker processes or on
a Dask cluster; all the runs of all the candidates of a generation or of a Jacobian go out as one
batch) and compared at its measured sample times.

Sensor offsets. With ``fit_offsets`` each run's measured output is its coordinate plus an
unknown constant c_k. For given physical parameters the best c_k is the mean of the run's
measured-minus-model values, so the offsets are *profiled out* (variable projection): the
residuals are centred per run and the optimisers see only the physical parameters. The
Jacobian of the centred residuals is the raw Jacobian centred per run, which is exactly what
differences of centred residuals give.

A candidate whose run fails (a refused set, a numerical blow-up) gets a residual of
:data:`BAD_RESIDUAL` at every sample of that run, far above any real misfit.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import Callable, Sequence

import numpy as np

from ..engine.batch import iter_batch
from ..engine.run import DEFAULT_DT_S
from ..parameters import ParameterError, ParameterSet
from ..profiles import ProfileError
from .bench_runs import BenchRun, coordinate_column
from .free_params import FreeBox

#: residual of every sample of a run that failed [m or rad]
BAD_RESIDUAL = 1.0


def coordinate_signal(result, column: str) -> np.ndarray:
    """The batch workers' ``reduce``: only the coordinate column travels back (one of the signals
    a run made with ``record="metrics"`` has, which is how the fit runs them)."""
    return np.asarray(result.signal(column), dtype=np.float64)


@dataclass(frozen=True)
class Evaluation:
    """The runs simulated at one point: model outputs (SI, at the sample times; ``None`` where
    the run failed), the offsets and the stacked residuals (model + offset - measured)."""

    model: tuple[np.ndarray | None, ...]
    offsets: np.ndarray
    residuals: np.ndarray
    failures: tuple[str, ...]

    @property
    def sse(self) -> float:
        return float(self.residuals @ self.residuals)


class Evaluator:
    """Simulates the fitted runs at points of the unit box, caching what it has computed.

    Parameters
    ----------
    runs : sequence of BenchRun
    box : FreeBox
    pool : a pool of :func:`smafinger.engine.batch.make_pool`
    fit_offsets : bool
        Profile a sensor offset per run (see the module docstring).
    dt_s : float
        Integration step.
    on_sim : callable, optional
        Called with the number of simulations done so far, after each.
    """

    def __init__(self, runs: Sequence[BenchRun], box: FreeBox, pool, fit_offsets: bool = True,
                 dt_s: float = DEFAULT_DT_S, on_sim: Callable[[int], None] | None = None):
        self.runs, self.box, self.pool = tuple(runs), box, pool
        if not self.runs:  # numpy's concatenate said so (found by an API fuzz)
            raise ValueError("no run to fit: give one bench run at least")
        self.fit_offsets, self.dt_s, self.on_sim = fit_offsets, dt_s, on_sim
        self.column = coordinate_column(box.base)
        sizes = [r.n_samples for r in self.runs]
        edges = np.concatenate([[0], np.cumsum(sizes)])
        self.slices = tuple(slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]))
        self.data = np.concatenate([r.samples.values for r in self.runs])
        self.n_sims = 0
        self._cache: dict[bytes, Evaluation] = {}

    @property
    def n_residuals(self) -> int:
        return int(self.data.size)

    def evaluate(self, points: Sequence[np.ndarray]) -> list[Evaluation]:
        """The :class:`Evaluation` at each point (simulating only those not cached)."""
        pts = [np.clip(np.asarray(u, dtype=np.float64), 0.0, 1.0) for u in points]
        todo = []
        for u in pts:
            key = u.tobytes()
            if key not in self._cache and all(key != k for k, _ in todo):
                todo.append((key, u))
        for (key, _), ev in zip(todo, self._simulate([u for _, u in todo])):
            self._cache[key] = ev
        return [self._cache[u.tobytes()] for u in pts]

    def sse(self, points: Sequence[np.ndarray]) -> np.ndarray:
        return np.array([e.sse for e in self.evaluate(points)])

    def _simulate(self, points: list[np.ndarray]) -> list[Evaluation]:
        if not points:
            return []
        sets: list[ParameterSet | None] = []
        errors: dict[int, str] = {}
        items = []
        for i, u in enumerate(points):
            try:
                p = self.box.params(u)
                specs = [run.spec(p, self.dt_s) for run in self.runs]
            except (ParameterError, ProfileError, ValueError) as exc:
                sets.append(None)
                errors[i] = f"{type(exc).__name__}: {exc}"
                continue
            sets.append(p)
            items += [((i, k), spec) for k, spec in enumerate(specs)]
        outputs: dict[tuple[int, int], np.ndarray | Exception] = {}
        reduce = partial(coordinate_signal, column=self.column)
        keys = [key for key, _ in items]
        for j, ok, value in iter_batch([spec for _, spec in items], pool=self.pool, reduce=reduce, record="metrics"):
            outputs[keys[j]] = value
            self.n_sims += 1
            if self.on_sim is not None:
                self.on_sim(self.n_sims)
        return [self._assemble(i, sets[i], outputs, errors.get(i)) for i in range(len(points))]

    def _assemble(self, i: int, p: ParameterSet | None, outputs: dict, error: str | None) -> Evaluation:
        model, failures = [], []
        for k, run in enumerate(self.runs):
            value = outputs.get((i, k)) if p is not None else None
            if p is None or isinstance(value, Exception) or value is None:
                model.append(None)
                failures.append(f"{run.file}: {error or f'{type(value).__name__}: {value}'}")
                continue
            y = run.model_output(value, p)
            model.append(y if np.isfinite(y).all() else None)
            if model[-1] is None:
                failures.append(f"{run.file}: non-finite output")
        offsets, residuals = self.residuals(model)
        return Evaluation(tuple(model), offsets, residuals, tuple(failures))

    def residuals(self, model: Sequence[np.ndarray | None]) -> tuple[np.ndarray, np.ndarray]:
        """(offsets, stacked residuals) for model outputs of every run (``None``: failed)."""
        offsets = np.zeros(len(self.runs))
        res = np.empty(self.n_residuals)
        for k, (y, sl) in enumerate(zip(model, self.slices)):
            if y is None:
                res[sl] = BAD_RESIDUAL
                continue
            if self.fit_offsets:
                offsets[k] = float(np.mean(self.data[sl] - y))
            res[sl] = y + offsets[k] - self.data[sl]
        return offsets, res

    def model_jacobian(self, u: np.ndarray, step: float) -> tuple[np.ndarray, Evaluation]:
        """d(model outputs)/du at u by central differences of ``step`` in the unit box (one-sided
        at a bound), all 2n points simulated in one batch; and the evaluation at u."""
        u = np.asarray(u, dtype=np.float64)
        lows, highs = [], []
        for j in range(u.size):
            a, b = u.copy(), u.copy()
            a[j], b[j] = max(u[j] - step, 0.0), min(u[j] + step, 1.0)
            lows.append(a)
            highs.append(b)
        evals = self.evaluate([u] + lows + highs)
        centre, n = evals[0], u.size
        J = np.empty((self.n_residuals, n))
        for j in range(n):
            lo, hi = evals[1 + j], evals[1 + n + j]
            width = highs[j][j] - lows[j][j]
            for k, sl in enumerate(self.slices):
                a, b = lo.model[k], hi.model[k]
                J[sl, j] = 0.0 if (a is None or b is None) else (b - a) / width
        return J, centre

    def centred(self, J: np.ndarray) -> np.ndarray:
        """The Jacobian of the residuals with the offsets profiled out: J centred per run."""
        if not self.fit_offsets:
            return J
        out = J.copy()
        for sl in self.slices:
            out[sl] -= out[sl].mean(axis=0)
        return out
