"""Folders a command will write to, checked before it starts its work."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from suds_exp.errors import SudsError


def check_writable(
    folder: str | Path,
    what: str,
    error: type[SudsError] = SudsError,
    param: str | tuple[str, ...] | None = None,
) -> None:
    """Raise ``error`` (one line: ``what``, the folder and the reason) when a file cannot
    be created in ``folder`` (read-only folder or file system, a file in the way, no
    permission); checked by creating and removing a probe file, so it is true for root
    too. Folders made for the probe are removed again."""
    folder = Path(folder)
    made: list[Path] = []
    p = folder
    while not p.exists() and p != p.parent:
        made.append(p)
        p = p.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(dir=folder, prefix=".suds-probe-")
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        reason = (exc.strerror or str(exc)).lower()
        raise error(f"{what} {folder}: cannot write there: {reason}", param=param) from None
    finally:
        for d in made:
            try:
                d.rmdir()
            except OSError:
                break
