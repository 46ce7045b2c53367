"""Fig. 7 and the stability report (Table VI beside the paper's), drawn from a stability record alone.

Named for the `stability` command (drake_biped/experiments/stability.py) by design: that runs the walks, this
draws their record.
"""

from __future__ import annotations

import html
import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from drake_biped.records import save_figure, write_text_atomic  # noqa: E402

CONDITIONS = ("without", "with")
DISTURBANCES = ("undisturbed", "forward", "backward")
# Fig. 7's colours for 0-4 steps after the push; later steps grey.
STEP_COLOURS = ("red", "green", "purple", "blue", "black")
CONDITION_NAMES = {"without": "without torque-free period", "with": "with torque-free period"}


def markdown_cell(text: str) -> str:
    """A table cell's text with its pipes escaped, so that it cannot split the Markdown table."""
    return str(text).replace("|", "\\|")


def _eig_text(pairs) -> str:
    out = []
    for real, im in pairs:
        out.append(f"{real:.3f}" if abs(im) < 5e-4 else f"{real:.3f}{'+' if im >= 0 else '−'}{abs(im):.3f}i")
    return ", ".join(out)


def fig7(record: dict, path: str | Path) -> None:
    """Return-map scatter of the inter-leg hip angle (deviation from x*): x_n against x_{n+1}, coloured by
    the number of steps after the push."""
    cells = record["cells"]
    fig, axes = plt.subplots(2, 3, figsize=(11, 7), sharex=True, sharey=True)
    for i, condition in enumerate(CONDITIONS):
        x_star = np.array(cells[condition]["equilibrium"])
        for j, kind in enumerate(DISTURBANCES):
            ax = axes[i, j]
            cell = cells[condition][kind]
            for seq, since in zip(cell["sequences"], cell["steps_since_push"]):
                s = np.array(seq).reshape(-1, 2)
                if len(s) < 2:
                    continue
                d = (s[:, 0] - x_star[0]) * 1e3
                for n in range(len(s) - 1):
                    k = since[n]
                    colour = STEP_COLOURS[k] if 0 <= k < len(STEP_COLOURS) else "0.6"
                    ax.plot(d[n], d[n + 1], "o", ms=3.5, color=colour, alpha=0.8)
            ax.axhline(0, color="0.85", lw=0.6)
            ax.axvline(0, color="0.85", lw=0.6)
            rho = cell.get("spectral_radius")
            title = f"{kind}: ρ = {rho:.3f}" if rho is not None else f"{kind}: no fit"
            if cell["falls"]:
                title += f"; {cell['falls']} of {cell['trials']} trials fell"
            ax.set_title(title, fontsize=9)
            if j == 0:
                ax.set_ylabel(f"{CONDITION_NAMES[condition]}\nθ_(n+1) − θ* [mrad]", fontsize=8)
            if i == 1:
                ax.set_xlabel("θ_n − θ* [mrad]", fontsize=8)
    lo, hi = axes[0, 0].get_xlim()
    for ax in axes.flat:
        ax.plot([lo, hi], [lo, hi], ":", color="0.5", lw=0.8)
        ax.set_xlim(lo, hi)
        ax.set_ylim(lo, hi)
    handles = [plt.Line2D([], [], ls="", marker="o", color=c,
                          label=f"{k} step{'' if k == 1 else 's'} after the push")
               for k, c in enumerate(STEP_COLOURS)]
    handles.append(plt.Line2D([], [], ls="", marker="o", color="0.6", label="later / undisturbed"))
    fig.legend(handles=handles, loc="lower center", ncol=6, fontsize=8)
    fig.suptitle("Fig. 7: Poincaré return map of the inter-leg hip angle θ at touchdown", fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 0.97))
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def _verdict(cell: dict) -> str:
    falls = f"{cell['falls']} of {cell['trials']} trials fell"
    if "error" in cell:
        return ("not stable: " + falls + "; no fit") if cell["falls"] else "no fit: " + cell["error"]
    if cell["falls"]:
        return f"not stable: {falls} (ρ {cell['spectral_radius']:.2f} over their touchdowns before the fall)"
    ci = cell.get("spectral_radius_ci")
    if cell["stable"] and ci and ci[1] >= 1.0:
        return f"stable by its fit (ρ < 1), but not established: the 95 % interval of ρ reaches {ci[1]:.2f}"
    return "stable (ρ < 1)" if cell["stable"] else "unstable (ρ ≥ 1)"


