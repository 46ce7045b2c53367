"""Figures drawn from saved records (no simulation here): the walk figure, the planar animation, the
torque-free window map."""

from __future__ import annotations

import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from drake_biped.analysis import rewalks  # noqa: E402
from drake_biped.analysis.cost_of_transport import cost_decimals, format_cost  # noqa: E402
from drake_biped.analysis.series import cmt_change, moving_average, period, spread_text  # noqa: E402
from drake_biped.kinematics import B_TORSO_COM_X, B_TORSO_COM_Z, TABLE_I_BODY, leg_points  # noqa: E402
from drake_biped.paper import SLOPE_MOVING_AVERAGE as MOVING_AVERAGE  # noqa: E402
from drake_biped.paper import TABLE_V, TABLE_V_REDUCTION  # noqa: E402
from drake_biped.records import atomic_file, save_figure, write_text_atomic  # noqa: E402

JOINTS = ("left_hip", "left_knee", "left_ankle", "right_hip", "right_knee", "right_ankle")
COLORS = {"left": "#2f6fbf", "right": "#d9661f"}


def _spans(time: np.ndarray, flag: np.ndarray) -> list[tuple[float, float]]:
    """Intervals of `time` where flag > 0.5."""
    on = flag > 0.5
    edges = np.flatnonzero(np.diff(on.astype(int)))
    starts = list(time[edges[~on[edges]] + 1]) if len(edges) else []
    ends = list(time[edges[on[edges]] + 1]) if len(edges) else []
    if on.size and on[0]:
        starts.insert(0, time[0])
    if on.size and on[-1]:
        ends.append(time[-1])
    return list(zip(starts, ends))


def walk_figure(trajectory: dict, path: str | Path, title: str = "") -> None:
    """Joint angles, hip torques with the torque-free windows shaded, cumulative positive work
    (the kind of the paper's Fig. 3)."""
    t = trajectory["time"]
    q = trajectory["positions"]
    tau = trajectory["actuation"]
    work = trajectory["positive_work"]
    fig, axes = plt.subplots(3, 1, figsize=(11.5, 9), sharex=True)
    ax = axes[0]
    for j, name in enumerate(JOINTS):
        side = name.split("_")[0]
        style = {"hip": "-", "knee": "--", "ankle": ":"}[name.split("_")[1]]
        ax.plot(t, np.degrees(q[:, 3 + j]), style, color=COLORS[side], lw=1, label=name)
    ax.set_ylabel("joint angle [deg]")
    # Legends beside the axes, where they cover no trace.
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax = axes[1]
    for side, j in (("left", 0), ("right", 3)):
        ax.plot(t, tau[:, j], color=COLORS[side], lw=1, label=f"{side} hip torque")
    for k, (a, b) in enumerate(_spans(t, trajectory["torque_free"])):
        ax.axvspan(a, b, color="0.8", lw=0, label="torque-free (swing hip)" if k == 0 else None)
    ax.set_ylabel("hip torque [N m]")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax = axes[2]
    for j, name in enumerate(JOINTS):
        side = name.split("_")[0]
        style = {"hip": "-", "knee": "--", "ankle": ":"}[name.split("_")[1]]
        ax.plot(t, work[:, j], style, color=COLORS[side], lw=1, label=name)
    ax.plot(t, work.sum(axis=1), "k-", lw=1.5, label="total")
    ax.set_ylabel("cumulative positive work [J]")
    ax.set_xlabel("time [s]")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def _skeleton(q: np.ndarray, body=TABLE_I_BODY) -> dict[str, np.ndarray]:
    x, z, pitch = q[0], q[1], q[2]
    # the torso drawn from the base to twice its centre of mass (its top, for a uniform torso)
    cx, cz = body[B_TORSO_COM_X], body[B_TORSO_COM_Z]
    top = 2.0 * cx, 2.0 * cz
    torso_top = (x + top[0] * np.cos(pitch) - top[1] * np.sin(pitch), z + top[0] * np.sin(pitch) + top[1] * np.cos(pitch))
    lines = {"torso": np.array([[x, z], torso_top])}
    for side, i in (("left", 3), ("right", 6)):
        p = leg_points(x, z, pitch, q[i], q[i + 1], q[i + 2], body)
        lines[side] = np.array(
            [[p.hip_x, p.hip_z], [p.knee_x, p.knee_z], [p.ankle_x, p.ankle_z], [p.heel_x, p.heel_z],
             [p.toe_x, p.toe_z], [p.ankle_x, p.ankle_z]]
        )
    return lines


