"""The bench's plant for learned controllers: a step-by-step session and a Gymnasium environment.

:class:`PlantSession` advances the plant one control interval at a time with a duty per wire
(a fraction of the supply V_H, switched at the PWM period: the engine's ``duty`` drive
program, strategy ``open-loop``), and returns what the controllers of the bench may measure:
the coordinate and its rate (user unit), each wire's resistance and, if declared, its
temperature. The engine runs whole programs, so each step re-runs the program so far from
t = 0 (deterministic: the state after step k is bit-identical to one open-loop run of the same
k steps; the cost of an episode grows with the square of its length, about 10 s for 200
steps of 0.1 s on the joint).

:func:`make_env` wraps it as a ``gymnasium.Env`` (the optional extra:
``pip install 'smafinger[gym]'``): action: a duty per wire in [0, 1]; observation: the
measured signals and the target, in the order of :attr:`PlantSession.observation_names`;
reward: minus the tracking error |q - q_F| (user unit) times the interval, less
``heat_penalty`` per degC by which any wire exceeds ``max_T_C`` at the end of a step (per step,
not scaled by the interval) and ``interlock_penalty`` for a step whose action asks to heat two
opposing wires at once. The plant never does: the interlock of Sec. 2.6 (the engine refuses a
program that breaks it) drives only the wire with the larger duty, neither on a tie, and the
step is counted (:attr:`PlantSession.interlock_cuts`). An episode ends by its time limit, which
Gymnasium calls truncation (``truncated=True``, ``terminated=False``: the observation holds no
clock, so the last state is not terminal); stepping on continues the plant. A learned policy is
then compared on the same plant and tasks as the built-in controllers (docs/controllers.md).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..engine.run import make_spec, run_spec
from ..model.build import build_model
from ..parameters import ParameterSet
from ..parameters import get as get_params
from ..profiles import VoltageProgram
from ..values import is_real, one_or_many
from .runner import BENCH_NUMERICS


class PlantSession:
    """One episode of the plant, advanced a control interval at a time (see the module docstring)."""

    def __init__(self, params: str | ParameterSet = "paper2010", target: float | None = None,
                 control_interval_s: float = 0.1, episode_s: float = 20.0, temperature_sensors: bool = False,
                 overrides: tuple[str, ...] = ()):
        overrides = tuple(one_or_many(overrides))  # one string is a list of one
        if not all(isinstance(o, str) for o in overrides):
            raise ValueError(f"overrides = {overrides!r} must be a list of NAME=VALUE strings")
        if not isinstance(params, (str, ParameterSet)):
            raise TypeError(f"params = {params!r} is not a parameter set or a set's name")
        p = get_params(params) if isinstance(params, str) else params
        self.params = p.with_overrides(list(overrides)) if overrides else p
        from ..engine.numerics import damping_rate_per_s, damping_step_limit, unstable_step

        method, step = BENCH_NUMERICS["method"], BENCH_NUMERICS["dt_s"]
        why = unstable_step(self.params, method, step)
        if why is None and (limit := damping_step_limit(self.params, method)) is not None and step > limit:
            why = (f"this set's damping ({damping_rate_per_s(self.params):.4g} 1/s) holds {method} only up to "
                   f"dt = {limit * 1e3:.2g} ms: it would blow up")  # found by review: mid-episode, with no hint
        if why is not None:
            raise ValueError(f"params {self.params.name} with overrides {list(overrides)}: the plant runs at "
                             f"{method}, {step:g} s (not settable here): {why}")
        self.dt = _positive("control_interval_s", control_interval_s)
        if self.dt < BENCH_NUMERICS["dt_s"]:
            raise ValueError(f"control_interval_s = {control_interval_s!r} is shorter than the plant's step, "
                             f"{BENCH_NUMERICS['dt_s']} s")
        episode = _positive("episode_s", episode_s)
        self.n_steps = int(round(episode / self.dt))
        if self.n_steps < 1 or not math.isclose(self.n_steps * self.dt, episode, rel_tol=1e-9):
            raise ValueError(f"episode_s = {episode_s!r} is not a whole number of control intervals of "
                             f"{self.dt:g} s")
        c = self.params.coordinate
        if target is not None and not (is_real(target) and math.isfinite(target) and abs(target) <= c.limit):
            raise ValueError(f"target = {target!r} must be a finite number within +-{c.limit:g} {c.unit}")
        self.target = float(self.params.initial_target if target is None else target)
        if not isinstance(temperature_sensors, (bool, np.bool_)):
            raise ValueError(f"temperature_sensors = {temperature_sensors!r} must be True or False")
        self.temperature_sensors = bool(temperature_sensors)
        self.wires = tuple(self.params.wire_names)
        self._directions = tuple(w.direction for w in build_model(self.params).wires)
        self._q, self._v = f"{c.name}_{c.unit}", None
        self.steps: list[tuple[float, ...]] = []
        self.result = None
        self.interlock_cuts = 0  #: steps whose duties the interlock cut (two opposing wires asked)
        self.last_step_cut = False

    @property
    def observation_names(self) -> tuple[str, ...]:
        c = self.params.coordinate
        temps = tuple(f"T_{w}_C" for w in self.wires) if self.temperature_sensors else ()
        return (f"{c.name}_{c.unit}", f"rate_{c.unit}_s", *(f"R_{w}_ohm" for w in self.wires), *temps,
                f"target_{c.unit}")

    def reset(self) -> np.ndarray:
        self.steps, self.result = [], None
        self.interlock_cuts, self.last_step_cut = 0, False
        return self.observe()

    @property
    def t_s(self) -> float:
        return len(self.steps) * self.dt

    @property
    def done(self) -> bool:
        return len(self.steps) >= self.n_steps

    def step(self, duties) -> np.ndarray:
        """Apply ``duties`` (one per wire, each in [0, 1]) for one control interval."""
        d = np.asarray(duties, dtype=float).reshape(-1)
        if d.size != len(self.wires):
            raise ValueError(f"duties: {d.size} value(s) given, the mechanism has {len(self.wires)} wires "
                             f"({', '.join(self.wires)})")
        for w, x in zip(self.wires, d):
            if not (math.isfinite(x) and 0.0 <= x <= 1.0):
                raise ValueError(f"duty of wire {w} = {float(x)!r} must be in [0, 1]")
        applied, cut = self._interlocked(d)
        steps = (*self.steps, (self.t_s, *applied))
        spec = make_spec(self.params, "open-loop", voltage=VoltageProgram(steps, "duty"),
                         t_end_s=len(steps) * self.dt, output_interval_s=self.dt, **BENCH_NUMERICS)
        self.result = run_spec(spec)  # the session changes only once the step has run
        self.steps.append(steps[-1])
        self.last_step_cut = cut
        self.interlock_cuts += cut
        return self.observe()

    def _interlocked(self, d: np.ndarray) -> tuple[tuple[float, ...], bool]:
        """The duties the plant applies: where wires pulling both ways are asked to heat, only
        those of the direction with the larger duty (none on a tie); and whether that cut any."""
        push = max((x for x, k in zip(d, self._directions) if k > 0), default=0.0)
        pull = max((x for x, k in zip(d, self._directions) if k < 0), default=0.0)
        if push == 0.0 or pull == 0.0:
            return tuple(map(float, d)), False
        keep = 1.0 if push > pull else -1.0 if pull > push else 0.0
        return tuple(float(x) if k == keep else 0.0 for x, k in zip(d, self._directions)), True

    def signal(self, name: str) -> float:
        """The last sample of an output signal; before the first step, the initial state's (the
        first sample of any run, at zero duty; it raised AttributeError, found by an API fuzz)."""
        if self.result is None:
            return float(self._initial().signal(name)[0])
        return float(self.result.signal(name)[-1])

    def _initial(self):
        """A run of one control interval at zero duty, whose first sample is the initial state."""
        zero = VoltageProgram(((0.0,) + (0.0,) * len(self.wires),), "duty")
        return run_spec(make_spec(self.params, "open-loop", voltage=zero, t_end_s=self.dt,
                                  output_interval_s=self.dt, **BENCH_NUMERICS))

    def observe(self) -> np.ndarray:
        if self.result is None:  # the initial state: the first sample of any run (zero duty here)
            probe = self._initial()
            first = {n: float(probe.signal(n)[0]) for n in probe.column_names}
            get = first.__getitem__
            rate = 0.0
        else:
            get = self.signal
            rate = float(self.result.signal(self._rate_name())[-1])
        q = get(self._q)
        R = [get(f"R_{w}_ohm") for w in self.wires]
        T = [get(f"T_{w}_C") for w in self.wires] if self.temperature_sensors else []
        return np.array([q, rate, *R, *T, self.target], dtype=np.float64)

    def _rate_name(self) -> str:
        c = self.params.coordinate
        return next(n for n in self.result.column_names if n.endswith(f"_{c.unit}_s"))

    def hottest_T_C(self) -> float:
        """The hottest wire now [degC]."""
        return max(self.signal(f"T_{w}_C") for w in self.wires) if self.result is not None else -math.inf

    def interlock_violations(self) -> int:
        """The engine's count of drives of opposing wires at once (0: the session applies the
        interlock; :attr:`interlock_cuts` counts the steps whose action asked for it)."""
        return int(self.result.interlock_violations) if self.result is not None else 0


def _positive(name: str, v) -> float:
    if not (is_real(v) and math.isfinite(v) and v > 0):
        raise ValueError(f"{name} = {v!r} must be a finite number > 0")
    return float(v)


def _finite(name: str, v, low: float = -math.inf) -> float:
    if not (is_real(v) and math.isfinite(v) and v >= low):
        raise ValueError(f"{name} = {v!r} must be a finite number" + (f" >= {low:g}" if low > -math.inf else ""))
    return float(v)


def make_env(**kwargs: Any):
    """A ``gymnasium.Env`` around :class:`PlantSession` (keyword arguments: the session's, and
    ``max_T_C`` (default 110 degC), ``heat_penalty`` (1 per degC), ``interlock_penalty`` (1))."""
    try:
        import gymnasium
        from gymnasium import spaces
    except ImportError:
        raise ImportError("the Gymnasium environment needs the optional extra: pip install 'smafinger[gym]'") from None

    max_T = _finite("max_T_C", kwargs.pop("max_T_C", 110.0))
    heat_w = _finite("heat_penalty", kwargs.pop("heat_penalty", 1.0), 0.0)
    lock_w = _finite("interlock_penalty", kwargs.pop("interlock_penalty", 1.0), 0.0)

    class SMAPlantEnv(gymnasium.Env):
        metadata = {"render_modes": []}

        def __init__(self):
            self.session = PlantSession(**kwargs)
            n = len(self.session.wires)
            self.action_space = spaces.Box(0.0, 1.0, shape=(n,), dtype=np.float64)
            k = len(self.session.observation_names)
            self.observation_space = spaces.Box(-np.inf, np.inf, shape=(k,), dtype=np.float64)

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            return self.session.reset(), {"t_s": 0.0}

        def step(self, action):
            s = self.session
            obs = s.step(np.clip(np.asarray(action, dtype=float), 0.0, 1.0))
            reward = -abs(obs[0] - s.target) * s.dt
            reward -= heat_w * max(0.0, s.hottest_T_C() - max_T)
            reward -= lock_w * s.last_step_cut
            # the time limit: truncation, not a terminal state (module docstring)
            return obs, float(reward), False, s.done, {"t_s": s.t_s, "hottest_T_C": s.hottest_T_C(),
                                                       "interlock_cut": s.last_step_cut}

    return SMAPlantEnv()
