"""Batch engine: parallel runs bit-identical to the same runs made alone."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings, strategies as st

from smafinger.engine import batch, dask_pool, pools
from smafinger.engine.batch import BatchError, DistributedMissing, run_batch, specs_product
from smafinger.engine.run import make_spec, run_spec
from smafinger.parameters import get


def _specs():
    t2 = get("paper2010-table2")
    return [
        make_spec("paper2010", "cooperative", "0:-25,1.5:-45", t_end_s=3.0),
        make_spec("authors2020", "independent", "0:-30", t_end_s=2.0),
        make_spec(t2, "open-loop", voltage="0:8:0,1:0:0", t_end_s=2.5),
        make_spec(t2.replace(h0_heating_W_m2K=60.0), "open-loop", voltage="0:8:0,1:0:0", t_end_s=2.5),
        make_spec("paper2010", "cooperative", "0:-55", t_end_s=2.0, method="euler", dt_s=1e-4),
        make_spec("paper2010", "independent", "0:-25,1:-50", t_end_s=2.0, output_interval_s=0.01),
    ]


def _summary(result):
    s = result.summary()
    s.pop("wall_s")
    return s


def _boom(result):
    if result.spec.method == "euler":
        raise RuntimeError("reduce failed on purpose")
    return result.spec.method


def test_parallel_results_bit_identical_to_single_runs():
    specs = _specs()
    alone = [run_spec(s) for s in specs]
    together = run_batch(specs, workers=2, chunk_size=2)
    assert len(together) == len(specs)
    for a, b in zip(alone, together):
        assert b.spec == a.spec  # input order kept
        pd.testing.assert_frame_equal(a.to_pandas(), b.to_pandas(), check_exact=True)
        assert np.array_equal(a.segment_start_s, b.segment_start_s, equal_nan=True)
        assert np.array_equal(a.segment_reached_s, b.segment_reached_s, equal_nan=True)
        assert (a.substeps, a.interlock_violations) == (b.substeps, b.interlock_violations)
        assert _summary(a) == _summary(b)


@pytest.mark.parametrize("workers", [1, 2])
def test_progress_counts_every_outcome_once(workers):
    """``on_progress(done, total)``: once per run as its outcome arrives, done counting 1..total
    whatever order the chunks finish in, a failed run counted too."""
    specs = _specs()
    calls = []
    out = run_batch(specs, workers=workers, chunk_size=2, reduce=_boom, errors="return",
                    on_progress=lambda done, total: calls.append((done, total)))
    assert sum(isinstance(v, RuntimeError) for v in out) == 1  # the euler run's reduce failed
    assert calls == [(k, len(specs)) for k in range(1, len(specs) + 1)]


@pytest.mark.skipif(sys.platform != "linux", reason="a forkserver is a POSIX start method")
def test_workers_fork_warm_from_the_forkserver():
    """Local workers fork from a forkserver that loaded the kernel (engine/forking.py): in each
    worker it was loaded by neither the worker nor the client, but by the process it was forked
    from. In a fresh process, so that no forkserver is left from another test."""
    pools.warm_up()  # the kernel in numba's disk cache
    code = ("import json, os\nfrom smafinger.engine import batch, pools\n"
            "pool = batch.LocalPool(2).start()\n"
            "print(json.dumps({'client': os.getpid(), 'workers': list(pool.map_tasks(pools.warmed_in, range(4)))}))\n"
            "pool.close()\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    got = json.loads(proc.stdout)
    assert len(got["workers"]) == 4
    for pid, loaded_in in got["workers"]:
        assert loaded_in is not None and loaded_in not in (pid, got["client"])


def test_reduce_in_workers_serial_and_pool_agree():
    specs = _specs()
    serial = run_batch(specs, workers=1, reduce=_summary)
    with batch.LocalPool(2) as pool:
        pooled = run_batch(specs, pool=pool, reduce=_summary, chunk_size=1)
        again = run_batch(specs[:2], pool=pool, reduce=_summary)  # the pool is reused
    assert serial == pooled
    assert again == serial[:2]


def _recorded(result):
    return result.recorded, result.column_names, _summary(result)


def test_a_batch_can_record_only_the_metrics_signals():
    """record="metrics" reaches every run, in this process and in workers; the metrics are the same."""
    from smafinger.engine.signals import METRIC_FIELDS

    specs = _specs()[:3]
    full = run_batch(specs, workers=1, reduce=_recorded)
    for lean in (run_batch(specs, workers=1, reduce=_recorded, record="metrics"),
                 run_batch(specs, workers=2, chunk_size=1, reduce=_recorded, record="metrics")):
        for (rec, cols, summ), (rec_all, cols_all, summ_all) in zip(lean, full):
            assert rec == METRIC_FIELDS and rec_all is None
            assert "theta_deg" in cols and set(cols) < set(cols_all)
            assert summ == summ_all
    with pytest.raises(ValueError, match="record = 'some' is not one of all, metrics"):
        run_batch(specs, workers=1, record="some")


def test_dict_items_and_errors():
    items = [dict(params="paper2010", strategy="cooperative", profile="0:-30", t_end_s=0.5),
             dict(params="paper2010", strategy="cooperative", profile="0:-30", t_end_s=0.5, method="euler")]
    out = run_batch(items, workers=1, reduce=_boom, errors="return")
    assert out[0] == make_spec(**items[0]).method  # the reduce's value comes back (the run's integrator)
    assert isinstance(out[1], RuntimeError)
    with pytest.raises(BatchError, match="1 of 2 runs failed; first: run 1: RuntimeError"):
        run_batch(items, workers=1, reduce=_boom)
    with pytest.raises(TypeError, match="RunSpec or a dict"):
        run_batch([42])
    [(i, ok, exc)] = list(batch.iter_batch([object()], workers=1))  # iter_batch: checked in the worker
    assert (i, ok) == (0, False) and "a RunSpec or a recipe with build()" in str(exc)
    with pytest.raises(ValueError, match="errors"):
        run_batch(items, errors="ignore")
    with pytest.raises(ValueError, match="workers"):
        run_batch(items, workers=0)
    assert run_batch([]) == []


def test_specs_product_and_chunking():
    specs = specs_product(["paper2010", "authors2020"], profiles=["0:-25", "0:-55"],
                          strategy="cooperative", t_end_s=1.0)
    assert [(s.params.name, s.profile.segments[0].target_deg) for s in specs] == [
        ("paper2010", -25.0), ("paper2010", -55.0), ("authors2020", -25.0), ("authors2020", -55.0)]
    assert [len(c) for c in batch.chunked(list(range(10)), 4)] == [4, 4, 2]
    assert batch.auto_chunk_size(231, 2) == 29
    assert batch.auto_chunk_size(3, 2) == 1
    assert batch.auto_chunk_size(100000, 2) == 64


def test_dask_is_optional(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with pytest.raises(DistributedMissing, match=r"pip install 'smafinger\[distributed\]'"):
        batch.make_pool(scheduler="tcp://127.0.0.1:8786")


def _counting(specs, drawn):
    for s in specs:
        drawn.append(s)
        yield s


@pytest.mark.parametrize("workers", [1, 2])
def test_iter_batch_draws_runs_lazily(workers):
    """Only a few chunks per worker are drawn ahead of the results (bounded memory)."""
    spec = make_spec("paper2010", "cooperative", "0:-30", t_end_s=0.2)
    drawn: list = []
    seen = []
    with batch.make_pool(workers) as pool:
        for i, ok, value in batch.iter_batch(_counting([spec] * 40, drawn), pool=pool, chunk_size=2,
                                             reduce=_summary):
            assert ok
            if not seen:
                ahead = len(drawn)
            seen.append(i)
    assert sorted(seen) == list(range(40))
    assert ahead <= 2 * pools.IN_FLIGHT_PER_SLOT * pool.slots + 2  # not the 40 of the batch
    assert len(drawn) == 40


def test_compact_results_float32_decimated():
    spec = make_spec("paper2010", "cooperative", "0:-25,1:-45", t_end_s=2.0)
    full = run_spec(spec)
    [c] = run_batch([spec], workers=1, reduce=batch.Compact(("t_s", "theta_deg", "T_upper_C"), every=10))
    assert c.signal("t_s").dtype == np.float64 and c.signal("theta_deg").dtype == np.float32
    assert np.array_equal(c.signal("t_s"), full.signal("t_s")[::10])
    assert np.array_equal(c.signal("theta_deg"), full.signal("theta_deg")[::10].astype(np.float32))
    # float32 loses nothing that matters: well below the model's 0.015 deg accuracy
    assert np.max(np.abs(c.signal("theta_deg") - full.signal("theta_deg")[::10])) < 1e-4
    assert c.summary == full.summary() | {"wall_s": c.summary["wall_s"]}  # metrics at full resolution
    assert c.nbytes == 201 * (8 + 4 + 4)
    with pytest.raises(KeyError, match="signal 'xi_upper' was not kept"):
        c.signal("xi_upper")
    with pytest.raises(ValueError, match="every = 0"):
        batch.Compact(every=0)
    everything = batch.Compact()(full)
    assert set(everything.signals) == set(full.to_pandas().columns)


@given(n=st.integers(0, 50), size=st.integers(1, 12))
@settings(max_examples=50, deadline=None)
def test_chunked_is_lazy_and_complete(n, size):
    chunks = list(batch.chunked(iter(range(n)), size))
    assert [x for c in chunks for x in c] == list(range(n))
    assert all(len(c) == size for c in chunks[:-1]) and (not chunks or 1 <= len(chunks[-1]) <= size)


@pytest.mark.parametrize("address, message", [
    ("tcp://127.0.0.1:99999", r"port '99999' is not a number in 1..65535"),
    ("tcp://127.0.0.1:http", r"port 'http' is not a number"),
    ("tcp://:8786", "the host is missing"),
    ("tcp://host:1/path", "expected an address like tcp://HOST:PORT"),
    ("tcp://h:\u00b2", r"port '\u00b2' is not a number"),  # isdigit() but not int(): found by an API fuzz
    ("tcp://" + "a" * 70 + ":8786", "host 'a{70}' is not a valid host name"),  # UnicodeError from IDNA
])
def test_bad_scheduler_addresses_are_refused_at_once(address, message):
    with pytest.raises(batch.SchedulerError, match=message):
        batch.check_scheduler(address, 5.0)


def test_scheduler_address_parsing():
    parse = dask_pool.parse_scheduler_address
    assert parse("tcp://10.0.0.1:8786") == ("tcp", "10.0.0.1", 8786)
    assert parse("localhost:8786") == ("tcp", "localhost", 8786)
    assert parse("tls://[::1]:9000") == ("tls", "::1", 9000)
    assert parse("tcp://sched") == ("tcp", "sched", None)


def test_a_reduce_that_cannot_reach_the_workers_is_refused_before_any_task():
    """A lambda ran with one worker and failed with two, with pickle's own error from inside the
    pool (found by an API fuzz): now a TypeError naming it, before any task is sent."""
    spec = make_spec("paper2010", "cooperative", "0:-25", t_end_s=0.5)
    assert run_batch([spec], workers=1, reduce=lambda r: r.substeps) == [run_spec(spec).substeps]
    with pools.LocalPool(1) as pool:
        with pytest.raises(TypeError, match="reduce = <function .*lambda.* cannot be sent to the worker processes"):
            run_batch([spec], pool=pool, reduce=lambda r: r.substeps)
        assert run_batch([spec], pool=pool, reduce=batch.Compact(every=10))[0].every == 10  # the pool goes on


@pytest.mark.parametrize("workers, error", [("2", TypeError), (1.5, TypeError), (True, TypeError), (0, ValueError)])
def test_workers_must_be_a_whole_number(workers, error):
    spec = make_spec("paper2010", "cooperative", "0:-25", t_end_s=0.5)
    with pytest.raises(error, match=f"workers = {workers!r}"):
        run_batch([spec], workers=workers)  # "2" met '<' against an int inside the pool's choice


def test_specs_product_takes_one_value_or_a_list():
    """specs_product("paper2010") ran over the name's letters ("unknown parameter set 'p'")."""
    one = specs_product("paper2010", profiles="0:-25", strategy="cooperative", t_end_s=1.0)
    assert one == specs_product(["paper2010"], profiles=["0:-25"], strategy="cooperative", t_end_s=1.0)
    assert len(one) == 1
    assert len(specs_product(get("paper2010"), voltages="0:8:0", strategy="open-loop", t_end_s=1.0)) == 1
