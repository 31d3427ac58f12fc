"""A recording on a simulation grid: zero-order hold of the input, output located on the grid,
the input as a piecewise-constant program."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from smafinger.recordings import (
    Recording, RecordingError, Series, input_on_grid, input_program, output_on_grid,
)


def rec(t_in, v_in, t_out=(0.0, 1.0), v_out=(0.0, 0.0), kind="duty"):
    return Recording("bench.csv", Series(kind, t_in, v_in, "u"), Series("theta_rad", t_out, v_out, "th"))


def test_zero_order_hold_matches_hand_computed_values():
    r = rec([0.0, 1.0, 2.5], [0.1, 0.7, 0.3])
    grid = [0.0, 0.5, 0.999, 1.0, 1.2, 2.5, 3.0, 10.0]
    assert input_on_grid(r, grid).tolist() == [0.1, 0.1, 0.1, 0.7, 0.7, 0.3, 0.3, 0.3]
    assert input_on_grid(r, [0.5, 2.6]).tolist() == [0.1, 0.3]  # a grid may start after the first sample


def test_grid_before_the_first_input_sample_is_refused():
    r = rec([0.2, 1.0], [0.1, 0.7])
    with pytest.raises(RecordingError) as info:
        input_on_grid(r, [0.0, 0.5])
    msg = str(info.value)
    assert "bench.csv" in msg and "'u'" in msg and "starts at 0.0 s, before the first sample" in msg and "0.2 s" in msg


def test_a_grid_time_a_rounding_error_before_a_sample_takes_the_sample():
    """A logger that adds dt at each tick drifts above k * dt by a few ulps: a simulation grid
    k * dt then lies a rounding error before most sample times."""
    k = np.arange(1000)
    samples = np.concatenate([[0.0], np.cumsum(np.full(k.size - 1, 1e-3))])
    grid = k * 1e-3
    below = np.flatnonzero(grid < samples)
    assert below.size > 500, "the test needs grid times that round below the sample times"
    values = (k % 2).astype(float)
    got = input_on_grid(rec(samples, values), grid)
    np.testing.assert_array_equal(got, values)
    # with no tolerance the hold lags one step exactly there
    lagged = input_on_grid(rec(samples, values), grid, tol_s=0.0)
    assert (lagged[below] == values[below - 1]).all()


@pytest.mark.parametrize("grid, fragment", [
    ([[0.0, 1.0]], "1-D"),
    ([], "non-empty"),
    ([0.0, np.nan], "t_grid[1] = nan is not finite"),
    ([0.0, 1.0, 1.0], "t_grid[2] = 1.0 s is not after t_grid[1] = 1.0 s"),
])
def test_bad_grids_are_refused(grid, fragment):
    with pytest.raises(RecordingError) as info:
        input_on_grid(rec([0.0, 1.0], [0.0, 1.0]), grid)
    assert fragment in str(info.value)


def test_output_on_the_grid_is_an_exact_gather():
    t_out = np.arange(0, 1.0, 0.01)
    y_true = np.sin(t_out)
    r = rec([0.0, 1.0], [0.0, 0.0], t_out, y_true)
    grid = np.arange(0, 1001) * 1e-3
    o = output_on_grid(r, grid)
    assert o.exact and o.name == "theta_rad"
    np.testing.assert_array_equal(o.index, np.arange(0, 1000, 10))
    y_grid = np.sin(grid)
    np.testing.assert_array_equal(o.model_at(y_grid), np.sin(grid[o.index]))
    np.testing.assert_allclose(o.residuals(y_grid), np.sin(grid[o.index]) - y_true, atol=1e-15)


def test_output_between_grid_points_is_interpolated_linearly():
    r = rec([0.0, 1.0], [0.0, 0.0], [0.0005, 0.0105, 0.02], [0.0, 0.0, 0.0])
    grid = np.arange(0, 31) * 1e-3
    o = output_on_grid(r, grid)
    assert not o.exact
    assert o.index.tolist() == [0, 10, 20]
    np.testing.assert_allclose(o.weight, [0.5, 0.5, 0.0], atol=1e-9)
    assert o.weight[2] == 0.0
    np.testing.assert_allclose(o.model_at(3.0 * grid + 1.0), 3.0 * np.array([0.0005, 0.0105, 0.02]) + 1.0,
                               rtol=1e-12)


def test_output_outside_the_grid_is_refused():
    r = rec([0.0, 1.0], [0.0, 0.0], [0.0, 0.5, 1.2], [0.0, 0.0, 0.0])
    with pytest.raises(RecordingError) as info:
        output_on_grid(r, np.linspace(0, 1, 11))
    msg = str(info.value)
    assert "bench.csv" in msg and "output 'th' sample 3 at 1.2 s is outside t_grid [0.0, 1.0] s" in msg


def test_program_merges_equal_consecutive_values():
    r = rec([0.0, 0.001, 0.002, 0.003, 0.004, 0.005], [0.5, 0.5, 0.0, 0.0, 0.5, 0.5])
    assert input_program(r) == ((0.0, 0.5), (0.002, 0.0), (0.004, 0.5))
    assert input_program(rec([1.0, 2.0], [0.3, 0.3])) == ((1.0, 0.3),)


def test_time_origin_moves_every_series():
    r = rec([2.0, 3.0], [0.1, 0.2], [2.5, 4.0], [0.0, 0.1])
    z = r.with_time_origin()
    assert z.input.t_s.tolist() == [0.0, 1.0] and z.output.t_s.tolist() == [0.5, 2.0]
    assert z.meta["time_origin_s"] == 2.0
    assert input_program(z)[0] == (0.0, 0.1)


# ---- properties ----------------------------------------------------------------------------
@st.composite
def series(draw, min_size=2, max_size=40):
    steps = draw(st.lists(st.floats(1e-6, 10.0), min_size=min_size - 1, max_size=max_size - 1))
    t0 = draw(st.floats(-100.0, 100.0))
    t = t0 + np.concatenate([[0.0], np.cumsum(steps)])
    t = np.unique(t)  # the sums may round two times together: keep them strictly increasing
    if t.size < 2:
        t = np.array([t0, t0 + 1.0])
    v = np.array(draw(st.lists(st.floats(0.0, 1.0), min_size=t.size, max_size=t.size)))
    return t, v


@settings(max_examples=200, deadline=None)
@given(series())
def test_hold_on_the_input_times_is_the_input(tv):
    t, v = tv
    r = rec(t, v)
    np.testing.assert_array_equal(input_on_grid(r, t), v)
    # and the program, held back onto those times, is the input too
    starts = np.array([s for s, _ in input_program(r)])
    vals = np.array([x for _, x in input_program(r)])
    np.testing.assert_array_equal(vals[np.searchsorted(starts, t, side="right") - 1], v)


@settings(max_examples=200, deadline=None)
@given(series(), st.lists(st.floats(0.0, 1.0), min_size=1, max_size=30))
def test_hold_is_the_last_sample_at_or_before(tv, fractions):
    t, v = tv
    grid = np.unique(t[0] + np.array(fractions) * (t[-1] + 5.0 - t[0]))
    got = input_on_grid(rec(t, v), grid, tol_s=0.0)
    for g, x in zip(grid, got):
        assert x == v[t <= g][-1]


@settings(max_examples=100, deadline=None)
@given(series())
def test_output_at_grid_times_is_gathered_exactly(tv):
    t, y = tv
    r = rec([t[0], t[-1]], [0.0, 0.0], t, y)
    o = output_on_grid(r, t)
    assert o.exact and o.index.tolist() == list(range(t.size))
    np.testing.assert_array_equal(o.model_at(y), y)
