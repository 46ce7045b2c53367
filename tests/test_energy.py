"""Energy by role past the initiation (analysis.energy), on recorded walks whose answer is known."""

import numpy as np
import pytest

from drake_biped.analysis.energy import kept_from, power_by_phase, shares, work_by_role
from drake_biped.model import ROLES


def _walk(seconds: float = 6.0, step_s: float = 1.0, dt: float = 0.01) -> dict:
    """A made-up recorded walk: steps of `step_s`, the right leg standing in even steps; the swing hip turns at
    1 rad/s under 2 N*m (2 W), the stance hip holds 3 N*m still, the stance knee gives back 1 W (0.5 N*m at -2 rad/s
    ... as work, -1 J a second); the role sums are logged as the controller keeps them."""
    t = np.arange(0.0, seconds + 1e-9, dt)
    step = np.floor(t / step_s)
    right = (step % 2 == 0).astype(float)
    q = np.zeros((len(t), 9))
    act = np.zeros((len(t), 6))
    swing = np.where(right > 0.5, 0, 3)  # the swing leg's hip column: left while the right stands
    stance = 3 - swing
    for k in range(len(t)):
        act[k, swing[k]] = 2.0
        act[k, stance[k]] = 3.0
        act[k, stance[k] + 1] = 0.5
    for k in range(1, len(t)):
        q[k] = q[k - 1]
        q[k, 3 + swing[k - 1]] += dt * 1.0
        q[k, 3 + stance[k - 1] + 1] -= dt * 2.0
    work = act[:-1] * np.diff(q[:, 3:], axis=0)
    pos, neg = np.zeros((len(t), 6)), np.zeros((len(t), 6))
    for k in range(1, len(t)):
        held_right = right[k - 1] > 0.5
        pos[k], neg[k] = pos[k - 1], neg[k - 1]
        for i in range(6):
            role = 2 * (i % 3) + (1 if (i >= 3) == held_right else 0)
            (pos if work[k - 1, i] > 0 else neg)[k, role] += work[k - 1, i]
    return {"time": t, "positions": q, "actuation": act, "stance_right": right, "step_start": step * step_s,
            "positive_work_by_role": pos, "negative_work_by_role": neg}


def test_the_initiation_is_left_out_from_the_first_touchdown_after_it():
    w = _walk()
    k = kept_from(w, 3.0)
    assert w["time"][k] == pytest.approx(3.0) and w["step_start"][k] == pytest.approx(3.0)
    assert w["time"][kept_from(w, 2.5)] == pytest.approx(3.0)
    with pytest.raises(ValueError, match="no touchdown at or after 7"):
        kept_from(w, 7.0)


def test_work_by_role_counts_the_walk_kept_and_its_shares_sum_to_one():
    by_role = work_by_role(_walk(), 3.0)  # 3 s kept: 2 W of swing hip, -1 W of stance knee
    assert by_role["swing_hip"]["positive_j"] == pytest.approx(6.0)
    assert by_role["stance_knee"]["negative_j"] == pytest.approx(-3.0)
    assert by_role["stance_hip"] == {"positive_j": 0.0, "negative_j": 0.0}  # held still: no work
    assert shares(by_role)["swing_hip"] == pytest.approx(1.0)
    assert set(by_role) == set(ROLES)


def test_power_by_phase_averages_each_roles_power_over_the_time_since_touchdown():
    p = power_by_phase(_walk(), 3.0, bin_s=0.1)
    assert len(p["time_s"]) == 10 and np.all(p["steps"] == 3)
    np.testing.assert_allclose(p["swing_hip"], 2.0)
    np.testing.assert_allclose(p["stance_knee"], -1.0)
    np.testing.assert_allclose(p["stance_hip"], 0.0)


def test_the_energy_figure_draws_the_work_it_is_given(tmp_path, monkeypatch):
    import matplotlib.figure

    from drake_biped.analysis import energy

    drawn = []
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda self, path, **kw: drawn.append(self))
    walk = _walk()
    by_role = work_by_role(walk, 3.0)
    energy.energy_figure(by_role, power_by_phase(walk, 3.0), tmp_path / "energy.png", "made up")
    heights = [p.get_height() for p in drawn[0].axes[0].patches]
    assert heights[:6] == pytest.approx([by_role[r]["positive_j"] for r in ROLES])
    assert heights[6:] == pytest.approx([by_role[r]["negative_j"] for r in ROLES])


