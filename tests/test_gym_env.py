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


def test_bad_session_settings():
    with pytest.raises(ValueError, match="control_interval_s = 0"):
        PlantSession("paper2010", control_interval_s=0)


def test_gymnasium_env_passes_the_checker():
    gymnasium = pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env

    env = make_env(params="linear-bias-spring", target=0.008, episode_s=1.0)
    check_env(env, skip_render_check=True)
    obs, _ = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(np.array([1.0]))
    assert reward <= 0.0 and not truncated and gymnasium is not None