def walk_frame(trajectory: dict, time_s: float, path: str | Path, ground_height=None, body=TABLE_I_BODY) -> None:
    """One still of the walk: the stick figure (as in walk_animation) at the recorded sample nearest `time_s`, in
    the world's x from 0.8 m behind the hip to 0.8 m ahead, on its ground."""
    t, q = trajectory["time"], trajectory["positions"]
    qi = q[int(np.argmin(np.abs(np.asarray(t) - time_s)))]
    x0 = qi[0]
    fig, ax = plt.subplots(figsize=(5, 3.2))
    ax.set_aspect("equal")
    ax.set_xlim(x0 - 0.8, x0 + 0.8)
    ax.set_ylim(-0.05, 1.0)
    ax.set_xlabel("x [m]")
    gx = np.linspace(x0 - 0.8, x0 + 0.8, 50)
    ax.plot(gx, np.array([ground_height(v) for v in gx]) if ground_height else np.zeros_like(gx),
            color="#5a8f5a", lw=2)
    for name, pts in _skeleton(qi, body).items():
        ax.plot(pts[:, 0], pts[:, 1], "-o", color="0.35" if name == "torso" else COLORS[name], lw=3, ms=3)
    ax.text(0.02, 0.93, f"t = {t[int(np.argmin(np.abs(np.asarray(t) - time_s)))]:.2f} s", transform=ax.transAxes,
            fontsize=8)
    fig.tight_layout()
    save_figure(fig, Path(path), dpi=100)
    plt.close(fig)


def walk_animation(trajectory: dict, path: str | Path, ground_height=None, fps: int = 15,
                   max_frames: int = 300, body=TABLE_I_BODY) -> None:
    """A planar stick-figure GIF of the walk, the camera following the hip: drawn in the hip's frame
    (axes fixed, so each frame redraws only the robot, the ground and the metre marks), x in the label.
    `body`: the robot's (kinematics.BODY), the shipped one's by default."""
    from PIL import Image

    t = trajectory["time"]
    q = trajectory["positions"]
    n_frames = int(min(max_frames, max(2, t[-1] * fps)))
    frame_times = np.linspace(t[0], t[-1], n_frames)
    idx = np.searchsorted(t, frame_times).clip(0, len(t) - 1)
    fig, ax = plt.subplots(figsize=(5, 3.2))
    ax.set_aspect("equal")
    ax.set_xlim(-0.8, 0.8)
    ax.set_ylim(-0.05, 1.0)
    ax.set_xlabel("x from the hip [m]")
    artists = {k: ax.plot([], [], "-o", color=c, lw=3, ms=3, animated=True)[0]
               for k, c in (("torso", "0.35"), ("left", COLORS["left"]), ("right", COLORS["right"]))}
    (ground_line,) = ax.plot([], [], color="#5a8f5a", lw=2, animated=True)
    (marks,) = ax.plot([], [], color="#2f4f2f", lw=1, animated=True)  # a mark on the ground every metre
    label = ax.text(0.02, 0.93, "", transform=ax.transAxes, fontsize=8, animated=True)
    moving = (*artists.values(), ground_line, marks, label)

    def height(x: np.ndarray) -> np.ndarray:
        return np.array([ground_height(v) for v in x]) if ground_height else np.zeros_like(x)

    def draw(k: int) -> None:
        qi = q[idx[k]]
        x0 = qi[0]
        gx = np.linspace(x0 - 0.8, x0 + 0.8, 50)
        gz = height(gx)
        z0 = gz.min()
        for name, pts in _skeleton(qi, body).items():
            artists[name].set_data(pts[:, 0] - x0, pts[:, 1] - z0)
        ground_line.set_data(gx - x0, gz - z0)
        mx = np.arange(np.ceil(x0 - 0.8), np.floor(x0 + 0.8) + 1.0)
        mz = height(mx) - z0
        marks.set_data(np.repeat(mx - x0, 3), np.column_stack([mz - 0.03, mz + 0.03, np.full_like(mz, np.nan)]).ravel())
        label.set_text(f"t = {t[idx[k]]:.2f} s, x = {x0:.2f} m")

    fig.subplots_adjust(bottom=0.17, top=0.97)
    fig.canvas.draw()
    background = fig.canvas.copy_from_bbox(fig.bbox)
    frames = []
    for k in range(n_frames):
        draw(k)
        fig.canvas.restore_region(background)
        for artist in moving:
            ax.draw_artist(artist)
        frames.append(Image.fromarray(np.asarray(fig.canvas.buffer_rgba())).convert("RGB")
                      .quantize(colors=64, method=Image.Quantize.FASTOCTREE))
    with atomic_file(Path(path)) as tmp:
        frames[0].save(tmp, format="GIF", save_all=True, append_images=frames[1:], duration=round(1000 / fps), loop=0)
    plt.close(fig)


