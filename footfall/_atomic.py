"""Atomic output: write to a temporary file beside the target, then rename."""

from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def unwritable_reason(folder: str | Path) -> str | None:
    """Why outputs cannot be written into ``folder`` (created if missing), or None.

    Its nearest existing ancestor (itself if it exists) must be a folder this process may
    write in; checked before any work, so a refused output costs nothing.
    """
    folder = Path(folder).absolute()
    existing = folder
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        return f"cannot create {folder}: {existing} is a file, not a folder"
    if not os.access(existing, os.W_OK | os.X_OK):
        return f"cannot write in {existing}: permission denied"
    return None


def make_folder(folder: str | Path, file, field: str) -> Path:
    """Create ``folder`` (and its parents) for outputs, or raise a one-line :class:`InputError`
    naming ``file`` and ``field`` (:func:`unwritable_reason` first: nothing is created then)."""
    from footfall._errors import InputError

    folder = Path(folder)
    reason = unwritable_reason(folder)
    if reason:
        raise InputError(file, field, reason)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise InputError(file, field, f"cannot create {folder}: {e.strerror or e}") from None
    return folder


@contextmanager
def atomic_path(target: str | Path, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary path next to ``target``; rename it over ``target`` on success.

    On any exception the temporary file is removed and ``target`` is left as it was,
    so a reader never sees a half-written output.
    """
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=suffix or target.suffix, dir=target.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        # mkstemp makes the file owner-only; an output gets the mode a plain open() would give it.
        os.chmod(tmp_path, 0o666 & ~_umask())
        os.replace(tmp_path, target)
    except BaseException:
        tmp_path.unlink(missing_ok=True)
        raise


def write_text_atomic(target: str | Path, text: str) -> None:
    with atomic_path(target) as tmp:
        tmp.write_text(text)
