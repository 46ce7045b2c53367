"""The reproduction report's dynamics step: what each walk settles on (its attractor, Lyapunov exponent), the
slope premise's envelopes, the basins and the Floquet multipliers, as verdict rows and as a section."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from drake_biped.analysis.floquet import record_verdict
from drake_biped.analysis.report_text import BEYOND, NOT_REPRODUCED, REPRODUCED, embed, num, read_markdown

__all__ = ["SLOPE_LEVEL_M", "attractor_text", "dynamics_rows", "dynamics_section", "floquet_text"]

SLOPE_LEVEL_M = 2.0  # the level ground before the dynamics step's slopes (Reproduction.dynamics)


def floquet_text(gaits: dict[str, Any]) -> str:
    """Each gait's spectral radius and what it establishes; no radius where no perturbation size converged
    (the largest eigenvalue of an unconverged Jacobian measures nothing)."""
    return ", ".join(f"{name} ρ {num(g['spectral_radius'])} ({record_verdict(g)})"
                     if g.get("converged_epsilon") is not None
                     else f"{name}: {record_verdict(g)} (Newton's residual {g['fixed_point_residual']:.1e})"
                     for name, g in gaits.items())


def attractor_text(point: dict[str, Any]) -> str:
    """A walk's attractor in words: the 2 ms reading, the jitter-scale one where it differs, the exponent."""
    if point["fell"]:
        return "falls"
    text = point["attractor"]
    jitter = (point.get("within_jitter") or {}).get("attractor")
    if jitter and jitter != text:
        text += f" ({jitter} at {1e3 * point['within_jitter']['tolerance_s']:g} ms)"
    lyap = point.get("lyapunov") or {}
    if lyap.get("exponent") is not None:
        text += f", Lyapunov {lyap['exponent']:+.2f}/step"
    if point.get("spread_s") is not None:
        text += f", step periods spread {1e3 * point['spread_s']:.0f} ms"
    return text


def _bound(premise: dict[str, Any], key: str) -> str:
    """A slope envelope of `bifurcation.premise`: "0.015", or "≥ 0.06" where it is the sweep's last slope."""
    value = premise[key]
    if value is None:
        return "none"
    return ("≥ " if premise.get(f"{key}_is_bound") else "") + f"{value:g}"


def _dynamics_walks_m(d: dict[str, Any]) -> tuple[float, float, float, float]:
    """The dynamics step's walk lengths (m): the attractors, the sweeps, the slopes (2 m level included), the
    basins (Profile.dynamics_walks_m, recorded in its settings)."""
    return tuple(d["settings"]["walks_m"])


def dynamics_rows(d: dict[str, Any], wtext: str) -> list[tuple[str, str, str, str]]:
    """The dynamics step's verdict rows: the attractors, the slope premise, the Table III walker."""
    none, learned = d["learned"]
    long_m, _, slope_m, _ = _dynamics_walks_m(d)
    rows = [(f"What the walk settles on ({long_m:g} m)", "—",
             f"no window: {attractor_text(none)}; {wtext}: {attractor_text(learned)}", BEYOND)]
    pr = d["premise"]
    up = {k: "none" if pr[f"{k}_up_to"] is None else _bound(pr, f"{k}_up_to") + " rad" for k in ("without", "with")}
    band = (f"the window fails and none climbs at {', '.join(f'{v:g}' for v in pr['band'])} rad" if pr["band"]
            else "no slope where the window fails and none climbs")
    rows.append(("The slope premise: the learned window cannot climb where none can", "holds at 0.02 rad",
                 f"climbs {slope_m - SLOPE_LEVEL_M:g} m up to: none {up['without']}, {wtext} {up['with']}; {band}",
                 REPRODUCED if pr["holds"] else NOT_REPRODUCED))
    rows.append(("Table III, entrained reading (`paper_entrained`): a gait?", "walks",
                 "; ".join(f"{1e3 * p['time_step_s']:g} ms: {attractor_text(p)}" for p in d["paper_entrained"]),
                 BEYOND))
    return rows


def dynamics_section(out: Path, d: dict[str, Any], wtext: str) -> list[str]:
    """The gait as a dynamical system: the bifurcation over t1, the slope envelopes, the basins."""
    pr = d["premise"]
    slope_m = _dynamics_walks_m(d)[2]
    return [
        "## The gait as a dynamical system (`dynamics/`, beyond the paper)",
        "",
        "Each walk is read by its step periods after the transient its sweep names: period-k where every k-th "
        "period varies by less than 2 ms, read again at 10 ms (a controller that updates on a grid sees a "
        "touchdown only at its next update, so even a regular gait's periods jitter by up to its update period), "
        "irregular ones with a finite-size Lyapunov exponent from a neighbour walk (`drake-biped bifurcation`, "
        "`drake-biped basins`).",
        "",
        "### Bifurcation over t1, the learned t2 kept (`dynamics/t1/`)",
        "",
        embed(read_markdown(out, "dynamics/t1/bifurcation.md"), "dynamics/t1"),
        "![bifurcation over t1](dynamics/t1/bifurcation.png)",
        "",
        "### The slope premise (`dynamics/slope_without/`, `dynamics/slope_with/`)",
        "",
        f"The steepest slope climbed for {slope_m - SLOPE_LEVEL_M:g} m after {SLOPE_LEVEL_M:g} m level (every slope "
        "up to it climbed; the last slope of the sweep is a bound, ≥): without a window "
        f"**{_bound(pr, 'without_up_to')}** rad, with {wtext} **{_bound(pr, 'with_up_to')}** rad. Slopes where the window falls "
        f"and no window climbs: {', '.join(f'{v:g}' for v in pr['band']) or 'none'}. The paper's slope story "
        "needs such a band; its 0.02 rad is run as printed in the slope stories below.",
        "",
        "### Where starts end (`dynamics/basins/`)",
        "",
        embed(read_markdown(out, "dynamics/basins/basins.md"), "dynamics/basins"),
        "![basins](dynamics/basins/basins.png)",
        "",
    ]
