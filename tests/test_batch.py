"""Batch engine: parallel runs bit-identical to the same runs made alone."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from smafinger.engine import batch
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
        assert a.to_pandas().equals(b.to_pandas())
        assert np.array_equal(a.segment_start_s, b.segment_start_s)
        assert (a.substeps, a.interlock_violations) == (b.substeps, b.interlock_violations)


def test_reduce_in_workers_serial_and_pool_agree():
    specs = _specs()
    serial = run_batch(specs, workers=1, reduce=_summary)
    with batch.LocalPool(2) as pool:
        pooled = run_batch(specs, pool=pool, reduce=_summary, chunk_size=1)
        again = run_batch(specs[:2], pool=pool, reduce=_summary)  # the pool is reused
    assert serial == pooled
    assert again == serial[:2]


def test_dict_items_and_errors():
    items = [dict(params="paper2010", strategy="cooperative", profile="0:-30", t_end_s=0.5),
             dict(params="paper2010", strategy="cooperative", profile="0:-30", t_end_s=0.5, method="euler")]
    out = run_batch(items, workers=1, reduce=_boom, errors="return")
    assert out[0] == "rk4"
    assert isinstance(out[1], RuntimeError)
    with pytest.raises(BatchError, match="1 of 2 runs failed; first: run 1: RuntimeError"):
        run_batch(items, workers=1, reduce=_boom)
    with pytest.raises(TypeError, match="RunSpec or a dict"):
        run_batch([42])
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
    assert batch.auto_chunk_size(231, 2) == 8
    assert batch.auto_chunk_size(3, 2) == 1
    assert batch.auto_chunk_size(100000, 2) == 64


def test_dask_is_optional(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with pytest.raises(DistributedMissing, match=r"pip install 'smafinger\[distributed\]'"):
        batch.make_pool(scheduler="tcp://127.0.0.1:8786")
