"""Where a walk spends its energy: the motors' work by the joints' roles (swing hip, stance hip, ...) over a walk
past its initiation, and their power over the step's time since touchdown, from a recorded walk
(`run_episode(config, record_trajectory=True).trajectory`).

The initiation is left out by time: everything before the first touchdown at or after `from_s` (default
INITIATION_S, the paper's initiation and the first steps it takes to settle) is dropped, so that the walk kept
starts at a touchdown and is whole steps. The roles are the controller's: a joint's role over a
control period is the one its leg held when the period began (`model.ROLES`).
"""

from __future__ import annotations

import numpy as np

from drake_biped.model import ROLES

INITIATION_S = 3.0


def kept_from(trajectory, from_s: float = INITIATION_S) -> int:
    """The sample index the walk is kept from: the first update whose step began at or after `from_s` (a
    touchdown). ValueError when the walk has no touchdown after `from_s`."""
    t, start = np.asarray(trajectory["time"]), np.asarray(trajectory["step_start"])
    later = np.nonzero((start >= from_s) & (t >= start))[0]
    if len(later) == 0:
        raise ValueError(f"the walk has no touchdown at or after {from_s:g} s (it lasts {t[-1]:.2f} s): nothing is "
                         "left past its initiation")
    return int(later[0])


def work_by_role(trajectory, from_s: float = INITIATION_S) -> dict[str, dict[str, float]]:
    """{role: {"positive_j", "negative_j"}} of the walk from `kept_from`: the controller's role sums at the last
    update less those where the walk is kept from (trajectory "positive_work_by_role", "negative_work_by_role")."""
    k = kept_from(trajectory, from_s)
    pos, neg = np.asarray(trajectory["positive_work_by_role"]), np.asarray(trajectory["negative_work_by_role"])
    return {role: {"positive_j": float(pos[-1, i] - pos[k, i]), "negative_j": float(neg[-1, i] - neg[k, i])}
            for i, role in enumerate(ROLES)}


def shares(by_role: dict[str, dict[str, float]]) -> dict[str, float]:
    """Each role's part of the positive work (`work_by_role`'s), summing to 1."""
    total = sum(v["positive_j"] for v in by_role.values())
    if not total > 0.0:
        raise ValueError("no positive work: no shares")
    return {role: v["positive_j"] / total for role, v in by_role.items()}


def power_by_phase(trajectory, from_s: float = INITIATION_S, bin_s: float = 0.02) -> dict[str, np.ndarray]:
    """The roles' mean power over the time since touchdown, from `kept_from`: each control period's power
    (the torque held times the joint's displacement over it, over its length) given to its role and to the bin of
    `bin_s` its start falls in since the last touchdown, averaged over the steps that reach that bin. Returns
    "time_s" (the bins' starts), "steps" (how many steps reach each bin) and one array per role (W)."""
    k = kept_from(trajectory, from_s)
    t = np.asarray(trajectory["time"])[k:]
    q = np.asarray(trajectory["positions"])[k:, 3:]
    act = np.asarray(trajectory["actuation"])[k:]
    right = np.asarray(trajectory["stance_right"])[k:-1] > 0.5  # the roles each period began with
    since = t[:-1] - np.asarray(trajectory["step_start"])[k:-1]
    dt = np.diff(t)
    power = act[:-1] * np.diff(q, axis=0) / dt[:, None]
    bins = np.floor(since / bin_s).astype(int)
    n_bins = int(bins.max()) + 1
    starts = np.asarray(trajectory["step_start"])[k:-1]
    steps = np.array([len(np.unique(starts[bins == b])) for b in range(n_bins)])
    out = {"time_s": np.arange(n_bins) * bin_s, "steps": steps}
    for i, role in enumerate(ROLES):
        kind, stance = i // 2, i % 2 == 1
        leg_right = right if stance else ~right  # the leg holding the role: the right one where it stands
        p = np.where(leg_right, power[:, 3 + kind], power[:, kind])
        total = np.bincount(bins, weights=p * dt, minlength=n_bins)
        length = np.bincount(bins, weights=dt, minlength=n_bins)
        with np.errstate(invalid="ignore", divide="ignore"):
            out[role] = np.where(length > 0, total / length, np.nan)
    return out


def energy_figure(by_role: dict[str, dict[str, float]], phase: dict[str, np.ndarray], path, title: str = "") -> None:
    """Two panels: each role's positive and negative work (J, `work_by_role`), and each role's mean power over the
    time since touchdown (W, `power_by_phase`); the title says what was left out."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (bars, lines) = plt.subplots(1, 2, figsize=(11, 4))
    x = np.arange(len(ROLES))
    bars.bar(x - 0.2, [by_role[r]["positive_j"] for r in ROLES], 0.4, label="positive", color="tab:red")
    bars.bar(x + 0.2, [by_role[r]["negative_j"] for r in ROLES], 0.4, label="negative", color="tab:blue")
    bars.set_xticks(x, [r.replace("_", "\n") for r in ROLES])
    bars.axhline(0.0, color="k", lw=0.5)
    bars.set_ylabel("work (J)")
    bars.legend()
    for role in ROLES:
        lines.plot(phase["time_s"], phase[role], label=role.replace("_", " "),
                   ls="-" if role.startswith("swing") else "--")
    lines.axhline(0.0, color="k", lw=0.5)
    lines.set_xlabel("time since touchdown (s)")
    lines.set_ylabel("mean power (W)")
    lines.legend(fontsize=7, ncol=2)
    fig.suptitle(title or "the motors' work by role, the initiation left out")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
