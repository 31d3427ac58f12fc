"""Compare the current engine with the golden record: every run, every signal.

``python tests/golden/compare.py [GLOB ...]`` prints, per run, the signals whose bits differ
and the largest difference on the decimated traces, and the change in segment times. Exit
status 1 if anything differs.
"""

from __future__ import annotations

import fnmatch
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from make_golden import HERE, digest, paper_tasks, signals  # noqa: E402


def load():
    meta = json.loads((HERE / "paper_runs.json").read_text())
    traces = np.load(HERE / "paper_runs.npz")
    return meta, traces


def differences(key: str, result, meta: dict, traces) -> list[str]:
    """Human-readable differences of one run against its golden record ([] if bit-identical)."""
    rec = meta["runs"][key]
    sig = signals(result)
    out = []
    for name, h in rec["hash"].items():
        if name not in sig:
            out.append(f"{name}: missing")
            continue
        if digest(sig[name]) == h:
            continue
        tk = f"{key}|{name}"
        if tk in traces:
            ref = traces[tk].astype(float)
            now = sig[name][:: meta["every"]][: len(ref)]
            out.append(f"{name}: bits differ, max |diff| on the trace {np.max(np.abs(now - ref)):.3g}")
        else:
            out.append(f"{name}: bits differ")
    for what in ("segment_reached_s", "segment_start_s"):
        now = [None if np.isnan(x) else float(x) for x in getattr(result, what)]
        if now != rec[what]:
            out.append(f"{what}: {rec[what]} -> {now}")
    if int(result.substeps) != rec["substeps"]:
        out.append(f"substeps: {rec['substeps']} -> {result.substeps}")
    return out


def main(patterns: list[str]) -> int:
    from smafinger.engine.run import run_spec

    meta, traces = load()
    bad = 0
    for key, spec in paper_tasks():
        if patterns and not any(fnmatch.fnmatchcase(key, p) for p in patterns):
            continue
        diff = differences(key, run_spec(spec), meta, traces)
        print(f"{key}: {'identical' if not diff else ''}")
        for line in diff:
            print(f"    {line}")
        bad += bool(diff)
    print(f"{bad} run(s) differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
