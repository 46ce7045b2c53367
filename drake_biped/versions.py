"""Versions of the code and of Drake, recorded in every result file."""

from __future__ import annotations

import functools
import subprocess
from importlib import metadata
from pathlib import Path

__all__ = ["versions"]


@functools.lru_cache(maxsize=1)
def versions() -> dict[str, str | None]:
    """Package version, git commit of a source checkout (with '+dirty' when the tree has changes; None when
    installed from a wheel) and Drake version."""
    from drake_biped import __version__

    root = Path(__file__).resolve().parent.parent
    commit = None
    if not (root / ".git").exists():  # an installed package: its version is the code version
        root = None
    try:
        if root is None:
            raise OSError("not a source checkout")
        commit = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=5, check=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=root, capture_output=True, text=True, timeout=5, check=True,
        ).stdout.strip()
        if dirty:
            commit += "+dirty"
    except (OSError, subprocess.SubprocessError):
        pass
    try:
        drake = metadata.version("drake")
    except metadata.PackageNotFoundError:
        drake = None
    return {"drake_biped": __version__, "git_commit": commit, "drake": drake}
