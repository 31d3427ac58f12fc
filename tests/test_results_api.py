"""The results object's API: signals that cannot corrupt the result, format methods that write
their format, plots that leave the caller's matplotlib alone (found by review)."""

from __future__ import annotations

import os
import subprocess
import sys

import matplotlib
import numpy as np
import pytest

from smafinger import simulate


@pytest.fixture(scope="module")
def run():
    return simulate("paper2010", "open-loop", voltage="0:8:0,1:0:0", t_end_s=2.0)


def test_signals_are_read_only_views(run):
    peak = run.metrics["peak_temperature_C"]["upper"]
    T = run.T_upper_C
    assert np.shares_memory(T, run.wire_signals)  # a view, not a copy (the fast path)
    with pytest.raises(ValueError, match="read-only"):
        T += 273.15  # found by review: this changed the result, its metrics and what it saved
    with pytest.raises(ValueError, match="read-only"):
        run.t[:] = 0.0
    assert run.T_upper_C.max() == peak == simulate(
        "paper2010", "open-loop", voltage="0:8:0,1:0:0", t_end_s=2.0).metrics["peak_temperature_C"]["upper"]
    df = run.to_pandas()
    df["T_upper_C"] += 1.0  # a copy: free to change
    assert run.T_upper_C.max() == peak


@pytest.mark.parametrize("method, wrong", [("to_csv", "x.parquet"), ("to_parquet", "y.csv"), ("to_mat", "z.csv")])
def test_a_format_method_refuses_another_formats_suffix(run, tmp_path, method, wrong):
    with pytest.raises(ValueError, match=f"{method}: path .* does not end in"):
        getattr(run, method)(tmp_path / wrong)
    assert list(tmp_path.iterdir()) == []


def test_plot_leaves_the_callers_backend_alone(run, tmp_path):
    before = matplotlib.get_backend()
    matplotlib.use("pdf")
    try:
        fig = run.plot(tmp_path / "r.png")
        assert matplotlib.get_backend() == "pdf"  # it was switched to Agg
        assert (tmp_path / "r.png").stat().st_size > 0 and fig.axes[3].get_ylabel() == "Drive [V]"
    finally:
        matplotlib.use(before)


def test_a_current_drive_is_plotted_in_amperes(tmp_path):
    r = simulate("paper2010", "open-loop", voltage="0:0.9:0,1:0:0", drive="current", t_end_s=1.0)
    fig = r.plot(tmp_path / "c.png")
    assert fig.axes[3].get_ylabel() == "Drive current [A]"  # was "Drive [V]"


def test_a_closed_stdout_ends_quietly_with_the_pipe_status():
    """`smafinger params | head -1`: was 'smafinger: error:: Broken pipe' and exit 1."""
    code = ("import sys; sys.argv[0] = 'smafinger'; from smafinger.cli import _console; _console()")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    p = subprocess.Popen([sys.executable, "-c", code, "params", "paper2010"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, env=env)
    p.stdout.close()  # the reader went away before the first line
    err = p.stderr.read().decode()
    assert (p.wait(), err) == (141, "")


def test_a_metrics_only_run_is_refused_a_plot_before_any_figure_is_made(tmp_path):
    """A run that recorded only its metrics' signals has no velocity, target or drive: plot()
    says so (it raised a KeyError from inside the drawing and left the figure open), and a
    failed save closes its figure too."""
    import matplotlib.pyplot as plt

    from smafinger.engine.run import make_spec, run_spec

    open_before = len(plt.get_fignums())
    lean = run_spec(make_spec("paper2010", "cooperative", "0:-25", t_end_s=1.0), record="metrics")
    with pytest.raises(ValueError, match="record='all'"):
        lean.plot()
    full = run_spec(lean.spec)
    with pytest.raises(ValueError, match="does not exist"):  # refused before drawing
        full.plot(tmp_path / "no-such-folder" / "r.png")
    with pytest.raises(ValueError, match="xyz"):  # matplotlib refuses the format after drawing
        full.plot(tmp_path / "r.xyz")
    assert len(plt.get_fignums()) == open_before and list(tmp_path.iterdir()) == []
    plt.close(full.plot())


@pytest.mark.parametrize("every, error", [(-1, ValueError), (0, ValueError), (2.5, ValueError), (None, TypeError),
                                          (True, TypeError), ("2", TypeError), (float("nan"), ValueError)])
def test_decimated_and_compact_take_a_whole_number_of_samples(run, every, error):
    """decimated(-1) returned the run reversed in time, saved with samples_every = -1, and
    Compact(every=2.7) kept every 2nd sample (found by an API fuzz)."""
    from smafinger.engine.batch import Compact

    with pytest.raises(error, match=f"every = {every!r}"):
        run.decimated(every)
    with pytest.raises(error, match=f"every = {every!r}"):
        Compact(every=every)
    assert run.decimated(np.int64(4)).samples_every == 4 == run.decimated(4.0).samples_every
    assert Compact(every=4.0).every == 4 and type(Compact(every=np.int64(4)).every) is int
