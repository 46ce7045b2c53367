"""The reproduction report: every experiment's tables and figures beside the paper's, each with a verdict.

Built from the experiments' summaries (DIR/<name>/summary.json) and the Markdown each experiment writes
itself (Table V, the stability report, the slope reports, the time-step study), which are embedded with
their headings demoted and their figure links made relative to DIR. The HTML is the same Markdown rendered
by Python-Markdown (tables extension), figures linked from the experiments' folders.

Named for the `reproduce` command (drake_biped/experiments/reproduce.py) by design: that runs the experiments,
this writes their report.
"""

from __future__ import annotations

import html
import json
from pathlib import Path
from typing import Any

from drake_biped.analysis.cost_of_transport import format_cost
from drake_biped.analysis.dynamics_report import (
    dynamics_rows,
    dynamics_section,
    floquet_text,
)
from drake_biped.analysis.energy_report import energy_section, energy_walks_section
from drake_biped.analysis.report_figures import quick_summary_figure, summary_figure
from drake_biped.analysis.report_text import (
    BEYOND,
    DIFFERS,
    NOT_REPRODUCED,
    REPRODUCED,
    embed,
    num,
    pct,
    read_markdown,
    steps_text,
)
from drake_biped.analysis.verdicts import (
    climbs_2deg,
    cost_without_verdict,
    reduction_verdict,
    slope_verdict,
    stability_verdict,
    table_v_claim,
    table_vii_claim,
    table_vii_rows,
)
from drake_biped.paper import TABLE_V
from drake_biped.records import read_json, write_text_atomic


def _margin(margins: dict, condition: str, direction: str) -> str:
    """One margin of a push-margin summary (`Reproduction.push_margin`) in N."""
    m = margins[condition]
    return _n(m[direction], m.get(f"{direction}_at_grid_top", False))


def _n(force, at_top: bool = False) -> str:
    """A margin in N, "≥ N" where every force tried survived, or — where none was measured."""
    return "—" if force is None else ("≥ " if at_top else "") + f"{force:.0f}"


# What a push-margin step recorded before its summary held its method: PushMarginSettings' values then.
_MARGIN_METHOD_BEFORE = {"phases": 12, "settle_s": 5.0, "max_force_n": 100.0, "push_duration_s": 0.1}


def _margin_method(settings: dict, method: dict | None = None) -> str:
    """How a push-margin step measured its margins, from its settings and the method its summary records."""
    if "force_step_n" in settings:
        m = method or _MARGIN_METHOD_BEFORE
        return (f"Pushes of {m['push_duration_s']:g} s in steady state ({m['phases']} phases of the first step after "
                f"{m['settle_s']:g} s of a {settings['distance_m']:g} m walk) on a grid {settings['force_step_n']:g} N "
                f"apart up to {m['max_force_n']:g} N; the margin is the largest force at and below which every phase "
                "survives (the paper pushes ±20 N); a margin at the grid's top is a bound (≥):")
    return (f"The largest push over 0.1 s from 0.4 s after which the gait still walks {settings['distance_m']:g} m, "
            f"by bisection to {settings['tolerance_n']:g} N from 200 N (the paper pushes ±20 N):")

def _start_text(settings: dict) -> str:
    """A learning run's start, from its settings record: "start 0.5, 0.5 s; σ² 0.04"."""
    learner = settings["learner"]
    return f"start {learner['mean'][0]:g}, {learner['mean'][1]:g} s; σ² {learner['variance']:g}"


# The claims' rows of the full report, in order: the keys a quick run matches its own rows with.
CLAIM_KEYS = ("table_iii", "paper_gait", "grid", "learn", "table_v_without", "learn_variant", "compare_learners", "stability",
              "push_margin", "floquet", "attractors", "slope_premise", "table_iii_attractor", "slope", "slope2deg",
              "table_vii", "time_step")
# The rows of the dynamics step (a run made before it has none).
DYNAMICS_KEYS = ("attractors", "slope_premise", "table_iii_attractor")
# The learning runs whose evaluated windows a quick run re-walks (DIR/<source>/learning.json).
CHECKED_SOURCES = {"learn": ("learn",), "learn_variant": ("learn_variant",)}
# The shipped gaits other than the default, and why each exists (the report's closing section).
def claim_rows(verdicts: list[tuple[str, str, str, str]]) -> list[dict[str, str]]:
    """The verdict tuples as keyed rows (CLAIM_KEYS)."""
    keys = CLAIM_KEYS
    if len(verdicts) == len(CLAIM_KEYS) - len(DYNAMICS_KEYS):
        keys = tuple(k for k in CLAIM_KEYS if k not in DYNAMICS_KEYS)
    if len(verdicts) != len(keys):
        raise ValueError(f"expected {len(CLAIM_KEYS)} claims, got {len(verdicts)}")
    return [{"key": k, "what": a, "paper": b, "ours": c, "verdict": d} for k, (a, b, c, d) in zip(keys, verdicts)]


