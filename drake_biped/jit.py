"""Compilation of the control law's kernels with numba.

The controller's update runs once per simulated millisecond; in plain Python its arithmetic cost about as
much as the plant's own step. Its laws are therefore written as kernels on floats and float arrays and
compiled (cached on disk beside the module, so a process compiles them once per installation). Setting the
environment variable NUMBA_DISABLE_JIT=1 runs the same kernels as plain Python, to step through them.
"""

from __future__ import annotations

import numba


def njit(function):
    """`function` compiled in nopython mode, cached on disk; IEEE arithmetic (no fast-math), so the compiled
    law gives the numbers the same Python code gives."""
    return numba.njit(cache=True)(function)