def _rows(record: dict) -> list[dict]:
    rows = []
    for condition in CONDITIONS:
        for kind in DISTURBANCES:
            cell = record["cells"][condition][kind]
            ci = cell.get("spectral_radius_ci")
            rho = cell.get("spectral_radius")
            rows.append({
                "cell": f"{CONDITION_NAMES[condition]}, {kind}",
                "paper": _eig_text(cell["paper_eigenvalues"]),
                "paper_rho": f"{cell['paper_spectral_radius']:.3f}",
                "ours": _eig_text(cell["eigenvalues"]) if "eigenvalues" in cell else "—",
                "rho": "—" if rho is None else f"{rho:.3f}",
                "ci": "—" if not ci else f"[{ci[0]:.3f}, {ci[1]:.3f}]",
                "pairs": str(cell.get("n_pairs", 0)),
                "falls": f"{cell['falls']}/{cell['trials']}",
                "verdict": _verdict(cell),
                "paper_verdict": "stable" if cell["paper_spectral_radius"] < 1 else "unstable",
            })
    return rows


COLUMNS = (("cell", "cell"), ("paper", "paper λ"), ("paper_rho", "paper ρ"), ("ours", "ours λ"),
           ("rho", "ours ρ"), ("ci", "95 % CI of ρ"), ("pairs", "pairs"), ("falls", "falls"),
           ("verdict", "verdict"))


JACOBIAN_TITLE = "Step-to-step Jacobian by finite differences in Drake, beside the regression"
JACOBIAN_TEXT = (
    "Kicks of the swing hip 30 ms before touchdown 8 (angle ε, rate 10ε, 16 directions); J by least squares "
    "from the measured Δx_n, Δx_n+1. The residual is the part of Δx_n+1 that J does not explain; where it is "
    "large, the step map's linear response is as small as its scatter (most likely the jumps of a controller "
    "on the controller's update grid) and J is not identifiable at that kick size.")
JACOBIAN_COLUMNS = ("condition", "kick ε (rad)", "λ", "ρ", "residual", "regression ρ (undisturbed)")


def _jacobian_rows(record: dict) -> list[list[str]]:
    rows = []
    for condition, entries in (record.get("jacobian") or {}).items():
        reg = record["cells"][condition]["undisturbed"].get("spectral_radius")
        reg_text = "—" if reg is None else f"{reg:.3f}"
        for j in entries:
            if "error" in j:
                rows.append([CONDITION_NAMES[condition], f"{j['angle_rad']:g}", j["error"], "", "", reg_text])
            else:
                rows.append([CONDITION_NAMES[condition], f"{j['angle_rad']:g}", _eig_text(j["eigenvalues"]),
                             f"{j['spectral_radius']:.3f}", f"{100 * j['relative_residual']:.0f} %", reg_text])
    return rows


def _intro(record: dict) -> str:
    s = record["settings"]
    return (f"Torque-free period {s['window'][0]:g}–{s['window'][1]:g} s; pushes ±{s['push_force_n']:g} N on the "
            f"torso for {s['push_duration_s']:g} s from {s['push_start_s']:g} s; {s['trials']} trials per cell "
            f"(initial hip angle and speed within ±{100 * s['spread']:g} %, seed {s['seed']}); x* = mean "
            f"undisturbed section state from touchdown {s['steady_from_step']} on; section state = (inter-leg "
            "hip angle, rate) at touchdown.")


