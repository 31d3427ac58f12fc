"""Make the example bench runs shipped in ``src/smafinger/data/`` (synthetic, by the model itself).

A linear bias-spring rig whose "true" parameters differ from the ``linear-bias-spring``
template (warmer transformation temperatures, more convection while heating and less while
cooling, 2 % recoverable strain, a 9 N preload): the runs a bench would record, the duty sent at
1 kHz and the position at 100 Hz with 30 um of Gaussian noise and a sensor offset of its own per
run. Two runs are CSV files, two are MATLAB files laid out as Simulink's "To Workspace" blocks
save them (Structure With Time, the position in millimetres under other names), and one is a
closed-loop run of the rig's PID tracking a reference. The true set is written beside them
(``bench_truth.toml``) and every run is described in ``bench_runs.json``.

    python examples/make_bench_data.py [--out DIR]

Then fit the template to three runs, predict the others (``docs/identification.md``)::

    D=src/smafinger/data
    smafinger identify actuator --params linear-bias-spring \\
        --fit $D/bench_step.csv --fit $D/bench_square.csv \\
        --fit "$D/bench_stairs.mat::duty=u_pwm,position_m=x_mm*1e-3" \\
        --validate "$D/bench_ramp.mat::duty=u_pwm,position_m=x_mm*1e-3" \\
        --replay $D/bench_tracking.csv --gains 40:5:20 --duty-max 0.4 \\
        --out fit.toml --report fit.json --plot fit-figures
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from smafinger import __version__
from smafinger.analysis import bench_synth as bs
from smafinger.analysis.bench_runs import RigController
from smafinger.files import atomic_write_text
from smafinger.parameters import get

TRUTH = get("linear-bias-spring").replace(
    name="bench-truth", source="examples/make_bench_data.py: the set that made the example bench runs",
    A_S0_C=72.0, A_F0_C=83.0, M_S0_C=55.0, M_F0_C=44.0, h0_heating_W_m2K=55.0, h0_cooling_W_m2K=35.0,
    eps_R=0.02, bias_spring_preload_N=9.0)
NOISE_M = 30e-6
#: the rig's PID in the tracking run: duty per metre of error (s/m, 1/(m s)), clamped at 40 %
CONTROLLER = RigController(K_P=40.0, K_V=5.0, K_I=20.0, duty_max=0.4)
#: the MATLAB files' variables: (name, factor from the canonical unit)
SIMULINK_NAMES = {"duty": ("u_pwm", 1.0), "position_m": ("x_mm", 1e3)}
SIMULINK_MAP = "duty=u_pwm,position_m=x_mm*1e-3"


def _ramp(t0: float, t1: float, d1: float, steps: int = 80) -> str:
    return ",".join(f"{t0 + k * (t1 - t0) / steps:.3f}:{d1 * k / steps:.4f}" for k in range(steps))


#: name -> (role, duty program or target profile, length [s], sensor offset [m], format)
RUNS = {
    "bench_step": ("fit", "0:0,0.5:0.25,6:0", 12.0, 1.2e-3, "csv"),
    "bench_square": ("fit", "0:0,0.5:0.4,2:0,4.5:0.4,6:0,8.5:0.4,9.5:0", 12.0, -0.7e-3, "csv"),
    "bench_stairs": ("fit", "0:0,0.5:0.13,4.5:0.16,8.5:0.2,11.5:0", 15.0, 2.5e-3, "mat"),
    "bench_ramp": ("validate", "0:0," + _ramp(0.5, 8.5, 0.3) + ",8.5:0", 15.0, 0.4e-3, "mat"),
    "bench_tracking": ("replay", "0:0,0.5:0.005,6:0.012,10:0.003", 14.0, 0.8e-3, "csv"),
}


def make(out: Path) -> list[Path]:
    """Write every run, the true set and the manifest into ``out``; the paths written."""
    out.mkdir(parents=True, exist_ok=True)
    written, manifest = [], {"smafinger_version": __version__, "noise_m": NOISE_M, "truth": "bench_truth.toml",
                             "runs": {}}
    for seed, (name, (role, program, t_end, offset, fmt)) in enumerate(RUNS.items(), start=1):
        if role == "replay":
            run = bs.closed_loop_run(TRUTH, program, CONTROLLER, t_end, noise=NOISE_M, offset=offset, seed=seed)
        else:
            run = bs.open_loop_run(TRUTH, program, t_end, noise=NOISE_M, offset=offset, seed=seed)
        path = out / f"{name}.{fmt}"
        if fmt == "csv":
            bs.write_csv(path, run)
        else:
            bs.write_simulink_mat(path, run, SIMULINK_NAMES, {"description": f"synthetic bench run {name}",
                                                              "offset_m": offset, "noise_m": NOISE_M})
        manifest["runs"][path.name] = {"role": role, "program" if role != "replay" else "profile": program,
                                       "t_end_s": t_end, "offset_m": offset, "seed": seed,
                                       "map": SIMULINK_MAP if fmt == "mat" else ""}
        written.append(path)
    manifest["controller"] = {"K_P": CONTROLLER.K_P, "K_V": CONTROLLER.K_V, "K_I": CONTROLLER.K_I,
                              "duty_max": CONTROLLER.duty_max}
    atomic_write_text(out / "bench_truth.toml", TRUTH.to_toml())
    atomic_write_text(out / "bench_runs.json", json.dumps(manifest, indent=2) + "\n")
    return written + [out / "bench_truth.toml", out / "bench_runs.json"]


def main() -> None:
    default = Path(__file__).resolve().parent.parent / "src" / "smafinger" / "data"
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=default, help=f"directory (default: {default})")
    for path in make(ap.parse_args().out):
        print(f"wrote {path} ({path.stat().st_size / 1024:.0f} kB)")


if __name__ == "__main__":
    main()
