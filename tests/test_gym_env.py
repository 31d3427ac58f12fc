"""The step-by-step plant for learned controllers, and its Gymnasium wrapper (skipped without
the optional extra)."""

import numpy as np
import pytest

from smafinger.bench.gym_env import PlantSession, make_env
from smafinger.bench.runner import BENCH_NUMERICS
from smafinger.engine.run import make_spec, run_spec
from smafinger.profiles import VoltageProgram


def test_stepping_equals_one_open_loop_run_bit_for_bit():
    s = PlantSession("paper2010", target=-30.0, control_interval_s=0.2, episode_s=1.0)
    s.reset()
    duties = [(0.8, 0.0), (0.8, 0.0), (0.3, 0.0), (0.0, 0.5), (0.0, 0.0)]
    for d in duties:
        obs = s.step(d)
    assert s.done and s.t_s == pytest.approx(1.0)
    prog = VoltageProgram(tuple((0.2 * k, *d) for k, d in enumerate(duties)), "duty")
    # the plant runs at the bench's numerics (the reference ones), as the bench's controllers do
    r = run_spec(make_spec("paper2010", "open-loop", voltage=prog, t_end_s=1.0, output_interval_s=0.2,
                           **BENCH_NUMERICS))
    expected = [r.signal("theta_deg")[-1], r.signal("omega_deg_s")[-1], r.signal("R_upper_ohm")[-1],
                r.signal("R_lower_ohm")[-1], -30.0]
    np.testing.assert_array_equal(obs, np.array(expected))
    assert s.observation_names == ("theta_deg", "rate_deg_s", "R_upper_ohm", "R_lower_ohm", "target_deg")


def test_the_initial_observation_is_the_rest_state():
    s = PlantSession("paper2010", temperature_sensors=True)
    obs = dict(zip(s.observation_names, s.reset()))
    p = s.params
    assert obs["theta_deg"] == pytest.approx(p.initial_target, abs=1e-9) and obs["rate_deg_s"] == 0.0
    assert obs["T_upper_C"] == pytest.approx(obs["T_lower_C"])


@pytest.mark.parametrize("duties, names", [((0.5,), "2 wires"), ((1.5, 0.0), "duty of wire upper = 1.5"),
                                           ((float("nan"), 0.0), "duty of wire upper")])
def test_bad_duties_name_the_wire_and_value(duties, names):
    s = PlantSession("paper2010")
    s.reset()
    with pytest.raises(ValueError, match=names):
        s.step(duties)
    assert s.steps == []  # nothing applied


@pytest.mark.parametrize("kwargs, match", [
    ({"control_interval_s": 0}, "control_interval_s = 0"),
    ({"control_interval_s": True}, "control_interval_s = True"),  # was an interval of 1 s
    ({"episode_s": True}, "episode_s = True"),
    ({"control_interval_s": 0.0005}, "shorter than the plant's step"),  # named the engine's t_end_s
    ({"episode_s": 0.25}, "episode_s = 0.25 is not a whole number"),  # ran 0.2 s
    ({"episode_s": 0.04}, "episode_s = 0.04 is not a whole number"),  # was done at reset
    ({"target": float("nan")}, "target = nan"),  # every reward NaN
    ({"target": 1e6}, "target = 1000000.0 must be a finite number within"),
    ({"temperature_sensors": "no"}, "temperature_sensors = 'no'"),  # turned the sensors on
    ({"overrides": ["V_H_V=9", 9.0]}, "list of NAME=VALUE"),
])
def test_bad_session_settings_name_the_field_and_value(kwargs, match):
    """Each was accepted and silently misread, or refused naming something else (found by review)."""
    with pytest.raises(ValueError, match=match):
        PlantSession("paper2010", **kwargs)


def test_a_joint_too_damped_for_the_plants_step_is_refused_when_made():
    """5x paper2010's damping (3,074 1/s) blew up RK4 at 1 ms mid-episode with no hint (found by
    review): refused when made, naming the damping and the step it holds."""
    with pytest.raises(ValueError, match=r"this set's damping \(3074 1/s\) holds rk4 only up to dt = 0.91 ms"):
        PlantSession("paper2010", overrides=("C_DF_heating_Nms=0.15", "C_DF_cooling_Nms=0.15"))
    assert PlantSession("paper2010", overrides=("C_DF_heating_Nms=0.12",))  # 2,459 1/s: held at 1 ms


