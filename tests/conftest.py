import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")
# the compiled kernel in every test (a cold cache would otherwise answer some runs interpreted and
# start background compiles); tests/test_interpreted.py chooses its engines itself
os.environ["SMAFINGER_ENGINE"] = "compiled"

#: the repository (the folder holding tests/)
REPO = Path(__file__).resolve().parents[1]


def data_root() -> Path:
    """The real data sets: ``$SMAFINGER_DATA``, else ``../shared/data`` beside the repository."""
    env = os.environ.get("SMAFINGER_DATA")
    return Path(env) if env else REPO.parent / "shared" / "data"


@pytest.fixture(scope="session")
def data_dir():
    """``data_dir(NAME)``: the folder of a real data set. Missing, its tests are skipped, or fail
    when ``SMAFINGER_REQUIRE_DATA=1`` (as ``.ci/run`` sets), so that CI never passes without them."""
    def get(name: str) -> Path:
        path = data_root() / name
        if not path.is_dir():
            msg = (f"real data {name!r} not found at {path} (set SMAFINGER_DATA to the folder holding "
                   f"{name}/)")
            if os.environ.get("SMAFINGER_REQUIRE_DATA") == "1":
                pytest.fail(msg + "; SMAFINGER_REQUIRE_DATA=1 requires it", pytrace=False)
            pytest.skip(msg)
        return path

    return get


#: one run of each compiled kernel the suite uses (engine.run.kernel_key: mechanism and controller
#: record type), as make_spec arguments
KERNELS = (
    dict(params="paper2010", strategy="cooperative", profile="0:-25"),
    dict(params="paper2010", strategy="cooperative", profile="0:-25", controller="sliding-mode"),
    dict(params="linear-bias-spring", strategy="cooperative", profile="0:0.01"),
    dict(params="linear-bias-spring", strategy="cooperative", profile="0:0.01", controller="sliding-mode"),
)


def pytest_sessionstart(session):
    """Compile the kernels not in numba's cache yet, two processes at once (this machine's cores),
    before the first test: a fresh checkout otherwise compiles them one after the other, in
    whichever test first needs each (about a minute each). Tests are unchanged: with the cache
    warm this only looks the kernels up."""
    from smafinger.engine.run import kernel_cached, make_spec

    missing = [kw for kw in KERNELS if not kernel_cached(make_spec(t_end_s=0.01, **kw))]
    if len(missing) < 2:
        return  # one compile: the test that needs it does it
    code = ("import sys, json; from smafinger.engine.run import compile_kernel, make_spec\n"
            "for kw in json.loads(sys.argv[1]): compile_kernel(make_spec(t_end_s=0.01, **kw))")
    procs = [subprocess.Popen([sys.executable, "-c", code, json.dumps(missing[i::2])]) for i in range(2)]
    for proc in procs:
        proc.wait()


#: the test that reads :class:`FreshInstall`
FRESH_INSTALL_TEST = "test_a_fresh_install_answers_interpreted_then_compiles_in_the_background"


class FreshInstall:
    """``smafinger simulate`` of the linear rig with an empty numba cache of its own (a fresh
    install), started once the tests are collected if the fresh-install test is among them: the
    first run answers interpreted and starts the background compile (a minute or more), which
    then overlaps the tests run before that one checks it."""

    args = ("simulate", "--params", "linear-bias-spring", "--profile", "0:0.010", "--t-end", "3", "--no-progress")

    def __init__(self, root: Path):
        self.root = root
        self.env = {k: v for k, v in os.environ.items() if k != "SMAFINGER_ENGINE"}
        self.env["NUMBA_CACHE_DIR"] = str(root / "cache")
        with open(root / "first.out", "w") as out, open(root / "first.err", "w") as err:
            self.first = subprocess.Popen(self.command(root / "run0.json"), env=self.env, cwd=root, stdout=out,
                                          stderr=err)

    def command(self, summary: Path) -> list[str]:
        return [sys.executable, "-m", "smafinger.cli", *self.args, "--summary", str(summary)]

    def first_run(self, timeout_s: float) -> tuple[int, str]:
        """The first run's exit status and stderr, once it has ended."""
        rc = self.first.wait(timeout=timeout_s)
        return rc, (self.root / "first.err").read_text()


@pytest.hookimpl(trylast=True)  # after -k and -m have deselected
def pytest_collection_modifyitems(session, config, items):
    if any(item.name == FRESH_INSTALL_TEST for item in items):
        config.fresh_install = FreshInstall(config._tmp_path_factory.mktemp("fresh-install"))  # tmp_path_factory's


@pytest.fixture(scope="session")
def fresh_install(pytestconfig):
    probe = pytestconfig.fresh_install
    yield probe
    if probe.first.poll() is None:
        probe.first.kill()
        probe.first.wait()