def window_map_figure(rows: list[dict], baseline_cmt: float | None, path: str | Path) -> None:
    """Heat map of C_mt change (%) against the no-window walk over (t1, t2); falls marked with x."""
    t1s = sorted({r["t1"] for r in rows})
    t2s = sorted({r["t2"] for r in rows})
    grid = np.full((len(t2s), len(t1s)), np.nan)
    fig, ax = plt.subplots(figsize=(6.5, 5))
    for r in rows:
        i, j = t2s.index(r["t2"]), t1s.index(r["t1"])
        if r["walked"] and baseline_cmt and r["cost_of_transport"] is not None:
            grid[i, j] = 100.0 * (r["cost_of_transport"] / baseline_cmt - 1.0)
        else:
            ax.plot(r["t1"], r["t2"], "kx", ms=8)
    if np.isfinite(grid).any():
        lim = np.nanmax(np.abs(grid))
        d1 = (t1s[1] - t1s[0]) if len(t1s) > 1 else 0.1
        d2 = (t2s[1] - t2s[0]) if len(t2s) > 1 else 0.1
        im = ax.imshow(grid, origin="lower", cmap="RdBu_r", vmin=-lim, vmax=lim, aspect="auto",
                       extent=(t1s[0] - d1 / 2, t1s[-1] + d1 / 2, t2s[0] - d2 / 2, t2s[-1] + d2 / 2))
        fig.colorbar(im, ax=ax, label="C_mt change vs no window [%]")
        for i in range(len(t2s)):
            for j in range(len(t1s)):
                if np.isfinite(grid[i, j]):
                    ax.text(t1s[j], t2s[i], f"{grid[i, j]:+.0f}", ha="center", va="center", fontsize=7)
    ax.set_xlabel("torque-free start t1 [s]")
    ax.set_ylabel("torque-free end t2 [s]")
    base = format_cost(baseline_cmt or None)
    ax.set_title(f"Torque-free windows: C_mt vs no window (C_mt {base}); x = fell", fontsize=9)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


# Table V of the paper (C_mt) and our measured rows.
TABLE_V_PAPER = TABLE_V


def _learning_arrays(record: dict) -> dict[str, np.ndarray]:
    trials = record["trials"]
    n = min(len(t["episodes"]) for t in trials)

    def grid(key):
        return np.array([[np.nan if e[key] is None else float(e[key]) for e in t["episodes"][:n]] for t in trials])

    cmt = grid("cost_of_transport")
    cmt[np.array([[e["fell"] for e in t["episodes"][:n]] for t in trials])] = np.nan  # falls: no C_mt
    return {"episode": np.arange(1, n + 1), "reward": grid("reward"), "cmt": cmt, "t1": grid("t1"),
            "t2": grid("t2"), "mean_t1": grid("mean_t1"), "mean_t2": grid("mean_t2")}