def test_a_walk_writes_its_energy_audit_and_the_report_shows_the_swing_hips_share(tmp_path):
    """`drake-biped walk` (walk.write_walk) writes energy.json and energy.png from its recorded walk, the
    initiation left out: the shares are those of the trajectory's own role sums, and the report's walk section
    gives the swing hip's share; a walk that ends inside the initiation writes no audit."""
    import json

    from walkers import FAST

    from drake_biped.analysis.energy_report import energy_section
    from drake_biped.experiments.walk import energy_line, write_energy, write_walk

    result = write_walk(FAST.override({"sim.distance_m": 6.0}), tmp_path / "w", animation=False)
    record = json.loads((tmp_path / "w" / "energy.json").read_text())
    assert record["from_s"] == 3.0 and (tmp_path / "w" / "energy.png").stat().st_size > 10_000
    again = work_by_role(result.trajectory)
    for role in ROLES:
        assert record["work_by_role"][role] == pytest.approx(again[role], rel=1e-12)
    assert record["shares"] == pytest.approx(shares(again), rel=1e-12)
    assert sum(record["shares"].values()) == pytest.approx(1.0)
    # the audit past the initiation is less than the whole walk's, role by role
    assert all(record["work_by_role"][r]["positive_j"] <= result.work_by_role[r]["positive_j"] + 1e-9 for r in ROLES)
    hip = record["shares"]["swing_hip"]
    assert f"swing hip {100 * hip:.0f} %" in energy_line(record)
    assert f"does **{100 * hip:.0f} %** of the positive work" in "\n".join(energy_section(record))
    assert energy_section(None) == [] and energy_line(None) is None
    short = write_walk(FAST.override({"sim.distance_m": 1.0}), tmp_path / "s", animation=False)
    assert short.duration_s < 3.0 and write_energy(short.trajectory, tmp_path / "s") is None
    assert not (tmp_path / "s" / "energy.json").exists()


def test_the_reports_energy_table_gives_each_walks_shares_beside_the_story_walkers():
    """The reproduction's energy step: each walk's row holds its C_mt, its positive work after the initiation and
    each role's share of it, in model.ROLES order, below the story walker's own row; a walk too short for an
    audit keeps its row, without shares, and no figure."""
    from drake_biped.analysis.energy_report import energy_walks_section

    def audit(swing_hip):
        work = {role: {"positive_j": 10.0, "negative_j": -1.0} for role in ROLES}
        work["swing_hip"]["positive_j"] = swing_hip
        total = sum(v["positive_j"] for v in work.values())
        return {"from_s": 3.0, "work_by_role": work, "shares": {r: v["positive_j"] / total for r, v in work.items()}}

    walk = {"cost_of_transport": 0.2194, "energy": audit(10.0)}
    walks = {"gait": "paper", "distance_m": 10.0, "walks": {
        "window": {"label": "paper, window 0.1-0.2 s (learned)", "cost_of_transport": 0.2055, "fell": False,
                   "distance_m": 10.0, "energy": audit(50.0)},
        "fast_servo": {"label": "fast_servo, no window", "cost_of_transport": 0.55, "fell": True,
                       "distance_m": 1.2, "energy": None}}}
    text = "\n".join(energy_walks_section(walk, walks))
    rows = [line for line in text.splitlines() if line.startswith("| paper") or line.startswith("| fast_servo")]
    assert rows[0] == "| paper, no window (the walk above) | 0.2194 | 60 J | " + " | ".join(["17 %"] * 6) + " |"
    shares = [f"{100 * (50 if role == 'swing_hip' else 10) / 100:.0f} %" for role in ROLES]
    assert rows[1] == "| paper, window 0.1-0.2 s (learned) | 0.2055 | 100 J | " + " | ".join(shares) + " |"
    assert rows[2].startswith("| fast_servo, no window (fell at 1.2 m) | 0.5500 | — |")
    assert "(energy/window/energy.png)" in text and "energy/fast_servo/" not in text
    assert energy_walks_section(walk, None) == []
