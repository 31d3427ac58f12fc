"""An output folder a command replaces whole: checked before any work, written all or nothing.

``smafinger reproduce --out DIR`` and ``smafinger bench-controllers --out DIR`` each write a
set of files into a folder, and a second run into the same folder must leave no file of the
first beside its own (a figure of a task not run this time would pass for a result), while
never deleting a file of the user's. The rule, written once here:

- :func:`check_out_dir`, before any work: ``--out`` is a folder or can be made (its parent a
  writable folder), and holds nothing but what the command writes, by EXACT file names
  (:class:`OwnFiles`: its names at the top and in each of its sub-folders), so that a user's
  ``holiday.png`` is never taken for a figure;
- :func:`staged`: the outputs are written into a hidden folder inside ``--out``
  (:data:`STAGE_PREFIX`, so that the final moves are renames within one file system), and at
  the end :func:`publish` moves an earlier run's files out and the new ones in, Ctrl-C held
  off from the last check to the last rename (:func:`sigint_held`); any failure before that
  removes the hidden folder (and ``--out`` if it was made here), leaving ``--out`` as it was.

A run killed outright (SIGKILL) leaves its hidden folder; it counts as the command's own
(not refused), and can be deleted.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator

from .files import OutputError

#: the hidden folder a command writes into, inside its ``--out`` (``.partial-XXXXXXXX``)
STAGE_PREFIX = ".partial-"
#: inside the hidden folder: where an earlier run's files wait until the new ones are in
_OLD = ".old"


@dataclass(frozen=True, eq=False)
class OwnFiles:
    """What one command writes into its ``--out``, by exact names.

    ``command``: its name as typed (``reproduce``, ``bench-controllers``), and ``one``: one
    run of it as a noun phrase (``a reproduce``, ``a bench``), both for the messages.
    ``top``: the file names directly in ``--out``; ``folders``: sub-folder name -> the file
    names in it (``runs``, ``figures``).
    """

    command: str
    one: str
    top: frozenset[str]
    folders: dict[str, frozenset[str]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        clash = (set(self.top) & set(self.folders)) | ({_OLD} & (set(self.top) | set(self.folders)))
        if clash:  # a programming error of the command's definition, caught when it is made
            raise ValueError(f"{self.command}: {sorted(clash)[0]!r} cannot be both a file and a folder of --out")


def foreign(out_dir: Path, own: OwnFiles) -> list[Path]:
    """What ``out_dir`` holds that the command does not write (a killed run's hidden folder is its own)."""
    out = [p for p in sorted(out_dir.iterdir())
           if not (p.is_file() and p.name in own.top) and not (p.name in own.folders and p.is_dir())
           and not (p.is_dir() and p.name.startswith(STAGE_PREFIX))]
    for sub, names in own.folders.items():
        if (out_dir / sub).is_dir():
            out += [p for p in sorted((out_dir / sub).iterdir()) if not (p.is_file() and p.name in names)]
    return out


def check_out_dir(out_dir: str | Path, own: OwnFiles) -> None:
    """:class:`~smafinger.files.OutputError` (bad input, naming ``--out`` and the path) unless
    ``out_dir`` can take the command's outputs: new (its parent a writable folder), or a
    writable folder that is empty or holds only what the command writes (``own``)."""
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise OutputError(f"--out {out_dir}: is a file; give a folder (created if needed)")
    where = out_dir if out_dir.exists() else Path(os.path.abspath(out_dir)).parent
    if not where.is_dir():
        raise OutputError(f"--out {out_dir}: folder {where} does not exist")
    if not os.access(where, os.W_OK | os.X_OK):
        raise OutputError(f"--out {out_dir}: folder {where} is not writable")
    held = foreign(out_dir, own) if out_dir.exists() else []
    if held:
        raise OutputError(f"--out {out_dir}: holds {held[0].relative_to(out_dir)}, which {own.command} does not "
                          f"write; {own.one} replaces what an earlier one wrote there: give a new folder, or "
                          f"one only {own.command} wrote")
    _probe(out_dir)


def _probe(out_dir: Path) -> None:
    """Make (and remove at once) what :func:`staged` will make: ``out_dir`` if it is new, else a
    hidden folder in it; OutputError if that fails. ``os.access`` says yes to root everywhere
    (found by review: ``--out /proc/x`` ran the whole bench, then could not make the folder)."""
    try:
        if out_dir.exists():
            Path(tempfile.mkdtemp(prefix=STAGE_PREFIX, dir=out_dir)).rmdir()
        else:
            out_dir.mkdir()
            out_dir.rmdir()
    except OSError as exc:
        raise OutputError(f"--out {out_dir}: cannot be {'written' if out_dir.exists() else 'made'} "
                          f"({exc.strerror or exc})") from None


@contextmanager
def sigint_held() -> Iterator[None]:
    """Ctrl-C ignored inside (in the main thread; elsewhere nothing to hold)."""
    import signal
    import threading

    held = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if held else None
    try:
        yield
    finally:
        if held and previous is not None:
            signal.signal(signal.SIGINT, previous)


def publish(stage: Path, out_dir: Path, own: OwnFiles) -> None:
    """Replace what an earlier run wrote in ``out_dir`` by ``stage``'s files, by renames within
    ``out_dir`` (no copy): the old ones (``own``'s names) moved into ``stage/.old``, the new ones
    moved in (each sub-folder first, then the top), then ``stage`` removed; a sub-folder the
    new outputs do not have is removed if that leaves it empty. An OSError on the way moves
    everything back (``out_dir`` as it was) and is raised naming ``--out`` (found by review: a
    ``runs/`` not writable left the folder without its summary and report)."""
    old = stage / _OLD
    old.mkdir()
    moved: list[tuple[Path, Path]] = []  # (from, to), in order
    made: list[Path] = []  # folders made in out_dir, in order

    def move(src: Path, dst: Path) -> None:
        src.rename(dst)
        moved.append((src, dst))

    try:
        for name in own.top:
            if (out_dir / name).exists():
                move(out_dir / name, old / name)
        for sub, names in own.folders.items():
            for name in names:
                if (out_dir / sub / name).exists():
                    (old / sub).mkdir(exist_ok=True)
                    move(out_dir / sub / name, old / sub / name)
        for sub in own.folders:
            if (stage / sub).is_dir():
                if not (out_dir / sub).is_dir():
                    (out_dir / sub).mkdir()
                    made.append(out_dir / sub)
                for p in sorted((stage / sub).iterdir()):
                    move(p, out_dir / sub / p.name)
        for p in sorted(stage.iterdir()):
            if p.name != _OLD and p.name not in own.folders:
                move(p, out_dir / p.name)
    except OSError as exc:
        for src, dst in reversed(moved):
            try:
                dst.rename(src)
            except OSError:
                pass
        for folder in reversed(made):
            try:
                folder.rmdir()
            except OSError:
                pass
        raise OSError(f"--out {out_dir}: the outputs could not be moved into place ({exc}); the earlier "
                      f"outputs were put back") from None
    for sub in own.folders:  # e.g. figures/ after a bench without figures: nothing of it left
        if not (stage / sub).is_dir():
            try:
                (out_dir / sub).rmdir()
            except OSError:  # absent, or not empty (a killed run's leftovers): left alone
                pass
    shutil.rmtree(stage, ignore_errors=True)


@contextmanager
def staged(out_dir: str | Path, own: OwnFiles) -> Iterator[Path]:
    """Write the command's outputs into the yielded hidden folder; on leaving, they replace what
    an earlier run wrote in ``out_dir`` all at once (:func:`check_out_dir` again, then
    :func:`publish`, Ctrl-C held). On any exception inside (Ctrl-C included) the hidden folder
    is removed, and ``out_dir`` too if it was made here (and is empty again): ``out_dir`` is as
    it was. A dead worker (:class:`~smafinger.engine.batch.BatchError`) is raised again saying so."""
    from .engine.batch import BatchError

    out_dir = Path(out_dir)
    made = not out_dir.exists()
    out_dir.mkdir(exist_ok=True)
    stage = None
    try:
        stage = Path(tempfile.mkdtemp(prefix=STAGE_PREFIX, dir=out_dir))
        yield stage
        with sigint_held():  # from the last check to the last rename: all the old, or all the new
            check_out_dir(out_dir, own)  # still only what the command writes
            publish(stage, out_dir, own)
    except BaseException as exc:
        if stage is not None:
            shutil.rmtree(stage, ignore_errors=True)
        if made:
            try:
                out_dir.rmdir()  # made here and empty again
            except OSError:
                pass
        if isinstance(exc, BatchError):  # a worker died: nothing is kept
            raise BatchError(f"{exc}; no output was written ({out_dir} is as it was)") from None
        raise


__all__ = ["OwnFiles", "STAGE_PREFIX", "check_out_dir", "foreign", "publish", "sigint_held", "staged"]
