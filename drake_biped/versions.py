"""Versions of the code, of the libraries and the machine, recorded in every result file; and how a number
walked today compares with a record's (`compare_with_record`): exactly on the record's machine, within a stated
tolerance on another.

What is reproducible, where (docs/MODEL.md, "Reproducible numbers"): an episode is deterministic, so the same
configuration walks to the same digits on one machine with the same libraries. The simulation itself (Drake's
compiled plant and our compiled control law, whose small solves are our own loops in a fixed order) uses no
per-CPU kernel, so x86-64 CPUs that pick other BLAS kernels walk the same digits too; the C library's
mathematical functions, another compiler's build of Drake or numba, or another architecture may round otherwise,
and a walk that passes a touchdown or a joint stop by a rounding can then move in its 4th digit."""

from __future__ import annotations

import functools
import math
import os
import platform
import subprocess
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

__all__ = ["CROSS_MACHINE_RTOL", "PACKAGE_VERSION", "Comparison", "compare_with_record", "machine",
           "same_machine", "versions"]

try:  # the installed distribution's version (pyproject.toml): typed in one place
    PACKAGE_VERSION = metadata.version("drake-biped")
except metadata.PackageNotFoundError:  # run from a source tree that was never installed
    PACKAGE_VERSION = "0+unknown"


# The CPU flags that decide which kernels numerical libraries pick (OpenBLAS, numpy's SIMD loops, libm).
NUMERIC_CPU_FLAGS = ("sse2", "sse4_2", "avx", "avx2", "fma", "avx512f", "avx512dq", "avx512vl", "neon", "asimd", "sve")
# What makes two machines one for a walk's digits: not the OS's full name (a kernel update changes no rounding).
MACHINE_IDENTITY = ("cpu", "architecture", "cpu_flags", "libc", "python", "numpy", "scipy", "numba", "drake",
                    "openblas_coretype")
# The libraries whose builds round a walk's arithmetic, recorded with their versions.
NUMERIC_LIBRARIES = ("numpy", "scipy", "numba", "drake")


def _cpu() -> tuple[str, list[str]]:
    """The CPU's model name and its NUMERIC_CPU_FLAGS, from /proc/cpuinfo (Linux) or platform's words."""
    model, flags = "", set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                key = key.strip().lower()
                if key == "model name" and not model:
                    model = value.strip()
                elif key in ("flags", "features") and not flags:
                    flags = set(value.split())
    except OSError:
        pass
    return model or platform.processor() or platform.machine(), [f for f in NUMERIC_CPU_FLAGS if f in flags]


def _version(distribution: str) -> str | None:
    try:
        return metadata.version(distribution)
    except metadata.PackageNotFoundError:
        return None


@functools.lru_cache(maxsize=1)
def machine() -> dict[str, object]:
    """The machine a record was made on, as far as its numbers can depend on it: the CPU (model, architecture and
    the flags that pick numerical kernels), the OS, Python and the numerical libraries' versions, and
    OPENBLAS_CORETYPE where the environment sets it (it picks numpy's BLAS kernels)."""
    model, flags = _cpu()
    return {
        "cpu": model,
        "architecture": platform.machine(),
        "cpu_flags": flags,
        "os": platform.platform(),
        "libc": " ".join(platform.libc_ver()).strip() or None,
        "python": platform.python_version(),
        **{name: _version(name) for name in NUMERIC_LIBRARIES},
        "openblas_coretype": os.environ.get("OPENBLAS_CORETYPE"),
    }


@functools.lru_cache(maxsize=1)
def versions() -> dict[str, object]:
    """Package version, git commit of a source checkout (with '+dirty' when the tree has changes; None when
    installed from a wheel), Drake version, and the machine (`machine`)."""
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
    return {"drake_biped": PACKAGE_VERSION, "git_commit": commit, "drake": _version("drake"), "machine": machine()}


# Across machines a walk's C_mt agrees with a record's within this relative tolerance (a walk that passes an
# event by a rounding moves in its 4th digit; the paper walk's was 4e-4 across OpenBLAS kernels before its
# solves became our own). On the record's machine the comparison is exact.
CROSS_MACHINE_RTOL = 1e-3


def same_machine(record_versions: object) -> bool:
    """Whether a record's "versions" name this machine (`machine`, MACHINE_IDENTITY): the same CPU and flags, C
    library, Python, numerical libraries and OPENBLAS_CORETYPE. False for a record that names no machine."""
    if not isinstance(record_versions, dict) or not isinstance(record_versions.get("machine"), dict):
        return False
    theirs, ours = record_versions["machine"], machine()
    return all(theirs.get(key) == ours.get(key) for key in MACHINE_IDENTITY)


@dataclass(frozen=True)
class Comparison:
    """How a number walked today compares with a record's: `exact` (the rule was last-digit equality: the
    record's machine) or within `rtol`; `agrees` under that rule; `text`, one line saying which rule applied."""

    recorded: float
    today: float
    exact: bool
    rtol: float
    agrees: bool
    text: str


def compare_with_record(recorded: float, today: float, record_versions: object, what: str = "C_mt") -> Comparison:
    """Compare `today`'s number with a record's (`recorded`, made where `record_versions` says): to the last digit
    on the record's machine (`same_machine`), within CROSS_MACHINE_RTOL on another or where the record names none."""
    exact = same_machine(record_versions)
    rtol = 0.0 if exact else CROSS_MACHINE_RTOL
    finite = all(isinstance(x, (int, float)) and math.isfinite(x) for x in (recorded, today))
    if exact:
        agrees = recorded == today
        rule = "the record's machine: compared to the last digit"
    else:
        agrees = finite and abs(today - recorded) <= rtol * abs(recorded)
        named = isinstance(record_versions, dict) and isinstance(record_versions.get("machine"), dict)
        rule = (f"{'another machine than the record' if named else 'the record names no machine'}: compared "
                f"within a relative {rtol:g}")
    if recorded == today:
        outcome = "equal to the last digit"
    elif finite and recorded != 0:
        outcome = f"{'agrees' if agrees else 'DIFFERS'}: {100 * (today - recorded) / abs(recorded):+.4f} %"
    else:
        outcome = "DIFFERS"
    text = f"{what} {today!r} today, {recorded!r} in the record: {outcome} ({rule})"
    return Comparison(recorded, today, exact, rtol, agrees, text)
