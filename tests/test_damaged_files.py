"""Damaged or odd files met at the API's edge get the package's own error, naming the file, not
an error from inside a reader (found by an API fuzz: each of these was an internal error, exit 1,
on the command line)."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from scipy.io import loadmat, savemat

from smafinger import simulate
from smafinger.export import read_provenance
from smafinger.provenance import ProvenanceError
from smafinger.recordings import RecordingError, read_recording, write_mat


@pytest.fixture(scope="module")
def run():
    return simulate(profile="0:-25", t_end_s=0.5)


def test_provenance_of_damaged_or_foreign_files_is_refused_by_name(run, tmp_path):
    good = tmp_path / "run.mat"
    run.to_mat(good)
    damaged = bytearray(good.read_bytes())
    damaged[len(damaged) // 2] ^= 0xFF  # inside the compressed variables: zlib's error
    (tmp_path / "damaged.mat").write_bytes(damaged)
    savemat(tmp_path / "text.mat", {"provenance": "from the bench PC"})  # a string, not smafinger's struct
    pq.write_table(pa.table({"a": [1]}).replace_schema_metadata({b"smafinger.provenance": b"[1]"}),
                   tmp_path / "list.parquet")  # JSON, but not a record
    for name in ("damaged.mat", "text.mat", "list.parquet"):
        with pytest.raises(ProvenanceError, match=f"--from {tmp_path / name}: "):
            read_provenance(tmp_path / name)
    assert read_provenance(good)["run"] == read_provenance(_saved(run, tmp_path / "run.parquet"))["run"]


def _saved(result, path):
    result.save(path)
    return path


@pytest.mark.parametrize("suffix", [".csv", ".parquet", ".mat"])
def test_a_decimated_files_provenance_says_so_in_every_format(run, tmp_path, suffix):
    """The .mat dropped samples_every (loadmat gives it back as a Python number, which was skipped)."""
    path = _saved(run.decimated(5), tmp_path / f"d{suffix}")
    assert read_provenance(path)["samples_every"] == 5


def test_a_reader_failing_inside_scipy_is_a_recording_error(tmp_path, monkeypatch):
    """scipy's reader raised UnboundLocalError on a file with one damaged header byte."""
    t = np.linspace(0.0, 1.0, 11)
    path = tmp_path / "run.mat"
    savemat(path, {"duty": np.c_[t, 0.5 + 0 * t], "position_m": np.c_[t, 0 * t]})

    def damaged(*args, **kwargs):
        raise UnboundLocalError("local variable 'arr' referenced before assignment")

    monkeypatch.setattr("scipy.io.loadmat", damaged)
    with pytest.raises(RecordingError, match=f"{path}: not a readable MATLAB file"):
        read_recording(path)


def test_an_empty_signal_with_its_own_time_is_refused_in_words(tmp_path):
    """A 0 x 2 [time, value] array beside a mapped time vector: the refusal's message indexed
    the empty array (IndexError)."""
    t = np.linspace(0.0, 1.0, 11)
    path = tmp_path / "run.mat"
    savemat(path, {"tout": t[:, None], "duty": np.zeros((0, 2)), "position_m": np.c_[t, 0 * t]})
    with pytest.raises(RecordingError, match=r"variable 'duty': .*its own time \(no samples,"):
        read_recording(path, {"t_s": "tout"})


def test_a_table_cannot_be_named_as_the_provenance_beside_it(tmp_path):
    """write_mat(layout='table', table_name='provenance') wrote the provenance over the data."""
    t = np.linspace(0.0, 1.0, 11)
    with pytest.raises(RecordingError, match="table_name 'provenance'"):
        write_mat(tmp_path / "r.mat", t, {"theta_deg": t}, layout="table", table_name="provenance")
    assert list(tmp_path.iterdir()) == []
    write_mat(tmp_path / "r.mat", t, {"theta_deg": t}, layout="table", table_name="bench")
    assert {"bench", "provenance"} <= set(loadmat(tmp_path / "r.mat"))
