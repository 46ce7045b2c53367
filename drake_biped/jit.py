"""Compilation of the control law's kernels with numba.

The controller's update runs once per simulated millisecond; in plain Python its arithmetic cost about as
much as the plant's own step. Its laws are therefore written as kernels on floats and float arrays and
compiled, and the compiled code is cached on disk, so a process compiles them once per installation.
Setting the environment variable NUMBA_DISABLE_JIT=1 runs the same kernels as plain Python, to step through
them.

numba keys a cached function by its own file's time stamp only, while a kernel inlines the kernels it calls
from other modules: a changed `kinematics.leg_points_k` would leave the controller's cached update calling the
old one. The cache therefore lives in a folder named by a hash of every module of the package
(KERNEL_CACHE_DIR, under $XDG_CACHE_HOME or ~/.cache, or under NUMBA_CACHE_DIR when that is set): any change
to the package's code compiles every kernel afresh.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numba


def _source_hash() -> str:
    digest = hashlib.sha256()
    for path in sorted(Path(__file__).resolve().parent.glob("*.py")):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def _cache_root() -> Path:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "drake_biped"


KERNEL_CACHE_DIR = _cache_root() / f"kernels-{_source_hash()}"
numba.config.CACHE_DIR = str(KERNEL_CACHE_DIR)


def njit(function):
    """`function` compiled in nopython mode, cached on disk in KERNEL_CACHE_DIR; IEEE arithmetic (no
    fast-math), so the compiled law gives the numbers the same Python code gives."""
    return numba.njit(cache=True)(function)
