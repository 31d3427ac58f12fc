"""Sweeps on a real dask.distributed LocalCluster (loopback, 2 worker processes, 1 thread each)."""

from __future__ import annotations

import logging
import math
import os
import signal
import socket
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

distributed = pytest.importorskip("distributed")

from smafinger.analysis import sweep as sw  # noqa: E402
from smafinger.analysis.sweep import load_spec, parse_spec, run_sweep  # noqa: E402
from smafinger.engine import batch  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FIG8 = ROOT / "examples" / "sweep-fig8.toml"
SRC = Path(sw.__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))  # test_sweep's helpers


@pytest.fixture(scope="module")
def cluster():
    # the worker processes must import this checkout of smafinger
    old = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(SRC), old) if p)
    try:
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                      dashboard_address=None, silence_logs=logging.CRITICAL) as c:
            yield c
    finally:
        if old is None:
            os.environ.pop("PYTHONPATH", None)
        else:
            os.environ["PYTHONPATH"] = old


def _frame(path: Path) -> pd.DataFrame:
    return pd.read_parquet(path).drop(columns=["wall_s"])


def test_fig8_sweep_local_and_cluster_tables_identical(cluster, tmp_path):
    local, remote = tmp_path / "local.parquet", tmp_path / "cluster.parquet"
    rep_l = run_sweep(FIG8, local, workers=2)
    rep_c = run_sweep(FIG8, remote, scheduler=cluster.scheduler_address)
    assert rep_l.total == rep_c.total == len(load_spec(FIG8).runs()) >= 200
    assert rep_c.ran == rep_c.total and rep_c.failed == 0
    a, b = _frame(local), _frame(remote)
    assert a["run_id"].is_unique and (a["status"] == "ok").all()
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    # numba was loaded once per worker, by the warm-up plugin, before the tasks
    with distributed.Client(cluster.scheduler_address) as client:
        assert all(client.run(batch.is_warm).values())


def test_worker_killed_mid_sweep_still_completes(cluster, tmp_path):
    spec = parse_spec({
        "base": {"params": "paper2010-table2", "strategy": "open-loop", "voltage": "0:8:0,3:0:0", "t_end_s": 5.0},
        "sweep": {"chunk_size": 3},
        "vary": {"h0": {"fields": ["h0_heating_W_m2K", "h0_cooling_W_m2K"], "start": 60.0, "stop": 70.0, "num": 20},
                 "C_DF_heating_Nms": [0.02, 0.03, 0.04]},
    })
    client = distributed.Client(cluster.scheduler_address)
    killed = []

    def kill_one(done, total):
        if not killed:
            pid = next(iter(client.run(os.getpid).values()))
            os.kill(pid, signal.SIGKILL)  # a worker process of this test's cluster
            killed.append((pid, done, total))

    try:
        out = tmp_path / "killed.parquet"
        rep = run_sweep(spec, out, scheduler=cluster.scheduler_address, on_progress=kill_one)
    finally:
        client.close()
    assert killed and killed[0][1] < killed[0][2]  # killed mid-sweep
    assert rep.ran == rep.total == 60 and rep.failed == 0
    df = pd.read_parquet(out)
    assert len(df) == 60 and df["run_id"].is_unique and df["point"].tolist() == list(range(60))
    ref = tmp_path / "ref.parquet"
    run_sweep(spec, ref, workers=1)
    pd.testing.assert_frame_equal(_frame(out), _frame(ref), check_exact=True)


def test_unreachable_scheduler_is_a_clear_error():
    with pytest.raises(batch.SchedulerError, match="cannot connect to the Dask scheduler at tcp://127.0.0.1:9: "):
        batch.DaskPool("tcp://127.0.0.1:9", timeout_s=1.0)