def test_a_slider_too_stiff_for_the_plants_step_is_refused_when_made():
    """A 0.1 m wire pulling 5 g: its wire-slider mode makes the plant's RK4 at 1 ms unstable
    (engine.numerics.unstable_step). It was accepted and refused at reset() (found by review)."""
    with pytest.raises(ValueError, match=r"overrides \['wire_length_m=0.1', 'slider_mass_kg=0.005'\]: the plant runs at "
                                         r"rk4, 0.001 s \(not settable here\): dt_s = 0.001 is beyond rk4's stability"):
        PlantSession("linear-bias-spring", target=0.005, overrides=("wire_length_m=0.1", "slider_mass_kg=0.005"))


def test_numpy_numbers_are_settings_too():
    s = PlantSession("paper2010", control_interval_s=np.float32(0.25), episode_s=np.int64(1), target=np.float64(-30))
    assert s.n_steps == 4 and s.target == -30.0


def test_two_opposing_wires_asked_to_heat_get_the_interlock_not_a_crash():
    """The engine refuses a program heating both wires; the session stored the step before the
    run failed, so every later step failed too (found by review). The plant now drives the wire
    with the larger duty (neither on a tie) and counts the step."""
    s = PlantSession("paper2010", control_interval_s=0.2, episode_s=1.0)
    s.reset()
    s.step((0.6, 0.3))
    assert s.last_step_cut and s.interlock_cuts == 1 and s.steps[-1] == (0.0, 0.6, 0.0)
    s.step((0.0, 0.4))
    assert not s.last_step_cut and s.steps[-1] == (0.2, 0.0, 0.4)
    s.step((0.5, 0.5))
    assert s.last_step_cut and s.interlock_cuts == 2 and s.steps[-1] == (0.4, 0.0, 0.0)
    assert s.interlock_violations() == 0  # what the plant did: never both
    lone = PlantSession("linear-bias-spring", control_interval_s=0.2, episode_s=1.0)
    lone.reset()
    lone.step((0.7,))
    assert not lone.last_step_cut and lone.steps[-1] == (0.0, 0.7)


def test_a_step_that_fails_leaves_the_session_as_it_was(monkeypatch):
    import smafinger.bench.gym_env as g

    s = PlantSession("paper2010", control_interval_s=0.2, episode_s=1.0)
    s.reset()
    s.step((0.5, 0.0))
    before = (list(s.steps), s.result, s.interlock_cuts)

    def fail(spec):
        raise RuntimeError("blow-up")

    monkeypatch.setattr(g, "run_spec", fail)
    with pytest.raises(RuntimeError):
        s.step((0.3, 0.6))
    assert (s.steps, s.result, s.interlock_cuts) == before


def test_gymnasium_env_passes_the_checker():
    gymnasium = pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env

    env = make_env(params="linear-bias-spring", target=0.008, episode_s=1.0)
    check_env(env, skip_render_check=True)
    obs, _ = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(np.array([1.0]))
    assert reward <= 0.0 and not truncated and not terminated and gymnasium is not None


def test_the_joints_env_passes_the_checker_and_pays_for_the_interlock():
    """check_env failed on the joint: its random actions heat both wires (found by review)."""
    pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env

    env = make_env(params="paper2010", target=-30.0, control_interval_s=0.2, episode_s=0.4, interlock_penalty=5.0)
    check_env(env, skip_render_check=True)
    env.reset(seed=0)
    _, r_both, _, _, info = env.step(np.array([0.5, 0.2]))
    assert info["interlock_cut"]
    env.reset(seed=0)
    _, r_one, terminated, truncated, info = env.step(np.array([0.5, 0.0]))
    assert not info["interlock_cut"] and r_one - r_both == pytest.approx(5.0)  # the same plant, the penalty
    _, _, terminated, truncated, _ = env.step(np.array([0.0, 0.0]))
    assert truncated and not terminated  # the time limit is a truncation (Gymnasium's API)


@pytest.mark.parametrize("kwargs, match", [({"heat_penalty": float("nan")}, "heat_penalty = nan"),
                                           ({"heat_penalty": -1.0}, "heat_penalty = -1.0 must be a finite number >= 0"),
                                           ({"interlock_penalty": float("nan")}, "interlock_penalty = nan"),
                                           ({"max_T_C": float("nan")}, "max_T_C = nan")])
def test_bad_penalties_are_refused(kwargs, match):
    pytest.importorskip("gymnasium")
    with pytest.raises(ValueError, match=match):
        make_env(params="paper2010", **kwargs)


def test_a_session_reads_its_initial_state_before_any_step_and_refuses_a_non_set():
    """signal() before the first step raised AttributeError on the missing result, and
    make_env(params=5) an AttributeError on .mechanism (found by an API fuzz)."""
    s = PlantSession(episode_s=0.2)
    first = s.observe()
    assert s.signal("theta_deg") == first[0] and s.signal("duty_upper") == 0.0
    with pytest.raises(TypeError, match="params = 5 is not a parameter set"):
        make_env(params=5)
