"""The reproduction report's energy audit: where the story walker's energy goes without the window
(`walk/energy.json`), and beside it the same audit of its walk with the story's window and of the other shipped
gait without and with its own window (the `energy` step's walks, `energy/NAME/energy.json`). Each audit leaves
the initiation out (`analysis.energy`)."""

from __future__ import annotations

from typing import Any

from drake_biped.analysis.cost_of_transport import format_cost
from drake_biped.model import ROLES


def energy_section(energy: dict[str, Any] | None) -> list[str]:
    """Where the walk's energy goes (`walk/energy.json`, written by `drake-biped walk`), its initiation left out;
    nothing for a walk recorded before the audit was kept, or one too short to leave its initiation."""
    if not energy:
        return []
    by_role, shares = energy["work_by_role"], energy["shares"]
    rows = [f"| {role.replace('_', ' ')} | {v['positive_j']:.1f} | {v['negative_j']:.1f} | {100 * shares[role]:.0f} % |"
            for role, v in by_role.items()]
    return [
        f"Where its energy goes: the motors' work by the joints' roles from the first touchdown after "
        f"{energy['from_s']:g} s (the initiation left out), each control period counted for the roles held when "
        f"it began. The torque-free window frees only the swing hip, which does "
        f"**{100 * shares['swing_hip']:.0f} %** of the positive work here.",
        "",
        "| role | positive work (J) | negative work (J) | share of the positive work |",
        "|---|---|---|---|",
        *rows,
        "",
        "![energy by role](walk/energy.png)",
        "",
    ]


def _audit_cells(energy: dict[str, Any] | None) -> str:
    """A walk's positive work after the initiation and each role's share of it, as table cells."""
    if not energy:
        return " | ".join(["—"] * (len(ROLES) + 1))
    total = sum(v["positive_j"] for v in energy["work_by_role"].values())
    return f"{total:.0f} J | " + " | ".join(f"{100 * energy['shares'][role]:.0f} %" for role in ROLES)


def energy_walks_section(walk: dict[str, Any], walks: dict[str, Any] | None) -> list[str]:
    """The story walker without a window (`walk`, the walk step's summary and its audit) beside the energy step's walks (its
    window; the other gait without and with its window): C_mt over the walk and each role's share of the
    positive work after the initiation. Nothing where the step did not run."""
    if not walks or not walks.get("walks"):
        return []
    head = " | ".join(role.replace("_", " ") for role in ROLES)
    lines = [
        f"The same audit with the torque-free window, and on the other shipped gait (`energy/`, each walk "
        f"{walks['distance_m']:g} m from the paper's initiation, recorded; shares of the positive work after the "
        "initiation)" + (f". The story's window: {walks['window_source']}." if walks.get("window_source") else ":"),
        "",
        f"| walk | C_mt over the walk | positive work | {head} |",
        "|---|---|---|" + "---|" * len(ROLES),
    ]
    if walk.get("energy"):
        lines.append(f"| {walks['gait']}, no window (the walk above) | {format_cost(walk['cost_of_transport'], '—')} | "
                     f"{_audit_cells(walk['energy'])} |")
    for w in walks["walks"].values():
        fell = f" (fell at {w['distance_m']:.1f} m)" if w["fell"] else ""
        lines.append(f"| {w['label']}{fell} | {format_cost(w['cost_of_transport'], '—')} | {_audit_cells(w['energy'])} |")
    for name, w in walks["walks"].items():
        if w["energy"]:
            lines += ["", f"![energy: {w['label']}](energy/{name}/energy.png)"]
    return lines + [""]
