"""The verdicts of the reproduction report: each of the paper's claims judged from an experiment's summary, and
the paper's own figures for them read from `drake_biped.paper` (Tables V and VII)."""

from __future__ import annotations

from typing import Any

from drake_biped.analysis.cost_of_transport import GRAVITY_MPS2
from drake_biped.analysis.report_text import DIFFERS, NOT_REPRODUCED, PARTLY, REPRODUCED, pct
from drake_biped.analysis.rewalks import saving_spread, window_acted
from drake_biped.analysis.series import cmt_change
from drake_biped.paper import TABLE_V
from drake_biped.paper import TABLE_V_REDUCTION as PAPER_REDUCTION
from drake_biped.paper import TABLE_VII as TABLE_VII_PAPER

__all__ = ["climbs_2deg", "cost_without_verdict", "reduction_verdict", "slope_verdict", "stability_verdict", "table_v_claim",
           "table_vii_claim", "table_vii_rows"]

# How near Table V's C_mt without the window ours must be to reproduce it (relative).
COST_WITHOUT_TOLERANCE = 0.1
# The symbols of Table VII's parameters as the report writes them.
_SYMBOLS = {"u_a": "u_a", "u_r": "u_r", "kappa": "κ"}


def _whole_percent(x: float) -> str:
    """A change in whole percent with its sign, as the paper's tables read: "+37 %", "−50 %"."""
    return f"{100 * x:+.0f} %".replace("-", "−")


def table_v_claim() -> str:
    """Table V's claim in the report's words, from its numbers: "−50 % (0.58 → 0.29)"."""
    before, after = TABLE_V["CPG without torque-free period"], TABLE_V["CPG with torque-free period"]
    return f"{_whole_percent(-PAPER_REDUCTION)} ({before:g} → {after:g})"


def table_vii_claim() -> str:
    """Table VII's changes from Table III in the report's words: "u_a +37 %, u_r +25 %, κ +51 %"."""
    return ", ".join(f"{_SYMBOLS[name]} {_whole_percent(after / before - 1.0)}"
                     for name, (before, after) in TABLE_VII_PAPER.items())


def cost_without_verdict(evaluation: dict[str, Any]) -> tuple[str, str]:
    """Table V's first column, C_mt without the torque-free period: the learning run's walk without a window (its
    long-run mean where the record has one), beside the paper's 0.58, read as the dimensionless C_mt and given in the
    paper's printed unit (eq. 1 divides by kg, not by weight: C_mt x g, J/(kg*m)) too."""
    paper = TABLE_V["CPG without torque-free period"]
    no_window = evaluation.get("no_window") or {}
    cost = no_window.get("long_run_cost_of_transport")
    measure = evaluation.get("measure", "") if cost is not None else "its walk"
    if cost is None:
        cost = no_window.get("cost_of_transport")
    if cost is None:
        return "—", NOT_REPRODUCED
    ours = (f"{cost:.4f} ({measure}; {GRAVITY_MPS2 * cost:.2f} J/(kg·m) in eq. 1's printed unit), "
            f"{cost / paper:.2f} × the paper's")
    if abs(cost / paper - 1.0) <= COST_WITHOUT_TOLERANCE:
        return ours, REPRODUCED
    return ours, f"{DIFFERS}: {'below' if cost < paper else 'above'} the paper's by {abs(100 * (cost / paper - 1.0)):.0f} %"


def _windows_kept(evaluation: dict[str, Any]) -> int:
    """How many trials of a learning evaluation end with a window that frees the hip in a walk
    (`analysis.rewalks.window_acted`)."""
    no_window = evaluation.get("no_window")
    return sum(1 for r in evaluation.get("learned", []) if window_acted(r, no_window) and not r["fell"])


