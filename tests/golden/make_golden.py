"""Record what the engine computes for every run of ``smafinger reproduce`` (the golden record).

Run from the repository root: ``python tests/golden/make_golden.py``. It writes, beside this
file, ``paper_runs.json`` (per run: a SHA-256 of every signal's float64 bytes, the segment
times, the sub-step count) and ``paper_runs.npz`` (decimated traces, every 100th output
sample, for tolerance comparisons). ``tests/test_golden.py`` compares the current engine
with both; ``python tests/golden/compare.py`` prints every difference with its size.

Re-record only on purpose (a physics change), and say in the commit what changed and why.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: signals recorded (their exported names); the decimated traces keep TRACE_SIGNALS
TRACE_SIGNALS = ("theta_deg", "T_upper_C", "T_lower_C", "xi_upper", "xi_lower",
                 "sigma_upper_Pa", "sigma_lower_Pa", "duty_upper", "duty_lower")
EVERY = 100


def paper_tasks():
    """(key, RunSpec) of every run that ``smafinger reproduce`` makes."""
    from smafinger import reproduce, scenarios

    tasks = [(s.name, s.spec()) for s in scenarios.all_scenarios()]
    return tasks + reproduce.investigation_tasks()


def digest(a: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(a, dtype=np.float64).tobytes()).hexdigest()


def signals(result) -> dict[str, np.ndarray]:
    """Every exported signal of a result, by name."""
    df = result.to_pandas()
    return {c: df[c].to_numpy() for c in df.columns}


def record(result) -> dict:
    sig = signals(result)
    return {
        "hash": {k: digest(v) for k, v in sig.items()},
        "n_samples": int(len(sig["t_s"])),
        "segment_start_s": [None if np.isnan(x) else float(x) for x in result.segment_start_s],
        "segment_reached_s": [None if np.isnan(x) else float(x) for x in result.segment_reached_s],
        "substeps": int(result.substeps),
        "interlock_violations": int(result.interlock_violations),
    }


def main() -> int:
    import smafinger
    from smafinger.engine.run import run_spec

    runs, traces = {}, {}
    for key, spec in paper_tasks():
        r = run_spec(spec)
        runs[key] = record(r)
        sig = signals(r)
        for name in ("t_s",) + TRACE_SIGNALS:
            traces[f"{key}|{name}"] = sig[name][::EVERY].astype(np.float32)
        print(key, runs[key]["substeps"], file=sys.stderr)
    meta = {"smafinger": smafinger.__version__, "every": EVERY, "trace_signals": list(TRACE_SIGNALS),
            "runs": runs}
    (HERE / "paper_runs.json").write_text(json.dumps(meta, indent=1, sort_keys=True) + "\n")
    np.savez_compressed(HERE / "paper_runs.npz", **traces)
    return 0


if __name__ == "__main__":
    sys.exit(main())