def _hip_reading(paper_gait: dict[str, Any]) -> str:
    """How the `paper` gait's hip realizes zeta, from its summary (a summary without its gait is of the
    integrated servo reading, the `paper` gait then)."""
    gait = paper_gait.get("gait") or {"hip_drive": "servo", "swing_reading": "integrated"}
    if gait.get("hip_drive") == "motor":
        joint = "the swing hip joint" if gait.get("hip_joint", "swing") == "swing" else "the inter-leg angle"
        return (f"ζ the desired velocity of {joint}, realized by an effort-limited velocity motor as ODE's "
                f"({gait['motor_limit_nm']:.3g} N·m), at {1e3 * paper_gait.get('time_step_s', 1e-3):g} ms")
    return f"ζ driving the swing thigh's angle through a soft servo (the {gait.get('swing_reading')} reading)"


def table_iii_rank(out: Path) -> tuple[int, int] | None:
    """Where Table III's own walk (grid/table_iii.json) ranks among the grid's points (grid/points.jsonl), by
    the grid's order (further, then cheaper): (rank, walks ranked, Table III's included); None without them."""
    import gzip

    from drake_biped.analysis.grid_ranking import rank
    from drake_biped.records import read_kept, read_kept_lines, stored

    own = read_kept(out / "grid" / "table_iii.json")
    points = stored(out / "grid" / "points.jsonl")  # a committed run keeps it compressed
    if not isinstance(own, dict) or not points.is_file():
        return None
    if points.suffix == ".gz":
        with gzip.open(points, "rt") as f:
            rows = [json.loads(line) for line in f if line.strip()]
    else:
        rows = read_kept_lines(points, "a grid point record", lambda r: isinstance(r, dict))
    return rank(own, rows), len(rows) + 1


def gait_label(gait: str) -> str:
    """How the report names the gait a run walks: "the `paper` gait", "the `fast_servo` gait"."""
    return f"the `{gait}` gait"


def walk_section(walk: dict[str, Any], gait: str = "paper", energy_walks: dict[str, Any] | None = None) -> list[str]:
    """The report's section on the gait's walk (`walk/`), from its summary."""
    return [
        "## The walk (`walk/`)",
        "",
        f"{gait_label(gait)[0].upper()}{gait_label(gait)[1:]} from the paper's initiation: {walk['distance_m']:.2f} m, C_mt "
        f"{format_cost(walk['cost_of_transport'], '—')}, {walk['mean_speed_mps']:.2f} m/s, step {num(walk['step_period_s'])} s, "
        f"real-time factor {walk['real_time_factor']:.1f}. Animation: [walk.html](walk/walk.html) (Meshcat), "
        "[walk.gif](walk/walk.gif); record: [result.json](walk/result.json).",
        "",
        "![walk](walk/walk.png)",
        "",
        *energy_section(walk.get("energy")),
        *energy_walks_section(walk, energy_walks),
    ]


