"""Versions of the code and of Drake, recorded in every result file."""

from __future__ import annotations

import functools
import subprocess
from importlib import metadata
from pathlib import Path

__all__ = ["PACKAGE_VERSION", "versions"]

try:  # the installed distribution's version (pyproject.toml): typed in one place
    PACKAGE_VERSION = metadata.version("drake-biped")
except metadata.PackageNotFoundError:  # run from a source tree that was never installed
    PACKAGE_VERSION = "0+unknown"


@functools.lru_cache(maxsize=1)
def versions() -> dict[str, str | None]:
    """Package version, git commit of a source checkout (with '+dirty' when the tree has changes; None when
    installed from a wheel) and Drake version."""
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
    return {"drake_biped": PACKAGE_VERSION, "git_commit": commit, "drake": drake}
