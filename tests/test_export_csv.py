"""The signals CSV (``simulate --out run.csv``, ``reproduce``'s runs/*.csv) is written without
pandas, byte for byte what pandas wrote before (``DataFrame.to_csv(index=False,
float_format=CSV_FLOAT_FORMAT)``), pandas being the reference here."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from smafinger.export import CSV_CHUNK_ROWS, CSV_FLOAT_FORMAT, _plain_csv, write_signals_csv


def _pandas_bytes(tmp_path, names, columns) -> bytes:
    path = tmp_path / "pandas.csv"
    pd.DataFrame(dict(zip(names, columns))).to_csv(path, index=False, float_format=CSV_FLOAT_FORMAT)
    return path.read_bytes()


def _ours(tmp_path, names, columns) -> bytes:
    path = tmp_path / "ours.csv"
    write_signals_csv(path, names, columns)
    return path.read_bytes()


def _awkward_floats(n: int, seed: int) -> np.ndarray:
    """Magnitudes from subnormal to huge, both signs, exact integers, -0.0 and ties of %.9g."""
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(n) * 10.0 ** rng.integers(-310, 300, n)
    x[::7] = np.round(x[::7] * 1e-290)  # small integers (and -0.0 from negative ones)
    x[::11] = -0.0
    x[::13] = 5e-324
    x[::17] = 123456789.5  # rounds at the 9th digit
    x[::19] = 0.1 + 0.2
    return x


def test_fast_path_matches_pandas_byte_for_byte(tmp_path):
    n = 2 * CSV_CHUNK_ROWS + 5  # several chunks and a partial one
    names = ["t_s", "theta_deg", "T_upper_C", "sigma_lower_Pa"]
    columns = [_awkward_floats(n, seed) for seed in range(len(names))]
    assert _plain_csv(names, columns)  # the fast path, not pandas
    ours = _ours(tmp_path, names, columns)
    assert ours == _pandas_bytes(tmp_path, names, columns)
    assert ours.count(b"\n") == n + 1


@pytest.mark.parametrize("case", ["nan", "inf", "int column", "quoted name", "empty rows"])
def test_other_tables_are_written_as_pandas_writes_them(tmp_path, case):
    names, columns = ["a", "b"], [np.linspace(0.0, 1.0, 5), np.linspace(-3.0, 7.0, 5)]
    if case == "nan":
        columns[1][2] = np.nan
    elif case == "inf":
        columns[0][1], columns[1][3] = np.inf, -np.inf
    elif case == "int column":
        columns[1] = np.arange(5) * 1_000_000_000
    elif case == "quoted name":
        names[1] = "b, with a comma"
    else:
        columns = [c[:0] for c in columns]
    assert not _plain_csv(names, columns) or case == "empty rows"
    assert _ours(tmp_path, names, columns) == _pandas_bytes(tmp_path, names, columns)


def test_a_runs_csv_is_what_pandas_writes(tmp_path):
    from smafinger import simulate
    from smafinger.export import add_signals
    from smafinger.files import Outputs

    r = simulate("paper2010", "cooperative", "0:-25", t_end_s=1.0)
    out = Outputs()
    add_signals(out, r, tmp_path / "run.csv")
    out.commit()
    reference = tmp_path / "reference.csv"
    r.to_pandas().to_csv(reference, index=False, float_format=CSV_FLOAT_FORMAT)
    assert (tmp_path / "run.csv").read_bytes() == reference.read_bytes()