def report_markdown(out: Path, s: dict[str, dict[str, Any]], profile: Any, code: dict[str, Any],
                    gait: str = "paper", choices: str = "") -> tuple[str, list]:
    label = gait_label(gait)
    window = tuple(s["push_margin"]["settings"]["window"])  # the learned window (Reproduction.learned_window)
    source = s["push_margin"]["window_source"]
    wtext = _window_text(window)
    wname = window_name(source)
    wall = sum(x.get("wall_s") or 0.0 for x in s.values())
    verdicts: list[tuple[str, str, str, str]] = []  # (what, paper, ours, verdict)

    walk = s["walk"]
    grid = s["grid"]
    t3 = grid["table_iii"]
    verdicts.append((f"Table III walks ({label}'s other gains)", "walks (the grid's best)",
                     ("walks" if not t3["fell"] else f"falls after {steps_text(t3['steps'])}")
                     + f", {t3['distance_m']:.2f} m", REPRODUCED if not t3["fell"] else NOT_REPRODUCED))
    pg = s["paper_gait"]
    verdicts.append(("Table III walks, ζ driving the swing as printed (unprinted gains searched)", "walks",
                     ("walks" if not pg["fell"] else f"falls after {steps_text(pg['steps'])}") + f", {pg['distance_m']:.2f} m",
                     REPRODUCED if not pg["fell"] else NOT_REPRODUCED))
    best = grid["best"]
    ranked = table_iii_rank(out)
    rank_text = "" if ranked is None else f"; Table III ranks {ranked[0]} of {ranked[1]}"
    verdicts.append(("Table IV grid: furthest walk", "Table III, walks",
                     f"{best['distance_m']:.2f} m of {grid['points']} points ({grid['walked']} walk "
                     f"{profile.distance_m:g} m){rank_text}", REPRODUCED if ranked and ranked[0] == 1 else DIFFERS))
    learn_ours, learn_verdict = reduction_verdict(s["learn"]["evaluation"])
    verdicts.append(("Table V: C_mt reduction by learning (paper's settings)", table_v_claim(),
                     learn_ours, learn_verdict))
    verdicts.append(("Table V: C_mt without the torque-free period",
                     f"{TABLE_V['CPG without torque-free period']:g}", *cost_without_verdict(s["learn"]["evaluation"])))
    var_ours, var_verdict = reduction_verdict(s["learn_variant"]["evaluation"])
    verdicts.append(("C_mt reduction, exploration matched to the gait", "—", var_ours, f"{BEYOND}; {var_verdict}"))
    cl = s["compare_learners"]
    verdicts.append(("Learners side by side: final C_mt (best window)", "—",
                     ", ".join(f"{name} {format_cost(r['final_cost_of_transport'], '—')}" for name, r in cl["learners"].items())
                     + (f" (best window {format_cost(cl['best_window']['cost_of_transport'], '—')})" if cl["best_window"]
                        else " (no window walks)"), BEYOND))
    stab_ours, stab_verdict = stability_verdict(s["stability"]["cells"])
    verdicts.append((f"Table VI: stable under ±20 N, none vs {wname} ({wtext})", "all stable", stab_ours,
                     stab_verdict))
    m = s["push_margin"]["margins"]
    verdicts.append(("Push margins (forward / backward)", "survives ±20 N", f"none {_margin(m, 'without', 'forward')} / "
                     f"{_margin(m, 'without', 'backward')} N, {wtext} {_margin(m, 'with', 'forward')} / "
                     f"{_margin(m, 'with', 'backward')} N", BEYOND))
    verdicts.append(("Full-state Floquet multipliers (periodic orbit, through Drake)", "—",
                     floquet_text(s["floquet"]["gaits"]), BEYOND))
    if "dynamics" in s:
        verdicts += dynamics_rows(s["dynamics"], wtext)
    on_2deg = ("with the grid's best" if climbs_2deg(s["grid_slope2deg"])
               else f"on {label} (no grid point climbs)")
    for name, claim in (("slope", "Slope story, 0.02 rad (Figs. 8–9)"),
                        ("slope2deg", f"Slope story, 2.0° {on_2deg} (Figs. 10–11)")):
        ours, verdict = slope_verdict(s[name])
        verdicts.append((claim, "all three claims", ours, verdict))
    vii_rows, vii_changes, vii_verdict = table_vii_rows(s["grid_slope2deg"])
    verdicts.append(("Table VII: CPG parameters for 2.0°", table_vii_claim(), vii_changes,
                     vii_verdict))
    ts = s["time_step"]
    chosen = "none" if ts["chosen_step_s"] is None else f"{1e3 * ts['chosen_step_s']:g} ms"
    ran = _ms(s["learn"]["settings"]["config"]) if "config" in s.get("learn", {}).get("settings", {}) else None
    verdicts.append(("Time step", "—", f"chosen {chosen}" + (f"; this run's experiments at {ran}"
                                                              if ran is not None and ran != chosen else ""), BEYOND))

    summary_figure(verdicts, f"drake-biped reproduce ({profile.name}): the paper's claims, measured on one gait",
                   out / "report_summary.png")
    lines = [
        "# drake-biped: the paper reproduced, experiment by experiment",
        "",
        f"Profile **{profile.name}** ({_profile_text(profile)}); {len(s)} experiments, whose sessions in this "
        f"folder took {wall / 60:.1f} min (work found already done in the folder, such as learning episodes "
        f"resumed, is not counted). drake-biped {code.get('drake_biped')} ({code.get('git_commit')}), Drake "
        f"{code.get('drake')}. Paper: Takita, Azuma & Shibata, *Acquisition of Energy-Efficient Bipedal Walking "
        "Using CPG-Based Reinforcement Learning*. Every claim is measured on one gait, "
        + f"`{gait}`" + " (its "
        f"plant step {_ms(s['learn']['settings']['config'])}), with one torque-free window: {wtext}, {source}. Each row "
        f"links to its section, each number in the folder named there. {provenance_text(s)}"
        + (f" What this gait's story chooses where the paper prints nothing: {choices}." if choices else ""),
        "",
        "| what | paper | ours | verdict |",
        "|---|---|---|---|",
    ]
    lines += [f"| {a} | {b} | {c} | **{d}** |" for a, b, c, d in verdicts]
    lines += [
        "",
        "![verdicts](report_summary.png)",
        "",
        *walk_section(walk, gait, s.get("energy")),
        "## Grid search, Table IV (`grid/`)",
        "",
        f"{grid['points']} points over Table IV's CPG ranges and the initiation, level ground, one episode each: "
        f"{grid['walked']} walk {profile.distance_m:g} m; the furthest, {best['distance_m']:.2f} m, at "
        + ", ".join(f"{k.split('.')[-1]} {v:.3g}" for k, v in best["point"].items())
        + f". Table III itself (with {label}'s other gains) "
        + ("walks" if not t3["fell"] else f"falls after {steps_text(t3['steps'])}")
        + f" ({t3['distance_m']:.2f} m)"
        + ("" if ranked is None else f" and ranks {ranked[0]} of {ranked[1]} among them, further then cheaper "
           "first")
        + f". {label[0].upper()}{label[1:]}'s CPG: "
        + ", ".join(f"{k} {v:.4g}" for k, v in s["learn"]["settings"]["config"]["cpg"].items()) + ".",
        "",
        "![grid](grid/grid_slices.png)",
        "",
    ]
    lines += [
        "## Table III as printed (`paper_gait/`)",
        "",
        f"The shipped gait `paper`: Table III's CPG ({', '.join(f'{k} {v:g}' for k, v in pg['cpg'].items())}) and the "
        f"paper's initiation, {_hip_reading(pg)}, the gains the paper does not print searched (the gait's `about`): "
        + (f"walks {pg['distance_m']:.2f} m" if not pg["fell"] else f"falls after {steps_text(pg['steps'])} ({pg['fall_reason']}), "
                                              f"{pg['distance_m']:.2f} m")
        + ". Record: [result.json](paper_gait/result.json).",
        "",
    ]
    wm = s["window_map"]
    wbest = wm["best"]
    lines += [
        f"## Torque-free windows of {label} (`window_map/`)",
        "",
        f"{wm['walked']} of {wm['windows']} windows walk {profile.distance_m:g} m; no window C_mt "
        f"{format_cost(wm['no_window_cost_of_transport'], '—')}"
        + ("" if wbest is None else f"; the cheapest, {wbest['t1']:g}–{wbest['t2']:g} s, C_mt "
           f"{format_cost(wbest['cost_of_transport'], '—')} ({pct(wbest['cmt_change'])})") + ".",
        "",
        "![window map](window_map/window_map.png)",
        "",
        "## Experiment 1: learning the torque-free period (Table V, Figs. 4–6; `learn/`)",
        "",
        f"Verdict: **{learn_verdict}**. {s['learn']['settings']['trials']} trials × "
        f"{s['learn']['settings']['episodes']} episodes, the paper's settings ({_start_text(s['learn']['settings'])}; "
        f"Table II); {num(s['learn']['episodes_per_min'], 1)} episodes/min. Each trial's final policy mean is "
        "re-walked with the plant step halved and from 0.95 and 1.05 × the initiation speed, each against no "
        "window under the same change.",
        "",
        embed(read_markdown(out, "learn/table_v.md"), "learn"),
        "![Fig. 4](learn/fig4_reward.png)",
        "![Fig. 5](learn/fig5_cmt.png)",
        "![Fig. 6](learn/fig6_times.png)",
        "",
        "### Exploration matched to the gait (`learn_variant/`)",
        "",
        f"Verdict: **{var_verdict}**. {_start_text(s['learn_variant']['settings']).capitalize()}, where the "
        "paper's is 0.5, 0.5 s with σ² 0.04 (σ = 0.2 s).",
        "",
        embed(read_markdown(out, "learn_variant/table_v.md"), "learn_variant"),
        "![Fig. 6, variant](learn_variant/fig6_times.png)",
        "",
        f"## Pushes and return maps (Table VI, Fig. 7; `stability/`), {wname} {wtext}",
        "",
        f"Verdict: **{stab_verdict}**. The window: {source}.",
        "",
        embed(read_markdown(out, "stability/report.md"), "stability"),
        "### Push margins (`push_margin/`)",
        "",
        _margin_method(s["push_margin"]["settings"], s["push_margin"].get("method")),
        "",
        "| | forward (N) | backward (N) |",
        "|---|---|---|",
        f"| no torque-free period | {_margin(m, 'without', 'forward')} | {_margin(m, 'without', 'backward')} |",
        f"| {wname}, {wtext} | {_margin(m, 'with', 'forward')} | {_margin(m, 'with', 'backward')} |",
        "",
        "### The periodic orbit and its Floquet multipliers (`floquet/`)",
        "",
        "Beyond the paper's 2-D regression above: the fixed point of the full-state step map on the mid-stance "
        "section (Newton) and its Jacobian's eigenvalues by central differences through Drake, for the gait "
        "without a window and with the learned one. The regression is fitted over pushes "
        "(deviations of 10⁻²–10⁻¹); the multipliers are the map's derivative at the orbit (deviations below "
        "10⁻⁴, where the sweep converges); the sweep's larger ε show the map contracting at the pushes' scale.",
        "",
    ]
    for name in s["floquet"]["gaits"]:
        lines += [embed(read_markdown(out, f"floquet/{name}/floquet.md"), f"floquet/{name}"),
                  f"![Floquet multipliers, {name}](floquet/{name}/floquet.png)", ""]
    if "dynamics" in s:
        lines += dynamics_section(out, s["dynamics"], wtext)
    g2 = s["grid_slope2deg"]
    lines += [
        "## Slopes (Figs. 8–11, Table VII)",
        "",
        f"{label[0].upper()}{label[1:]} on 2 m level, then the slope, 10 m in all. The learner starts from "
        f"{wname} "
        f"({wtext}; from its learning record's policy when a trial learned it, else with σ² 0.04).",
        "",
    ]
    for name, figs in (("slope", "Figs. 8–9, 0.02 rad"), ("slope2deg", "Figs. 10–11, 2.0°")):
        if name == "slope2deg":
            lines += [
                f"### Table VII: CPG parameters for 2.0° (`grid_slope2deg/`, {g2['points']} points, {g2['walked']} "
                "climb)",
                "",
                f"Verdict: **{vii_verdict}**. Ours: {label} with its torso leaned further forward, a larger "
                "placement gain and u_a, u_r, κ raised as Table VII raises them; the 2.0° story runs on the grid's "
                f"best ({label} itself when no point climbs).",
                "",
                f"| parameter | paper: Table III → Table VII | ours: {gait} → "
                + ("2.0° best |" if climbs_2deg(g2) else "the furthest fall (nothing climbs) |"),
                "|---|---|---|",
                *vii_rows,
                "",
            ]
        point = s[name].get("point") or {}
        lines += [
            f"### The slope story, {figs} (`{name}/`)",
            "",
            f"Verdict: **{slope_verdict(s[name])[1]}**. The gait: {label}"
            + ("" if not point else " with " + ", ".join(f"{k.split('.')[-1]} {v:.4g}" for k, v in point.items()))
            + ".",
            "",
            embed(read_markdown(out, f"{name}/report.md"), name),
            f"![period]({name}/fig8_period.png)",
            f"![distance]({name}/fig9_distance.png)",
            "",
        ]
    lines += [
        "## Learners side by side (`compare_learners/`, beyond the paper)",
        "",
        embed(read_markdown(out, "compare_learners/compare.md"), "compare_learners"),
        "![learners](compare_learners/compare.png)",
        "",
        "## Time step (`time_step/`)",
        "",
        embed(read_markdown(out, "time_step/time_step_study.md"), "time_step"),
        "![time step](time_step/time_step_study.png)",
        "",
        *other_gaits_section(gait),
        "Rerun the same command to reuse every finished experiment; `drake-biped reproduce --out DIR` (without "
        "`--quick`) is the full run.",
        "",
    ]
    return "\n".join(lines), verdicts


