import os
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
