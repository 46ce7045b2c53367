"""floquet.md and floquet.png, drawn from a Floquet record alone (the `floquet` command's, and each condition's
under `stability --floquet`)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from drake_biped.analysis import floquet as fq
from drake_biped.legacy import clock_of_record


def _fmt(value: float | None, spec: str = ".4g") -> str:
    return "—" if value is None else format(value, spec)


def markdown(record: dict[str, Any], title: str = "Floquet multipliers of the periodic orbit") -> str:
    """floquet.md: the multipliers, the sweep, the modes and the cross-checks."""
    window = record["config"]["window"]
    has_window = window["end_s"] > window["start_s"]
    gait = f"torque-free period {window['start_s']:.3f}–{window['end_s']:.3f} s" if has_window else "no torque-free period"
    lines = [f"### {title} ({gait})", "",
             f"Full-state step map on the mid-stance section ({len(record['coordinates'])} coordinates), "
             f"central differences through Drake. Fixed point by Newton: residual "
             f"{record['start_residual']:.2e} → **{record['fixed_point_residual']:.2e}** (relative) in "
             f"{record['newton_iterations']} iterations"
             + (f"; the map's own evaluation noise there {record['evaluation_noise']:.1e}, so Newton's floor "
                f"{record['newton_floor']:.1e}." if record.get("evaluation_noise") is not None else "."), ""]
    p = record["plateau"]
    if p["epsilon"] is not None:
        lines.append(f"Converged ε = **{p['epsilon']:.1e}** (spectral radius within "
                     f"{100 * p['max_change']:.2f} % over {p['plateau'][0]:.0e}–{p['plateau'][1]:.0e}, "
                     f"{p['decades']:.1f} decades).")
    else:
        lines.append("No two neighbouring perturbation sizes agree: the Jacobian did not converge.")
    lines += ["", "| ε | spectral radius |", "|---|---|"]
    lines += [f"| {r['epsilon']:.1e} | {_fmt(r['spectral_radius'])} |" for r in record["epsilon_sweep"]]
    verdict = fq.record_verdict(record)
    verdict = f"{verdict} period-1 orbit" if verdict in ("stable", "unstable") else verdict
    lines += ["", f"**Spectral radius {record['spectral_radius']:.4f}** ({verdict}). Multipliers, largest first:",
              "", "| multiplier | modulus | mode (largest components) |", "|---|---|---|"]
    modes = {tuple(m["multiplier"]): m for m in record["dominant_modes"]}
    for k, (re, im) in enumerate(record["multipliers"][:6]):
        mode = modes.get((re, im))
        what = ", ".join(f"{c['name']} {c['magnitude']:.2f}" for c in mode["components"][:3]) if mode else (
            record["trivial"][k] or "")
        lines.append(f"| {re:.4f}{im:+.4f}i | {math.hypot(re, im):.4f} | {what} |")
    rest = len(record["multipliers"]) - 6
    if rest > 0:
        lines.append(f"| … {rest} more below {math.hypot(*record['multipliers'][6]):.1e} | | |")
    period = record.get("orbit_period")
    if period:
        transient, tol = record["settings"]["period_transient"], record["settings"]["period_tolerance"]
        if period.get("period"):
            k = period["period"]
            lead = period["multipliers"][0] if period.get("multipliers") else None
            lines += ["", f"**The map's attractor: period-{k}** (its iterates after {transient} steps repeat every {k} "
                      f"to {tol:g}); the {k}-fold map's leading multiplier "
                      + (f"{lead[0]:.4f}{lead[1]:+.4f}i (|{math.hypot(*lead):.4f}|)" if lead else "—")
                      + f", orbit residual {period['residual']:.1e}."]
        elif period.get("spread") is not None:
            lines += ["", f"**The map's iterates repeat with no period up to 8** (to {tol:g}, after {transient} "
                      f"steps; their coordinates still range over up to {period['spread']:.2g}): the period-1 "
                      "figures above are of the orbit Newton finds nearest, not one the iterates settle on."]
    d = record["decay"]
    lines += ["", "Perturbation of size {:.0e} along the dominant mode, |deviation| per step:".format(d["size"]), "",
              "| step | " + " | ".join(str(k + 1) for k in range(len(d["predicted"]))) + " |",
              "|---|" + "---|" * len(d["predicted"]),
              "| predicted J^k δ | " + " | ".join(f"{v:.2e}" for v in d["predicted"]) + " |",
              "| map iterated | " + " | ".join(f"{v:.2e}" for v in d["map_iterated"]) + " |"]
    if d.get("continued"):
        lines.append("| walk continued | " + " | ".join(f"{v:.2e}" for v in d["continued"]) + " |")
    if record.get("sampling_phase_drift"):
        period_ms = 1e3 * clock_of_record(record["config"]["sim"])[1]
        lines += ["", "The fixed point walked on without restarting the update grid drifts from itself by "
                  + ", ".join(f"{v:.1e}" for v in record["sampling_phase_drift"])
                  + f" per step: the gait's sensitivity to the phase of the {period_ms:g} ms control update, "
                  "which the map (restarted at each section) does not see."]
    if record.get("regression") is not None:
        lines += regression_lines(record["regression"])
    lines.append("")
    return "\n".join(lines)


def regression_lines(fit: dict[str, Any]) -> list[str]:
    """The least-squares fit's section of floquet.md (`floquet_runs.regression`)."""
    lines = ["", f"**Least-squares Jacobian** ({fit['samples']} random perturbations per size, each coordinate "
             "by the size times its scale; the fit's residual spread is the map's noise at that size, and a "
             "bootstrap of the fit gives the radius's 5–95 % range):", "",
             "| size | spectral radius | 5–95 % | noise | falls |", "|---|---|---|---|---|"]
    for r in fit["rows"]:
        span = "—" if r["interval"] is None else f"{r['interval'][0]:.3g}–{r['interval'][1]:.3g}"
        noise = "—" if r["noise"] is None else f"{r['noise']:.1e}"
        lines.append(f"| {r['size']:.0e} | {_fmt(r['radius'])} | {span} | {noise} | {r['falls']} |")
    p = fit["plateau"]
    if p["plateau"] is not None:
        lines += ["", f"Sizes that agree: {p['plateau'][0]:.0e}–{p['plateau'][1]:.0e} ({p['decades']:.1f} decades); "
                  f"at {p['size']:.0e}, the fitted map's fixed point has residual {fit['fixed_point_residual']:.1e} "
                  f"against the noise {fit['noise']:.1e}, spectral radius **{fit['radius']:.4f}** (5–95 % "
                  f"{fit['interval'][0]:.4f}–{fit['interval'][1]:.4f})."]
        for mode in fit["dominant_modes"][:2]:
            re, im = mode["multiplier"]
            lines.append(f"- {re:.4f}{im:+.4f}i: " + ", ".join(f"{c['name']} {c['magnitude']:.2f}"
                                                             for c in mode["components"][:3]))
    lines += ["", f"The fit's verdict: **{fit['verdict']}**."]
    return lines


def figure(record: dict[str, Any], path: Path) -> None:
    """floquet.png: the multipliers in the unit circle, and the sweep's spectral radius against ε."""
    from drake_biped.analysis.figures import floquet_figure

    floquet_figure(record, path)