def other_gaits_section(gait: str = "paper") -> list[str]:
    """The report's closing section: the shipped gaits other than the run's, and why each exists."""
    from drake_biped.resources import gait_about, gait_names

    lines = ["## Other gaits, and why each exists", "",
             f"Every claim above is measured on {gait_label(gait)}. The other shipped gaits (`--params NAME`) each "
             "told part of the story before it; their records are in docs/HISTORY.md. Each one's reasons are its "
             "file's `about` (drake_biped/gaits/).", "",
             "| gait | why it exists |", "|---|---|"]
    lines += [f"| `{name}` | {gait_about(name)} |" for name in gait_names() if name != gait]
    return lines + [""]


def window_name(source: str) -> str:
    """What the story's window is, in words, from where it came (Reproduction.learned_window's source): "the
    learned window" when a trial learned it, else "the window map's cheapest window", else (no window of the map
    walks) "the window its gait file declares"."""
    if source.startswith("learned"):
        return "the learned window"
    return "the window map's cheapest window" if source.startswith("the window map") else \
        "the window its gait file declares"


def _window_text(window) -> str:
    return f"{window[0]:g}–{window[1]:g} s"


def _ms(config: dict[str, Any]) -> str:
    """A recorded configuration's plant time step, in ms."""
    return f"{1e3 * config['sim']['time_step_s']:g} ms"