def learning_figures(record: dict, out: str | Path) -> list[Path]:
    """Fig. 4 (mean reward over trials, std bars), Fig. 5 (C_mt, moving average), Fig. 6 (t1, t2) and
    Table V (Markdown), from a learning.json record. Episodes where every trial fell have no C_mt."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # nanmean of all-NaN columns: those NaNs are meant
        return _learning_figures(record, Path(out))


def _learning_figures(record: dict, out: Path) -> list[Path]:
    a = _learning_arrays(record)
    ep = a["episode"]
    n = len(ep)
    window = min(100, max(1, n // 5))
    paths = []

    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    ax.plot(ep, np.nanmean(a["reward"], axis=0), color="0.6", lw=0.8, label="mean over trials")
    centers, means, stds = [], [], []
    for start in range(0, n, window):
        block = a["reward"][:, start : start + window]
        centers.append(ep[start] + (min(window, n - start) - 1) / 2)
        means.append(np.nanmean(block))
        stds.append(np.nanstd(block))
    ax.errorbar(centers, means, yerr=stds, fmt="o-", color="C0", capsize=3,
                label=f"{window}-episode blocks (± std, all trials)")
    ax.set_xlabel("episode")
    ax.set_ylabel("reward (distance fraction / C_mt)")
    ax.set_title(f"Fig. 4: reward, {len(record['trials'])} trials")
    ax.legend(fontsize=8)
    fig.tight_layout()
    paths.append(out / "fig4_reward.png")
    save_figure(fig, paths[-1], dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    per_episode = np.nanmean(a["cmt"], axis=0)
    ax.plot(ep, per_episode, ".", color="0.7", ms=3, label="mean over trials (walks only)")
    ax.plot(ep, moving_average(per_episode, window), color="C3", label=f"{window}-episode moving average")
    ev = record.get("evaluation") or {}
    if ev.get("no_window", {}).get("cost_of_transport"):
        ax.axhline(ev["no_window"]["cost_of_transport"], color="k", ls="--", lw=0.8, label="no torque-free period")
    ax.set_xlabel("episode")
    ax.set_ylabel("C_mt")
    ax.set_title("Fig. 5: cost of transport")
    ax.legend(fontsize=8)
    fig.tight_layout()
    paths.append(out / "fig5_cmt.png")
    save_figure(fig, paths[-1], dpi=120)
    plt.close(fig)

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11.5, 3.8), sharey=True)
    for key, color, name in (("1", "C0", "t̄1 (start)"), ("2", "C1", "t̄2 (end)")):
        ax.plot(ep, moving_average(np.nanmean(a[f"t{key}"], axis=0), window), color=color, lw=0.8, alpha=0.5,
                label=f"sampled t{key}, {window}-episode moving average")
        ax.plot(ep, np.nanmean(a[f"mean_t{key}"], axis=0), color=color, lw=2, label=f"policy mean {name}")
    ax.set_xlabel("episode")
    ax.set_ylabel("time after step start (s)")
    ax.set_title("Fig. 6: torque-free start and end times (mean over trials)", fontsize=10)
    ax.legend(fontsize=7)
    # Each trial's policy: a mean over trials can hide trials that learned different things.
    for k, trial in enumerate(record["trials"]):
        color = f"C{k % 10}"
        m1, m2 = a["mean_t1"][k], a["mean_t2"][k]
        ax2.plot(ep, m1, color=color, lw=1.2, label=f"trial {trial['trial']}: t̄1")
        ax2.plot(ep, m2, color=color, lw=1.2, ls="--", label=f"trial {trial['trial']}: t̄2")
        ax2.fill_between(ep, m1, m2, where=m2 > m1, color=color, alpha=0.15, lw=0)
    ax2.set_xlabel("episode")
    ax2.set_title("each trial's policy mean (shaded: a torque-free period; none where t̄2 ≤ t̄1)", fontsize=9)
    ax2.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    paths.append(out / "fig6_times.png")
    save_figure(fig, paths[-1], dpi=120)
    plt.close(fig)

    paths.append(out / "table_v.md")
    write_text_atomic(paths[-1], table_v(record))
    return paths


def table_v(record: dict) -> str:
    ev = record.get("evaluation") or {}
    base = (ev.get("no_window") or {}).get("cost_of_transport")
    learned = ev.get("learned_mean_cost_of_transport")

    def fmt(x):
        return format_cost(x, "—")

    ours_learned = fmt(learned)
    if learned is not None:
        spread = spread_text(ev["learned_std_cost_of_transport"], ev["learned_walks"],
                             lambda sd: f"{sd:.{cost_decimals(learned)}f}")
        ours_learned = f"{fmt(learned)} {spread} ({ev['learned_walks']} of {len(ev['learned'])} trials walk)"
    reduction = ev.get("reduction")
    lines = [
        "# Table V: cost of transport C_mt = E+ / (m g d)",
        "",
        "| | ASIMO | CPG without torque-free period | CPG with the learned torque-free period | human |",
        "|---|---|---|---|---|",
        f"| paper | {TABLE_V_PAPER['ASIMO']:.2f} | {TABLE_V_PAPER['CPG without torque-free period']:.2f} | "
        f"{TABLE_V_PAPER['CPG with torque-free period']:.2f} | {TABLE_V_PAPER['human']:.2f} |",
        f"| ours (measured) | — | {fmt(base)} | {ours_learned} | — |",
        "",
        f"C_mt change: paper {cmt_change(TABLE_V_REDUCTION, 0)}, ours {cmt_change(reduction)}"
        + ". Ours: " + _table_v_measure(record, ev) + ":",
        "",
        "| trial | t̄1 (s) | t̄2 (s) | C_mt | walked |",
        "|---|---|---|---|---|",
    ]
    for r in ev.get("learned", []):
        lines.append(f"| {r['trial']} | {r['t1']:.3f} | {r['t2']:.3f} | {fmt(r['cost_of_transport'])} | "
                     f"{'yes' if not r['fell'] else 'no'} |")
    episode = ev.get("episode")
    if episode:
        costs = ", ".join(fmt(c) for c in episode["learned"])
        lines += ["", f"The paper's measure, one {episode['distance_m']:g} m episode from the initiation (its C_mt over "
                  f"the whole walk): no window {fmt(episode['no_window'])}; the trials' means {costs}; C_mt change "
                  f"{cmt_change(episode.get('reduction'))}."]
    if ev.get("rewalks"):
        lines += ["", "## The learned windows re-walked", "", rewalks.markdown(ev["rewalks"]).rstrip()]
    return "\n".join(lines) + "\n"


def _table_v_measure(record: dict, ev: dict) -> str:
    """What Table V's measured row is, from the evaluation's record."""
    if ev.get("measure"):
        return (f"the {ev['measure']}, without a window and with each trial's final policy mean (t̄1, t̄2), at the "
                "learning's plant step")
    return (f"one {record['settings']['config']['sim']['distance_m']:g} m walk without a window, and one with each "
            "trial's final policy mean (t̄1, t̄2)")


def grid_slices_figure(axes, points: list[dict], rows: list[dict], best: dict, path: str | Path,
                       distance_m: float) -> None:
    """Walking distance over every pair of grid axes that vary, the other axes held at the best point's
    values (true slices through the best point, not projections). One axis that varies: a line."""
    varying = [a for a in axes if len(a.values) > 1]
    lookup = {tuple(p[a.name] for a in axes): r["distance_m"] for p, r in zip(points, rows)}

    def distance(assign: dict) -> float:
        return lookup.get(tuple(assign.get(a.name, best[a.name]) for a in axes), np.nan)

    pairs = [(a, b) for i, a in enumerate(varying) for b in varying[i + 1 :]]
    short = {a.name: a.name.split(".")[-1] for a in axes}
    # The colour scale spans the distances walked (up to the target), so that a grid in which every point
    # falls early still shows which fell later.
    walked = [r["distance_m"] for r in rows if np.isfinite(r["distance_m"])]
    top = min(distance_m, max(walked, default=distance_m)) if walked else distance_m
    top = top if top > 0 else distance_m
    if not pairs:
        fig, ax = plt.subplots(figsize=(5.5, 3.6))
        if varying:
            a = varying[0]
            ax.plot(a.values, [distance({a.name: v}) for v in a.values], "o-")
            ax.set_xlabel(short[a.name])
        ax.set_ylabel("walking distance (m)")
        ax.set_ylim(0, distance_m * 1.05)
    else:
        cols = min(4, len(pairs))
        nrows = -(-len(pairs) // cols)
        fig, grid = plt.subplots(nrows, cols, figsize=(3.0 * cols + 1.0, 2.6 * nrows + 0.4), squeeze=False,
                                 layout="constrained")
        image = None
        for ax, (a, b) in zip(grid.flat, pairs):
            z = np.array([[distance({a.name: va, b.name: vb}) for va in a.values] for vb in b.values])
            image = ax.imshow(z, origin="lower", aspect="auto", vmin=0, vmax=top, cmap="viridis")
            ax.set_xticks(range(len(a.values)), [f"{v:.3g}" for v in a.values], fontsize=7)
            ax.set_yticks(range(len(b.values)), [f"{v:.3g}" for v in b.values], fontsize=7)
            ax.set_xlabel(short[a.name], fontsize=8)
            ax.set_ylabel(short[b.name], fontsize=8)
            ax.plot(a.values.index(best[a.name]), b.values.index(best[b.name]), "r*", ms=9)
        for ax in list(grid.flat)[len(pairs):]:
            ax.axis("off")
        label = "walking distance (m)" + ("" if top >= distance_m else f"; the furthest walk, {top:.2f} m, is the top "
                                                                   f"(target {distance_m:g} m)")
        fig.colorbar(image, ax=grid.ravel().tolist(), shrink=0.9, label=label)
    fixed = ", ".join(f"{short[a.name]}={best[a.name]:.3g}" for a in axes)
    fig.suptitle(f"Grid search: distance walked, slices through the best point (red star: {fixed})", fontsize=9)
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def slope_figures(record: dict, out: str | Path) -> list[Path]:
    """The torque-free period (the paper's Fig. 8 at 0.02 rad, Fig. 10 at 2.0 deg) and the walking distance
    (Fig. 9 / Fig. 11) over the episodes of online learning on the slope, 20-episode moving averages, one
    line per trial; with the starting policy's period and the two check episodes for reference."""
    out = Path(out)
    slope = record["ground"]["slope_rad"]
    level = record["ground"]["level_length_m"]
    target = record["settings"]["config"]["sim"]["distance_m"]
    where = f"{level:g} m level, then {slope:g} rad ({np.degrees(slope):.2f}°)"
    paths = [out / "fig8_period.png", out / "fig9_distance.png"]

    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    for k, trial in enumerate(record["episodes"]):
        ep = trial["episodes"]
        x = np.arange(1, len(ep) + 1)
        color = f"C{k % 10}"
        ax.plot(x, moving_average([period(e["t1"], e["t2"]) for e in ep], MOVING_AVERAGE), color=color,
                label=f"trial {trial['trial']}: sampled period, {MOVING_AVERAGE}-episode average")
        ax.plot(x, [period(e["mean_t1"], e["mean_t2"]) for e in ep], color=color, ls=":", lw=1,
                label=f"trial {trial['trial']}: policy mean's period")
    ax.axhline(record["start"]["period_s"], color="k", ls="--", lw=0.8, label="learned on level ground (start)")
    ax.set_xlabel("episode on the slope")
    ax.set_ylabel("torque-free period t2 - t1 (s)")
    ax.set_ylim(bottom=0)
    ax.set_title(f"Torque-free period during learning ({where})", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, paths[0], dpi=120)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    for k, trial in enumerate(record["episodes"]):
        ep = trial["episodes"]
        x = np.arange(1, len(ep) + 1)
        ax.plot(x, [e["distance_m"] for e in ep], ".", color=f"C{k % 10}", ms=3, alpha=0.4)
        ax.plot(x, moving_average([e["distance_m"] for e in ep], MOVING_AVERAGE), color=f"C{k % 10}",
                label=f"trial {trial['trial']}, {MOVING_AVERAGE}-episode average")
    checks = record["checks"]
    ax.axhline(checks["start_window"]["distance_m"], color="C3", ls="--", lw=0.8,
               label="learned period, no learning")
    ax.axhline(checks["no_window"]["distance_m"], color="k", ls="--", lw=0.8, label="no torque-free period")
    ax.axhline(level, color="0.5", ls=":", lw=0.8, label="slope starts")
    ax.set_xlabel("episode on the slope")
    ax.set_ylabel("walking distance (m)")
    ax.set_ylim(0, target * 1.05)
    ax.set_title(f"Walking distance during learning ({where})", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, paths[1], dpi=120)
    plt.close(fig)
    return paths


def landscape_figure(record: dict, path) -> None:
    """The expected reward GARB climbs (`analysis.landscape`) over the policy mean, one panel per variance."""
    cells = record["variances"]
    base = record["no_window_reward"]
    fig, axes = plt.subplots(1, len(cells), figsize=(4.6 * len(cells), 4.2), squeeze=False)
    t1, t2 = np.array(record["t1"]), np.array(record["t2"])
    for ax, cell in zip(axes[0], cells):
        gain = 100.0 * (np.array(cell["expected_reward"]) / base - 1.0)
        lim = max(1.0, float(np.nanmax(np.abs(gain))))
        im = ax.pcolormesh(t1, t2, gain, cmap="RdBu", vmin=-lim, vmax=lim, shading="nearest")
        ax.contour(t1, t2, gain, levels=[0.0], colors="k", linewidths=0.8)
        ax.plot(*cell["best_mean"], "k*", ms=12, label=f"max J: {100 * cell['best_gain']:+.0f} %")
        for s in cell["starts"]:
            ax.plot(*s["mean"], "ko", mfc="none", ms=8, label=f"start {tuple(s['mean'])}: {100 * s['gain']:+.0f} %")
        ax.plot([0, min(t1[-1], t2[-1])], [0, min(t1[-1], t2[-1])], "k:", lw=0.8)
        ax.set_title(f"σ² = {cell['variance']:g} s²", fontsize=10)
        ax.set_xlabel("policy mean t̄1 [s]")
        ax.set_ylabel("policy mean t̄2 [s]")
        ax.legend(fontsize=7, loc="upper left")
        fig.colorbar(im, ax=ax, label="expected reward vs no window [%]")
    fig.suptitle("What GARB climbs: expected reward of N(T̄, σ²I) over measured windows (below the dotted "
                 "line: no window)", fontsize=9)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def learner_comparison_figure(curves: dict, record: dict, path: Path) -> Path:
    """Learning curves side by side: each learner's running C_mt (mean over its trials), with the best
    window's and the no-window C_mt."""
    from drake_biped.analysis.learner_comparison import running_cost

    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    length = record["running_length"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for k, (name, trials) in enumerate(curves.items()):
            n = min(len(t) for t in trials)
            runs = np.array([running_cost(t[:n], length) for t in trials])
            ax.plot(np.arange(1, n + 1), np.nanmean(runs, axis=0), color=f"C{k}", label=name)
    best = record["best_window"]
    if best is not None:
        ax.axhline(best["cost_of_transport"], color="k", ls="--", lw=0.8,
                   label=f"best window ({best['t1']:g}, {best['t2']:g}) s")
    if record["no_window_cost_of_transport"]:
        ax.axhline(record["no_window_cost_of_transport"], color="0.5", ls=":", lw=0.8, label="no window")
    ax.set_xlabel("episode")
    ax.set_ylabel(f"C_mt, running mean of {length} walks (mean over trials)")
    ax.set_title("Learners side by side")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, Path(path), dpi=110)
    plt.close(fig)
    return Path(path)


def floquet_figure(record: dict, path) -> None:
    """The multipliers in the unit circle (trivial ones hollow) and the sweep's spectral radius against ε."""
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(9.5, 4.2))
    angle = np.linspace(0, 2 * np.pi, 200)
    ax.plot(np.cos(angle), np.sin(angle), "k-", lw=0.8)
    mult = np.array(record["multipliers"])
    trivial = np.array([t is not None for t in record["trivial"]])
    ax.plot(mult[~trivial, 0], mult[~trivial, 1], "o", color="C0", label="multipliers")
    if trivial.any():
        ax.plot(mult[trivial, 0], mult[trivial, 1], "o", mfc="none", color="C3", label="trivial (section)")
    lim = max(1.1, 1.1 * float(np.max(np.abs(mult[:, 0] + 1j * mult[:, 1]))))
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.axhline(0, color="0.8", lw=0.6)
    ax.axvline(0, color="0.8", lw=0.6)
    ax.set_xlabel("Re λ")
    ax.set_ylabel("Im λ")
    ax.set_title(f"Floquet multipliers, spectral radius {record['spectral_radius']:.3f}", fontsize=10)
    ax.legend(fontsize=8, loc="lower left")
    rows = [r for r in record["epsilon_sweep"] if r["spectral_radius"] is not None]
    bx.semilogx([r["epsilon"] for r in rows], [r["spectral_radius"] for r in rows], "o-")
    if record.get("converged_epsilon"):
        lo, hi = record["plateau"]["plateau"]
        bx.axvspan(lo, hi, color="C2", alpha=0.15, label="converged (≤ 5 % change)")
        bx.axvline(record["converged_epsilon"], color="C2", lw=1, label=f"chosen ε {record['converged_epsilon']:.0e}")
        bx.legend(fontsize=8)
    bx.axhline(1.0, color="k", lw=0.6, ls=":")
    bx.set_xlabel("perturbation ε (each coordinate, its SI unit)")
    bx.set_ylabel("spectral radius of the difference Jacobian")
    bx.set_title("Where the central differences converge", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)