@pytest.fixture
def silent_port():
    """A loopback port that accepts TCP connections and never says a word."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    conns, stop = [], threading.Event()

    def accept():
        srv.settimeout(0.1)
        while not stop.is_set():
            try:
                conns.append(srv.accept()[0])
            except OSError:
                pass

    th = threading.Thread(target=accept, daemon=True)
    th.start()
    try:
        yield srv.getsockname()[1]
    finally:
        stop.set()
        th.join(5)
        for c in conns:
            c.close()
        srv.close()


def test_a_port_that_is_not_a_scheduler_fails_within_the_timeout(silent_port):
    t0 = time.monotonic()
    with pytest.raises(batch.SchedulerError, match=rf"tcp://127.0.0.1:{silent_port} accepts connections but is not "
                                                   r"a Dask scheduler \(no answer within 1 s; see --connect-timeout\)"):
        batch.DaskPool(f"tcp://127.0.0.1:{silent_port}", timeout_s=1.0)
    assert time.monotonic() - t0 < 30  # (it used to hang for ever)


@pytest.mark.parametrize("address, message", [
    ("tcp://127.0.0.1:99999", "port '99999' is not a number in 1..65535"),
    ("tcp://127.0.0.1:9", "cannot connect to the Dask scheduler at tcp://127.0.0.1:9"),
    ("SILENT", "accepts connections but is not a Dask scheduler"),
])
def test_cli_bad_scheduler_is_one_line_and_exit_2(tmp_path, silent_port, address, message):
    from test_sweep import SMALL, _cli, _write

    spec = _write(tmp_path, SMALL)
    address = address.replace("SILENT", f"tcp://127.0.0.1:{silent_port}")
    r = _cli([str(spec), "--scheduler", address, "--connect-timeout", "1"], tmp_path)
    assert r.exit_code == 2, r.output
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("smafinger: error: ") and message in lines[0], r.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["spec.toml"]


def test_worker_count_is_read_live(cluster):
    pool = batch.DaskPool(cluster.scheduler_address)
    try:
        assert pool.slots == 2 and "(2 worker threads)" in pool.describe()
        pool._slots_at = -1e9  # as if a second had passed
        assert pool.slots == sum(pool.client.nthreads().values())
    finally:
        pool.close()


@pytest.mark.parametrize("timeout", [math.inf, 1e300, math.nan])
def test_an_endless_connect_timeout_is_bad_input(timeout):
    """inf and 1e300 gave an internal error (OverflowError) with exit status 1 (found by review)."""
    with pytest.raises(batch.SchedulerError, match="--connect-timeout .*at most 86400"):
        batch.DaskPool("tcp://127.0.0.1:9", timeout_s=timeout)


class _Stop(Exception):
    pass


def test_a_cluster_without_workers_says_so_instead_of_waiting_silently(monkeypatch):
    """A sweep on a cluster with no worker (or that lost them all) waited for ever without a
    word (found by review). The pool now says every IDLE_REPORT_S that no task finishes and how
    many worker threads the cluster has; and it removes its worker plugin when it closes (a
    worker joining later loaded it and, without smafinger, hung the next sweep)."""
    from smafinger.engine import dask_pool

    monkeypatch.setattr(dask_pool, "IDLE_POLL_S", 0.1)
    monkeypatch.setattr(dask_pool, "IDLE_REPORT_S", 0.3)
    with distributed.LocalCluster(n_workers=0, processes=True, host="127.0.0.1", dashboard_address=None,
                                  silence_logs=logging.CRITICAL) as empty:
        pool = batch.DaskPool(empty.scheduler_address)
        texts = []

        def on_idle(text):
            texts.append(text)
            if len(texts) == 2:
                raise _Stop

        pool.on_idle = on_idle
        try:
            assert dask_pool.PLUGIN_NAME in empty.scheduler.worker_plugins
            with pytest.raises(_Stop):
                list(pool.map_tasks(abs, [-1, -2]))
        finally:
            pool.close()
        assert dask_pool.PLUGIN_NAME not in empty.scheduler.worker_plugins
    assert texts[0].startswith("no Dask task has finished for 0 s: the cluster has 0 worker threads; waiting for "
                               "workers (Ctrl-C stops; finished runs are kept)"), texts
    assert len(texts) == 2


def test_a_worker_of_another_version_is_refused_by_its_tasks(cluster):
    """The version was checked only at the start: a worker that joined later with another
    smafinger wrote 30 of 120 rows of a sweep whose provenance named the client's version
    (found by review). Each task now checks its worker's version."""
    pool = batch.DaskPool(cluster.scheduler_address)
    try:
        assert list(pool.map_tasks(abs, [-3])) == [3]
        pool._version = "0.0.0-not-this-one"  # as if every worker had joined with another version
        with pytest.raises(batch.BatchError, match=r"a Dask worker runs smafinger \S+, the client 0.0.0-not-this-one: "
                                                   "install the same version on every worker"):
            list(pool.map_tasks(abs, [-3]))
    finally:
        pool.close()