def _profile_text(p: Any, ran: list[str] | None = None) -> str:
    """The profile's sizes; `ran`: the steps this run ran (a profile of a few steps says which)."""
    if getattr(p, "steps", ()):
        return f"steps: {', '.join(ran if ran is not None else p.steps)}; learning {p.learn[0]}×{p.learn[1]} episodes"
    return (f"learning {p.learn[0]}×{p.learn[1]} and {p.learn_variant[0]}×{p.learn_variant[1]} episodes, "
            f"{p.stability_trials} trials per stability cell, slope learning {p.slope[0]}×{p.slope[1]}, "
            f"grid {p.grid_points} points per Table IV range")


def report_html(markdown_text: str) -> str:
    import markdown

    body = markdown.markdown(markdown_text, extensions=["tables"])
    return ("<!doctype html><html><head><meta charset='utf-8'><title>"
            + html.escape("drake-biped: reproduction report") + "</title><style>"
            "body{font-family:sans-serif;max-width:1100px;margin:2em auto;line-height:1.4}"
            "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 7px;"
            "font-size:90%}img{max-width:100%}</style></head><body>" + body + "</body></html>\n")


def full_run_digest(out: Path, verdicts: list[tuple[str, str, str, str]], profile: Any,
                    code: dict[str, Any]) -> dict[str, Any]:
    """What a quick run needs of a full one: its keyed verdict rows, and for the learning runs of
    CHECKED_SOURCES their configuration, the code that made them and the C_mt each evaluated window (and no
    window) gave, to be re-walked and compared. `code`: the report's own."""
    checks = {}
    for key, (source,) in CHECKED_SOURCES.items():
        record = read_json(out / source / "learning.json", "the full run")
        ev = record["evaluation"]
        config = record["settings"]["config"]
        # What the record's own configuration walks: the paper's 10 m episode where the windows were re-walked
        # long (their long-run figures need 110 m walks, beyond a quick run), else the re-walks themselves.
        episode = ev.get("episode")
        if episode is not None and episode.get("distance_m") == config["sim"]["distance_m"]:
            no_window, costs = episode["no_window"], episode["learned"]
        else:
            no_window, costs = ev["no_window"]["cost_of_transport"], [r["cost_of_transport"] for r in ev["learned"]]
        checks[key] = {"source": f"{source}/learning.json", "config": config, "versions": record["versions"],
                       "no_window": no_window,
                       "learned": [{**{k: r[k] for k in ("trial", "t1", "t2", "fell")}, "cost_of_transport": c}
                                   for r, c in zip(ev["learned"], costs)]}
    return {"profile": profile.name, "report_code": code,
            "code": checks[next(iter(CHECKED_SOURCES))]["versions"], "rows": claim_rows(verdicts), "checks": checks}


