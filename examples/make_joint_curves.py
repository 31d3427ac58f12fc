"""Make example angle-vs-time curves of the paper's joint (synthetic, by the model itself).

The three curves that ``smafinger identify joint`` fits in the README (the paper's Fig. 9
experiment): a 5 V heating curve, and two cooling curves after 8 V held for 3.5 s and for 10 s,
sampled every 20 ms with 0.05 deg of Gaussian noise, from the ``paper2010`` set (its heating and
cooling h0, h2, C_DF are what the fit should recover). The same curves as tests/test_identify_joint.py.

    python examples/make_joint_curves.py [--out DIR]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from smafinger.analysis.joint_fit import synthesize
from smafinger.parameters import get

NOISE_DEG = 0.05
SAMPLE_S = 0.02
#: (file, drive program, duration [s], noise seed, voltage column written)
CURVES = (("heat_5V.csv", "0:5:0", 22.0, 11, True),
          ("cool_3.5s.csv", "0:8:0,3.5:0:0", 16.0, 12, True),
          ("cool_10s.csv", "0:8:0,10:0:0", 22.0, 13, False))


def write_csv(path: Path, curve, voltage: bool) -> None:
    lines = ["time_s,angle_deg" + (",voltage_V" if voltage else "")]
    for i in range(curve.t_s.size):
        lines.append(f"{curve.t_s[i]:.4f},{curve.angle_deg[i]:.5f}" + (f",{curve.voltage_V[i]:g}" if voltage else ""))
    path.write_text("\n".join(lines) + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("."), help="folder for the CSV files (default: here)")
    out = ap.parse_args().out
    out.mkdir(parents=True, exist_ok=True)
    truth = get("paper2010")
    for name, program, t_end, seed, voltage in CURVES:
        write_csv(out / name, synthesize(truth, program, t_end, SAMPLE_S, NOISE_DEG, seed=seed), voltage)
        print(f"wrote {out / name}")


if __name__ == "__main__":
    main()