def report_markdown(record: dict) -> str:
    lines = [
        "# Stability report: Table VI (return-map eigenvalues) beside the paper's",
        "",
        _intro(record),
        "",
        "| " + " | ".join(markdown_cell(h) for _, h in COLUMNS) + " |",
        "|" + "---|" * len(COLUMNS),
    ]
    for row in _rows(record):
        lines.append("| " + " | ".join(markdown_cell(row[k]) for k, _ in COLUMNS) + " |")
    lines += ["", "ρ is the spectral radius, the largest |λ|. A cell is stable when the ρ of its fitted return map "
              "is below 1 and no trial fell (and established when the upper end of its 95 % interval is below 1 "
              "too); every cell of the paper's Table VI is stable. ![Fig. 7](fig7_return_map.png)", ""]
    jac_rows = _jacobian_rows(record)
    if jac_rows:
        lines += [f"## {JACOBIAN_TITLE}", "", JACOBIAN_TEXT, "", "| " + " | ".join(JACOBIAN_COLUMNS) + " |",
                  "|" + "---|" * len(JACOBIAN_COLUMNS)]
        lines += ["| " + " | ".join(markdown_cell(c) for c in row) + " |" for row in jac_rows]
        lines.append("")
    lines += _floquet_sections(record)
    v = record.get("versions", {})
    lines.append(f"drake-biped {v.get('drake_biped', '?')} ({v.get('git_commit', '?')}), Drake {v.get('drake', '?')}.")
    return "\n".join(lines) + "\n"


FLOQUET_TEXT = ("The full-state linearisation of the gait beside the 2-D regression: the fixed point of the step "
                "map on the mid-stance section and its multipliers (`drake-biped floquet`), without and with the "
                "window. The regression is fitted over pushes, deviations of 10⁻²–10⁻¹; the multipliers are the "
                "map's derivative at the orbit, where the sweep of ε converges.")


def _floquet_sections(record: dict) -> list[str]:
    """The Floquet sections (`stability --floquet`), as floquet.md writes them."""
    found = record.get("floquet") or {}
    if not found:
        return []
    lines = ["## Floquet multipliers of the periodic orbit, beside the regression", "", FLOQUET_TEXT, ""]
    for condition in ("without", "with"):
        if condition in found:
            text = re.sub(r"^(#+) ", lambda m: "#" + m.group(1) + " ", found[condition]["markdown"], flags=re.M)
            lines += [text, f"![Floquet multipliers, {condition}](floquet_{condition}/floquet.png)", ""]
    return lines


def report_html(record: dict) -> str:
    rows = _rows(record)
    head = "".join(f"<th>{html.escape(h)}</th>" for _, h in COLUMNS)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(r[k])}</td>" for k, _ in COLUMNS) + "</tr>" for r in rows)
    intro = html.escape(_intro(record))
    return (
        "<!doctype html><html><head><meta charset='utf-8'><title>drake-biped stability report</title>"
        "<style>body{font-family:sans-serif;max-width:70em;margin:2em auto}table{border-collapse:collapse}"
        "td,th{border:1px solid #bbb;padding:4px 8px;font-size:90%}</style></head><body>"
        "<h1>Stability report: Table VI beside the paper's</h1>"
        f"<p>{intro}</p><table><tr>{head}</tr>{body}</table>"
        "<p>A cell is stable when the spectral radius ρ of its fitted return map is below 1 and no trial fell.</p>"
        "<img src='fig7_return_map.png' alt='Fig. 7' style='max-width:100%'>"
        + _jacobian_html(record) + _floquet_html(record) +
        "</body></html>\n"
    )


def _jacobian_html(record: dict) -> str:
    rows = _jacobian_rows(record)
    if not rows:
        return ""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in JACOBIAN_COLUMNS)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>" for row in rows)
    return (f"<h2>{html.escape(JACOBIAN_TITLE)}</h2><p>{html.escape(JACOBIAN_TEXT)}</p>"
            f"<table><tr>{head}</tr>{body}</table>")


def write_stability_outputs(record: dict, out: str | Path) -> list[Path]:
    out = Path(out)
    paths = [out / "fig7_return_map.png", out / "report.md", out / "report.html"]
    fig7(record, paths[0])
    write_text_atomic(paths[1], report_markdown(record))
    write_text_atomic(paths[2], report_html(record))
    return paths


def _floquet_html(record: dict) -> str:
    lines = _floquet_sections(record)
    if not lines:
        return ""
    import markdown

    return markdown.markdown("\n".join(lines), extensions=["tables"])