def provenance_text(s: dict[str, dict[str, Any]]) -> str:
    """Which steps this run measured and which it reused from the records already in its folder (a resumed or
    copied folder), each reused one with the code that measured it, as its summary records it."""
    reused = [name for name, x in s.items() if x.get("reused")]
    if not reused:
        return "Every number below is measured by this run."
    by: dict[str, list[str]] = {}
    for name in reused:
        code = s[name].get("measured_by")
        key = (f"drake-biped {code.get('drake_biped')} ({code.get('git_commit')}), Drake {code.get('drake')}"
               if code else "code not recorded")
        by.setdefault(key, []).append(name)
    measured = [name for name in s if name not in reused]
    return (f"Measured by this run: {', '.join(measured) or 'none'}. Reused from the records already in this "
            "folder, not measured again: " + "; ".join(f"{', '.join(names)} (measured by {key})"
                                                        for key, names in by.items()) + ".")


def write_report(out: Path, summaries: dict[str, dict[str, Any]], profile: Any,
                 code: dict[str, Any], full_run: dict[str, Any] | None = None, gait: str = "paper",
                 choices: str = "") -> list[Path]:
    """report.md, report.html and report_summary.png of a run on `gait` (`choices`: what its story chooses
    where the paper prints nothing); a full run also writes verdicts.json (full_run_digest), which a quick run
    checks; a quick run's report is quick_report_markdown's, beside `full_run`."""
    paths = [out / "report.md", out / "report.html"]
    if profile.name == "quick":
        text = quick_report_markdown(out, summaries, profile, code, full_run, gait)
    else:
        text, verdicts = report_markdown(out, summaries, profile, code, gait, choices)
        paths.append(out / "verdicts.json")
        write_text_atomic(paths[-1], json.dumps(full_run_digest(out, verdicts, profile, code), indent=1) + "\n")
    write_text_atomic(paths[0], text)
    write_text_atomic(paths[1], report_html(text))
    return paths


