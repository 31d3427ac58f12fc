"""Writing files safely: never half-written, keeping the user's umask."""

from __future__ import annotations

import os
import uuid
from pathlib import Path
from typing import Callable


def temp_path(path: str | Path) -> Path:
    """A fresh hidden temporary name beside ``path`` (for write-then-rename)."""
    path = Path(path)
    return path.with_name(f".{path.name}.{uuid.uuid4().hex[:12]}.tmp")


def atomic_write(path: str | Path, write: Callable[[str], object]) -> None:
    """Write via a temporary file in the same directory, then rename: never half-written.

    ``write(tmp)`` creates the temporary file itself, so the result gets the usual
    permissions (umask), not the 0600 of :func:`tempfile.mkstemp`.
    """
    path = Path(path)
    tmp = temp_path(path)
    try:
        write(str(tmp))
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    atomic_write(path, lambda tmp: Path(tmp).write_text(text))
