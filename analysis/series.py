"""Small helpers on per-episode series (pure numpy): moving averages, torque-free period lengths."""

from __future__ import annotations

import numpy as np


def moving_average(x, n: int = 20) -> np.ndarray:
    """Trailing moving average over the last min(n, i + 1) values, ignoring NaNs (NaN where a window holds
    none). n = 20 is the paper's window in Figs. 8-11. ValueError unless n is an integer >= 1 and x one series."""
    if not isinstance(n, (int, np.integer)) or isinstance(n, bool) or n < 1:
        raise ValueError(f"moving_average: the window n must be an integer >= 1, got {n!r}")
    x = np.asarray(x, dtype=float)
    if x.ndim != 1:
        raise ValueError(f"moving_average: x must be one series (a 1-D array), got shape {x.shape}")
    ok = np.isfinite(x)
    total = np.cumsum(np.insert(np.where(ok, x, 0.0), 0, 0.0))
    count = np.cumsum(np.insert(ok, 0, False))
    i = np.arange(1, len(x) + 1)
    lo = np.maximum(0, i - n)
    n_ok = count[i] - count[lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n_ok > 0, (total[i] - total[lo]) / n_ok, np.nan)


def period(t1: float, t2: float) -> float:
    """Length of the torque-free period a (t1, t2) sample or mean gives: t2 - t1 with times below 0 acting
    as 0, and 0 when t2 <= t1."""
    return float(max(0.0, max(0.0, t2) - max(0.0, t1)))


def spread_text(sd: float | None, count: int, text, unit: str = "trial") -> str:
    """The spread printed beside a mean over `count` samples: "± " and `text(sd)`, or "(1 trial)" where fewer
    than two samples leave no spread to measure (a standard deviation of 0 over one trial says nothing)."""
    if sd is None or count < 2:
        return f"({count} {unit}{'' if count == 1 else 's'})"
    return f"± {text(sd)}"


def window_text(t1: float, t2: float, digits: int = 3) -> str:
    """A (t1, t2) sample or mean as the window it walks, in words: "0.367–0.863 s", or "none (t2 <= t1)" when
    it gives no torque-free period (times below 0 act as 0)."""
    if period(t1, t2) <= 0.0:
        return f"none (t2 {t2:.{digits}f} <= t1 {t1:.{digits}f})"
    return f"{max(0.0, t1):.{digits}f}–{max(0.0, t2):.{digits}f} s"


def signed_percent(fraction: float | None, digits: int = 1) -> str:
    """A fractional change as a signed percentage ("+12.3 %" a rise, "-4.0 %" a fall); one that rounds to zero
    prints "0.0 %", never "-0.0 %"; None prints "—"."""
    if fraction is None:
        return "—"
    value = round(100.0 * fraction, digits)
    if value == 0:
        return f"{0:.{digits}f} %"
    return f"{value:+.{digits}f} %"


def cmt_change(saving: float | None, digits: int = 1) -> str:
    """A C_mt saving (1 - C_mt / C_mt without a window) as the signed C_mt change it is: every report signs C_mt
    as a change, so a saving of 0.377 is "-37.7 %" (C_mt fell) and a negative saving "+..." (it rose); None "—"."""
    return signed_percent(None if saving is None else -saving, digits)


def sign_changes_per_s(times, values, segment=None) -> float:
    """How often a held signal (a torque, one value per update) changes sign, per second of `times`: a change
    counts between two consecutive nonzero values of opposite sign within one segment (`segment`: a label per
    sample, e.g. the stance leg, so that a role swap is no change; a value of exactly zero, a torque-free
    window's, neither starts nor ends one). ValueError for series of other lengths or under two samples."""
    t, x = np.asarray(times, dtype=float), np.asarray(values, dtype=float)
    same = np.ones(len(x), dtype=bool) if segment is None else np.asarray(segment)
    if t.ndim != 1 or x.shape != t.shape or same.shape != t.shape or len(t) < 2 or not t[-1] > t[0]:
        raise ValueError(f"sign_changes_per_s: times, values and segment must be one series each of the same length "
                         f"(at least 2, over a positive time), got shapes {t.shape}, {x.shape}, {same.shape}")
    change = (np.sign(x[1:]) * np.sign(x[:-1]) < 0) & (same[1:] == same[:-1])
    return float(change.sum() / (t[-1] - t[0]))


def swing_hip_sign_changes_per_s(trajectory, after_s: float = 3.0) -> float:
    """How often the swing hip's torque changes sign in a recorded walk (`EpisodeResult.trajectory`), from
    `after_s` on, per second (`sign_changes_per_s`, the stance leg as the segment: a role swap is no change): the
    hip motor's chatter. ValueError for a walk that ends before `after_s` plus one update."""
    t, act, right = trajectory["time"], trajectory["actuation"], trajectory["stance_right"] > 0.5
    names = [str(n) for n in trajectory["actuator_names"]]
    tau = np.where(right, act[:, names.index("left_hip_motor")], act[:, names.index("right_hip_motor")])
    keep = t >= after_s
    return sign_changes_per_s(t[keep], tau[keep], right[keep])
