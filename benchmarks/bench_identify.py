"""Wall time of the identification fits (issue 4's goal: the joint fit under 60 s on 2 cores).

Runs, as ``smafinger identify`` would:

- the kinetics fit to the four real stress levels of ``../shared/data/sma-thermal-cycling``
  (with the leave-one-level-out fits), if that folder is there;
- the joint-level fit of ``tests/test_identify_joint.py``: synthetic curves from the
  ``paper2010`` set (one 5 V heating curve, two cooling curves switched off after 3.5 s and
  10 s, 0.05 deg noise), fitted from Table II's values.

Run: ``python benchmarks/bench_identify.py``.
"""

from __future__ import annotations

import json
import os
import tempfile
import time
from pathlib import Path

from typer.testing import CliRunner

from smafinger.analysis.joint_fit import synthesize
from smafinger.cli.identify import app
from smafinger.parameters import get

ROOT = Path(__file__).resolve().parent.parent
#: the real data: $SMAFINGER_DATA, default ../shared/data beside the repository (as the tests)
DATA = Path(os.environ.get("SMAFINGER_DATA", ROOT.parent / "shared" / "data")) / "sma-thermal-cycling"


def _csv(path: Path, curve, voltage: bool = True) -> str:
    rows = ["time_s,angle_deg" + (",voltage_V" if voltage else "")]
    for i in range(curve.t_s.size):
        rows.append(f"{curve.t_s[i]:.4f},{curve.angle_deg[i]:.5f}" + (f",{curve.voltage_V[i]:g}" if voltage else ""))
    path.write_text("\n".join(rows) + "\n")
    return str(path)


def main() -> None:
    runner = CliRunner()
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        files = sorted(DATA.glob("filtered_data_*MPa.txt"))
        if files:
            t0 = time.perf_counter()
            r = runner.invoke(app, ["kinetics", *map(str, files), "--report", str(d / "k.json"), "--no-progress"])
            wall = time.perf_counter() - t0
            rep = json.loads((d / "k.json").read_text()) if r.exit_code == 0 else {}
            print(f"kinetics fit, {len(files)} real levels + leave-one-out: {wall:.1f} s "
                  f"(RMS strain all {100 * rep.get('rms_strain_all', float('nan')):.3f} %)")
        truth = get("paper2010")
        heat = _csv(d / "heat.csv", synthesize(truth, "0:5:0", 22.0, 0.02, 0.05, seed=11))
        cool_a = _csv(d / "cool_a.csv", synthesize(truth, "0:8:0,3.5:0:0", 16.0, 0.02, 0.05, seed=12))
        cool_b = _csv(d / "cool_b.csv", synthesize(truth, "0:8:0,10:0:0", 22.0, 0.02, 0.05, seed=13), voltage=False)
        t0 = time.perf_counter()
        r = runner.invoke(app, ["joint", "--heating", heat, "--cooling", cool_a, "--cooling", cool_b,
                                "--heat-s", "3.5", "--heat-s", "10", "--cooling-voltage", "8",
                                "--params", "paper2010-table2", "--report", str(d / "j.json"), "--no-progress"])
        wall = time.perf_counter() - t0
        if r.exit_code != 0:
            raise SystemExit(f"joint fit failed: {r.output}")
        rep = json.loads((d / "j.json").read_text())
        worst = max(abs(rep["values"][k] / getattr(truth, k) - 1.0)
                    for ph in ("heating", "cooling") for k in rep[ph]["values"])
        nfev = rep["heating"]["nfev"] + rep["cooling"]["nfev"]
        print(f"joint fit (h0, h2, C_DF of heating and cooling): {wall:.1f} s, {nfev} simulations, "
              f"largest error {100 * worst:.2f} %   goal < 60 s")


if __name__ == "__main__":
    main()
