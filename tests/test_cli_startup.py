"""Start-up of the command line (issue 11): ``--help`` loads no numerical stack, and the plain
values the CLI shows instead of the engine's (cli/choices.py) are the engine's."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

import smafinger
from smafinger.cli import choices, main

#: modules that cost most of a second to import (numba's compiler, SciPy, pandas, plots, Dask,
#: Arrow) and the package's own numerical layers; none is needed to print help
HEAVY = ("numba", "llvmlite", "scipy", "pandas", "matplotlib", "dask", "pyarrow", "smafinger.engine",
         "smafinger.model", "smafinger.control", "smafinger.analysis")
#: the engine's plain defaults (engine/defaults.py: no numba), which help shows
LIGHT = ("smafinger.engine", "smafinger.engine.defaults")

PROBE = """
import json, sys
from smafinger.cli import main
argv = json.loads(sys.argv[1])
out = sys.stdout
sys.stdout = open('/dev/null', 'w') if sys.platform != 'win32' else open('nul', 'w')
status = main(argv)
out.write(json.dumps({"status": status, "modules": sorted(sys.modules)}))
"""


def _modules_after(code: str, *args: str) -> dict:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    proc = subprocess.run([sys.executable, "-c", code, *args], env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def _heavy(modules: list[str]) -> list[str]:
    return [m for m in modules if m not in LIGHT
            and (m.split(".")[0] in HEAVY or any(m == h or m.startswith(h + ".") for h in HEAVY))]


@pytest.mark.parametrize("argv", [["--help"], [], ["simulate", "--help"], ["identify", "--help"],
                                  ["identify", "actuator", "--help"], ["identify", "kinetics", "--help"],
                                  ["sweep", "--help"], ["reproduce", "--help"], ["bench-controllers", "--help"],
                                  ["tune", "--help"], ["params", "--help"], ["scenarios", "--help"]],
                         ids=lambda a: " ".join(a) or "bare")
def test_help_loads_no_numerical_stack(argv):
    got = _modules_after(PROBE, json.dumps(argv))
    assert got["status"] == 0
    assert _heavy(got["modules"]) == []


def test_import_smafinger_is_light_and_its_names_load_on_use():
    code = ("import json, sys\nimport smafinger\nlight = sorted(sys.modules)\n"
            "from smafinger import simulate, SimulationError\n"
            "print(json.dumps({'light': light, 'after': sorted(sys.modules), "
            "'simulate': simulate.__module__, 'error': SimulationError.__module__}))")
    got = _modules_after(code)
    assert _heavy(got["light"]) == []
    assert "numba" in got["after"]  # the names are the engine's own, imported on first use
    assert (got["simulate"], got["error"]) == ("smafinger.engine.run", "smafinger.engine.run")


def test_package_names_are_the_modules_objects():
    from smafinger.engine import run
    from smafinger import parameters, profiles

    assert smafinger.simulate is run.simulate and smafinger.SimulationError is run.SimulationError
    assert smafinger.ParameterSet is parameters.ParameterSet and smafinger.ParameterError is parameters.ParameterError
    assert (smafinger.ProfileError, smafinger.TargetProfile, smafinger.VoltageProgram) == (
        profiles.ProfileError, profiles.TargetProfile, profiles.VoltageProgram)
    assert set(smafinger.__all__) <= set(dir(smafinger))
    with pytest.raises(AttributeError, match="no attribute 'not_a_name'"):
        smafinger.not_a_name  # noqa: B018


def test_choices_are_the_engines():
    from smafinger.control.strategies import STRATEGIES
    from smafinger.engine import run
    from smafinger.engine.integrators import INTEGRATORS
    from smafinger.engine.pwm import PWM_MODELS

    assert choices.STRATEGY_NAMES == tuple(STRATEGIES)
    assert choices.METHOD_NAMES == tuple(INTEGRATORS)
    assert choices.PWM_NAMES == tuple(PWM_MODELS)
    for name in ("DEFAULT_DT_S", "DEFAULT_METHOD", "DEFAULT_OUTPUT_S", "DEFAULT_PWM", "DEFAULT_TOL_M"):
        assert getattr(choices, name) is getattr(run, name), name


def test_fit_defaults_are_fit_settings():
    from smafinger.analysis.actuator_fit import FitSettings

    s = FitSettings()
    assert (choices.FIT_BUDGET, choices.FIT_MAX_NFEV, choices.FIT_SEED) == (s.budget, s.max_nfev, s.seed)


def test_the_console_script_freezes_the_collector_before_it_ends(monkeypatch):
    """``_console`` moves what is alive out of the collector's sight, then exits with the status."""
    import gc

    import smafinger.cli as cli

    monkeypatch.setattr(cli, "main", lambda: 3)
    gc.unfreeze()
    try:
        with pytest.raises(SystemExit) as exc:
            cli._console()
        assert exc.value.code == 3
        assert gc.get_freeze_count() > 0
    finally:
        gc.unfreeze()


def test_the_console_scripts_files_are_whole_after_it_ends(tmp_path):
    """The process's end without the final collections loses no output: the signals and the
    summary a ``python -m smafinger.cli`` process writes are those the same command writes here."""
    args = ["simulate", "--profile", "0:-25", "--t-end", "1", "--no-progress"]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    proc = subprocess.run([sys.executable, "-m", "smafinger.cli", *args, "--out", str(tmp_path / "child.csv"),
                           "--summary", str(tmp_path / "child.json")], env=env, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert main([*args, "--out", str(tmp_path / "here.csv"), "--summary", str(tmp_path / "here.json")]) == 0
    assert (tmp_path / "child.csv").read_bytes() == (tmp_path / "here.csv").read_bytes()
    child, here = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("child", "here"))
    child.pop("wall_s", None), here.pop("wall_s", None)
    assert child == here