CANNOT_JUDGE = "cannot judge at this size"


def _check_text(check: dict[str, Any] | None) -> str:
    if not check:
        return ""
    n, agree = check["walks"], check["agree"]
    rule = check.get("rule", "last digit")  # the record's machine: the last digit; another, or none named: a tolerance
    within = "to the last digit" if rule == "last digit" else f"within a {rule} (the record names another machine or none)"
    diff = check["max_relative_difference"]
    largest = f"largest difference {'n/a' if diff is None else f'{100 * diff:.3f} %'}"
    if agree == n:
        if rule == "last digit":
            return f" ✓ checked here: {n} re-walk{'s give' if n > 1 else ' gives'} the recorded C_mt {within}"
        return (f" ✓ checked here: {n} re-walk{'s give' if n > 1 else ' gives'} the recorded C_mt {within}, "
                f"{check.get('same_digits', 0)} of {n} to the last digit ({largest})")
    return f" ✗ checked here: {agree} of {n} re-walks give the recorded C_mt {within} ({largest})"


def quick_rows(s: dict[str, dict[str, Any]], full_run: dict[str, Any] | None) -> list[dict[str, str]]:
    """One row per claim of the full report: what this quick run measured (or that it did not run it, or
    that its size cannot judge it) beside the shipped full run's verdict, with the live check of the
    full run's learned windows where it has one."""
    mine: dict[str, tuple[str, str]] = {}
    if "table_iii" in s:
        t3 = s["table_iii"]
        mine["table_iii"] = (("walks" if not t3["fell"] else f"falls after {steps_text(t3['steps'])}")
                             + f", {t3['distance_m']:.2f} m", REPRODUCED if not t3["fell"] else NOT_REPRODUCED)
    if "paper_gait" in s:
        pg = s["paper_gait"]
        mine["paper_gait"] = (("walks" if not pg["fell"] else f"falls after {steps_text(pg['steps'])}")
                              + f", {pg['distance_m']:.2f} m", REPRODUCED if not pg["fell"] else NOT_REPRODUCED)
    if "learn" in s:
        ours, _ = reduction_verdict(s["learn"]["evaluation"])
        st = s["learn"]["settings"]
        mine["learn"] = (f"{ours} after {st['trials']} × {st['episodes']} episodes (the paper: 500)", CANNOT_JUDGE)
    if "floquet" in s:
        mine["floquet"] = (floquet_text(s["floquet"]["gaits"]), BEYOND)
    checks = (s.get("full_run") or {}).get("checks", {})
    rows = []
    for row in (full_run or {}).get("rows", []):
        ours, verdict = mine.get(row["key"], ("not run at this size", ""))
        rows.append({"what": row["what"], "paper": row["paper"], "this_run": ours, "this_verdict": verdict,
                     "full_run": f"{row['ours']}: {row['verdict']}" + _check_text(checks.get(row["key"])),
                     "full_verdict": row["verdict"]})
    return rows


# Where each gait's committed full run lives in the repository (its report, records and verdicts.json).
FULL_RUN_RECORDS = {"fast_servo": "benchmarks/results/reproduce-full", "paper": "benchmarks/results/reproduce-paper"}


def full_run_records(full_run: dict[str, Any] | None) -> str:
    """The repository folder of the shipped full run (FULL_RUN_RECORDS, by the gait its checks walked)."""
    return FULL_RUN_RECORDS.get(full_run_gait_name(full_run) or "paper", FULL_RUN_RECORDS["paper"])


def full_run_gait_name(full_run: dict[str, Any] | None) -> str | None:
    """The shipped gait (`--params NAME`) whose CPG, gains and initiation the full run's checks walked:
    "paper", another shipped gait's name, or None (another gait, or no checks recorded)."""
    from drake_biped.legacy import config_of_record
    from drake_biped.resources import gait_names, load_gait

    configs = [c["config"] for c in (full_run or {}).get("checks", {}).values() if "config" in c]
    if not configs:
        return None
    def walked(config):  # what the controller reads: a field the gait's readings leave unread is no difference
        return config.cpg, config.gait.as_walked(), config.initial

    recorded = walked(config_of_record(configs[0]))  # a record older than a field reads its default
    for name in sorted(gait_names(), key=lambda n: n != "paper"):
        if recorded == walked(load_gait(name)):
            return name
    return None