def reduction_verdict(evaluation: dict[str, Any]) -> tuple[str, str]:
    """Verdict on "the torque-free period cuts C_mt by 40-50 % and walking holds" for a learning run: judged on
    the learned windows re-walked with the plant step halved and from a nudged start (`rewalks`) where the
    record has them, else on one walk of each final mean."""
    walks = evaluation.get("learned_walks", 0)
    trials = len(evaluation.get("learned", []))
    windows = _windows_kept(evaluation)
    as_learned = evaluation.get("reduction")
    rewalked = evaluation.get("rewalks")
    if rewalked:
        reduction = rewalked["mean_saving"]
        spread = saving_spread(rewalked)
        spread = f"{spread} over trials" if spread.startswith("±") else spread.strip("()")
        ours = (f"C_mt {cmt_change(reduction)} re-walked at half the step and from "
                f"0.95 / 1.05 × the initiation speed ({spread}; "
                f"{rewalked['holding']} of {trials} trials save ≥ {100 * rewalked['hold_saving']:.0f} % in every "
                f"walk); as learned {cmt_change(as_learned)}, {walks} of {trials} walk, "
                f"{windows} end with a window")
    else:
        reduction = as_learned
        ours = f"C_mt {cmt_change(reduction)} (mean of the {walks} of {trials} trials " \
               f"that walk; {windows} end with a window; one walk each, not re-walked)"
    if reduction is None or walks == 0:
        return ours, NOT_REPRODUCED
    if reduction >= 0.40:
        return ours, REPRODUCED
    if reduction >= 0.05:
        return ours, f"{PARTLY}: {100 * reduction:.0f} % against the paper's {100 * PAPER_REDUCTION:.0f} %"
    return ours, NOT_REPRODUCED


def slope_verdict(summary: dict[str, Any]) -> tuple[str, str]:
    v = summary["verdicts"]
    held = [v["learned_period_fails_to_climb"], v["no_period_climbs"],
            v["learning_shrinks_the_period_until_it_climbs"] > 0]
    ours = (f"start period {'falls' if v['learned_period_fails_to_climb'] else 'climbs'}; none "
            f"{'climbs' if v['no_period_climbs'] else 'falls'}; learning: "
            f"{v['learning_shrinks_the_period_until_it_climbs']}/{v['trials']} trials end climbing")
    if all(held):
        return ours, REPRODUCED
    return ours, (PARTLY if any(held) else NOT_REPRODUCED) + f" ({sum(held)} of 3 claims hold)"


def stability_verdict(cells: dict[str, Any]) -> tuple[str, str]:
    flat = [(c, k, cell) for c, kinds in cells.items() for k, cell in kinds.items()]
    stable = sum(1 for *_, cell in flat if cell["stable"])
    diffs = [abs(cell["spectral_radius"] - cell["paper_spectral_radius"]) for *_, cell in flat
             if cell["spectral_radius"] is not None]
    ours = f"{stable} of 6 cells stable; ρ differs from the paper's by up to {max(diffs, default=0):.2f}"
    crossing = sum(1 for *_, cell in flat if cell["stable"] and cell.get("spectral_radius_ci")
                   and cell["spectral_radius_ci"][1] >= 1.0)
    if crossing:
        ours += f" ({crossing} of them with a 95 % interval of ρ reaching above 1)"
    if stable == 6 and crossing:
        return ours, f"{PARTLY}: all stable by their fits, {crossing} not established; eigenvalues: {DIFFERS}"
    if stable == 6:
        return ours, f"{REPRODUCED} (all stable); eigenvalues: {DIFFERS}"
    return ours, f"{NOT_REPRODUCED}: {6 - stable} cell(s) not stable"


def climbs_2deg(summary: dict[str, Any]) -> bool:
    """Whether any point of the 2.0 deg grid (its summary) climbs: else its best is only the furthest fall."""
    return bool(summary.get("walked"))


def table_vii_rows(summary: dict[str, Any]) -> tuple[list[str], str, str]:
    """Table VII's rows (paper and ours), our changes in a line, and the verdict."""
    base, best = summary["base_cpg"], summary["best"]["point"]
    rows, same, changes = [], 0, []
    for name, (before, after) in TABLE_VII_PAPER.items():
        ours_after = best.get(f"cpg.{name}", base[name])
        ours_change = ours_after / base[name] - 1.0
        paper_change = after / before - 1.0
        same += (ours_change > 0) == (paper_change > 0) and ours_change != 0
        rows.append(f"| {name} | {before:g} → {after:g} ({pct(paper_change)}) | {base[name]:.4g} → "
                    f"{ours_after:.4g} ({pct(ours_change)}) |")
        changes.append(f"{name} {pct(ours_change)}")
    others = [f"{k} = {v:.4g}" for k, v in best.items() if not k.startswith("cpg.")]
    note = f"; also {', '.join(others)}" if others else ""
    if not climbs_2deg(summary):  # the furthest fall is no 2.0 deg gait, and its parameters no Table VII
        return (rows, f"no point climbs (the furthest falls at {summary['best']['distance_m']:.2f} m)",
                f"{NOT_REPRODUCED}: none of the grid's {summary['points']} points climbs 2.0°")
    return rows, ", ".join(changes), f"{DIFFERS}: {same} of 3 CPG parameters move as in Table VII{note}"