def full_run_gait(full_run: dict[str, Any] | None, gait: str = "paper") -> str | None:
    """The gait the shipped full run was measured on, when it is not `gait` (the one this run walks): the
    shipped gait's name, quoted, else "another gait"; None when it is `gait` (or the full run records no
    checks)."""
    if not (full_run or {}).get("checks"):
        return None
    name = full_run_gait_name(full_run)
    if name == gait:
        return None
    return "another gait" if name is None else f"`{name}`"


def quick_report_markdown(out: Path, s: dict[str, dict[str, Any]], profile: Any, code: dict[str, Any],
                          full_run: dict[str, Any] | None, gait: str = "paper") -> str:
    rows = quick_rows(s, full_run)
    wall = sum(x.get("wall_s") or 0.0 for x in s.values())
    other = full_run_gait(full_run, gait)
    quick_summary_figure(rows, out / "report_summary.png", other)
    walk, fr = s["walk"], s.get("full_run") or {}
    full_code = (full_run or {}).get("code", {})
    lines = [
        "# drake-biped: the paper reproduced — quick run, beside the shipped full run",
        "",
        f"Profile **quick** ({_profile_text(profile, list(s))}); {len(s)} steps, {wall / 60:.1f} min. drake-biped "
        f"{code.get('drake_biped')} ({code.get('git_commit')}), Drake {code.get('drake')}. This run is too small "
        "to judge most of the paper's claims (learning needs hundreds of episodes, a stability cell several "
        "trials): where it cannot, its column says so, and the full run's verdict stands beside it, "
        f"from the records shipped with the package (full run: drake-biped {full_code.get('git_commit')}, "
        f"Drake {full_code.get('drake')}). {provenance_text(s)}"
        + (" The full run's learned windows, and no window, were walked again here: where they give the C_mt the "
           "full run recorded, its row says so (✓)." if fr else ""),
        "",
    ]
    if other is not None:
        lines += [f"The shipped full run was measured on {other}, not on {gait_label(gait)} this run walks: its "
                  "column is that gait's" + (" (its windows were walked again on it)." if s.get("full_run") else
                                             "; its windows are walked again only by a quick run on its gait."), ""]
    lines += [
        "| what | paper | this run (quick) | full run (checked here) |",
        "|---|---|---|---|",
    ]
    lines += [f"| {r['what']} | {r['paper']} | {r['this_run']}" + (f" — **{r['this_verdict']}**" if r["this_verdict"]
              else "") + f" | {r['full_run'].replace(r['full_verdict'], '**' + r['full_verdict'] + '**', 1)} |"
              for r in rows]
    lines += [
        "",
        "![verdicts](report_summary.png)",
        "",
        *walk_section(walk, gait, s.get("energy")),
    ]
    if fr:
        lines += ["## The full run's learned windows, walked again here (`full_run/`)", "",
                  "| learning run | window (s) | C_mt recorded | C_mt here | same |", "|---|---|---|---|---|"]
    for check in fr.get("checks", {}).values():
        for w in check["rows"]:
            window = "none" if w["t2"] <= max(0.0, w["t1"]) else f"{max(0.0, w['t1']):.3f}–{w['t2']:.3f}"
            lines.append(f"| {check['source']} | {window} | {num(w['recorded'], 6)} | {num(w['measured'], 6)} | "
                         + ("yes" if w["recorded"] == w["measured"] else
                            f"{'agrees' if w.get('agrees') else 'no'}"
                            + ("" if w["relative_difference"] is None else f": {100 * w['relative_difference']:+.3f} %"))
                         + " |")
    if "learn" in s:
        lines += ["", "## Learning, a few episodes (`learn/`)", "",
                  f"GARB with the paper's settings for {s['learn']['settings']['trials']} × "
                  f"{s['learn']['settings']['episodes']} episodes: the machinery of Experiment 1, too short to "
                  "judge it.", "", embed(read_markdown(out, "learn/table_v.md"), "learn"),
                  "![Fig. 4](learn/fig4_reward.png)", ""]
    if "floquet" in s:
        for name in s["floquet"]["gaits"]:
            lines += [embed(read_markdown(out, f"floquet/{name}/floquet.md"), f"floquet/{name}"),
                      f"![Floquet multipliers, {name}](floquet/{name}/floquet.png)", ""]
    lines += [f"The full report with every experiment: `{full_run_records(full_run)}/report.md` in the "
              "repository; `drake-biped reproduce --out DIR` (without `--quick`) runs it.", ""]
    return "\n".join(lines)
