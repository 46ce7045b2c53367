"""Figures drawn from saved records (no simulation here): the walk figure, the planar animation, the
torque-free window map."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402

from drake_biped.kinematics import leg_points  # noqa: E402
from drake_biped.params import TABLE_I_LENGTHS_M  # noqa: E402

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
    fig, axes = plt.subplots(3, 1, figsize=(10, 9), sharex=True)
    ax = axes[0]
    for j, name in enumerate(JOINTS):
        side = name.split("_")[0]
        style = {"hip": "-", "knee": "--", "ankle": ":"}[name.split("_")[1]]
        ax.plot(t, np.degrees(q[:, 3 + j]), style, color=COLORS[side], lw=1, label=name)
    ax.set_ylabel("joint angle [deg]")
    ax.legend(ncol=6, fontsize=7, loc="upper right")
    ax = axes[1]
    for side, j in (("left", 0), ("right", 3)):
        ax.plot(t, tau[:, j], color=COLORS[side], lw=1, label=f"{side} hip torque")
    for k, (a, b) in enumerate(_spans(t, trajectory["torque_free"])):
        ax.axvspan(a, b, color="0.8", lw=0, label="torque-free (swing hip)" if k == 0 else None)
    ax.set_ylabel("hip torque [N m]")
    ax.legend(fontsize=7, loc="upper right")
    ax = axes[2]
    for j, name in enumerate(JOINTS):
        side = name.split("_")[0]
        style = {"hip": "-", "knee": "--", "ankle": ":"}[name.split("_")[1]]
        ax.plot(t, work[:, j], style, color=COLORS[side], lw=1, label=name)
    ax.plot(t, work.sum(axis=1), "k-", lw=1.5, label="total")
    ax.set_ylabel("cumulative positive work [J]")
    ax.set_xlabel("time [s]")
    ax.legend(ncol=4, fontsize=7, loc="upper left")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _skeleton(q: np.ndarray) -> dict[str, np.ndarray]:
    x, z, pitch = q[0], q[1], q[2]
    torso_top = (x - TABLE_I_LENGTHS_M["torso"] * np.sin(pitch), z + TABLE_I_LENGTHS_M["torso"] * np.cos(pitch))
    lines = {"torso": np.array([[x, z], torso_top])}
    for side, i in (("left", 3), ("right", 6)):
        p = leg_points(x, z, pitch, q[i], q[i + 1], q[i + 2])
        lines[side] = np.array(
            [[x, z], [p.knee_x, p.knee_z], [p.ankle_x, p.ankle_z], [p.heel_x, p.heel_z], [p.toe_x, p.toe_z],
             [p.ankle_x, p.ankle_z]]
        )
    return lines


def walk_animation(trajectory: dict, path: str | Path, ground_height=None, fps: int = 15,
                   max_frames: int = 300) -> None:
    """A planar stick-figure GIF of the walk, the camera following the hip."""
    t = trajectory["time"]
    q = trajectory["positions"]
    n_frames = int(min(max_frames, max(2, t[-1] * fps)))
    frame_times = np.linspace(t[0], t[-1], n_frames)
    idx = np.searchsorted(t, frame_times).clip(0, len(t) - 1)
    fig, ax = plt.subplots(figsize=(5, 3.2))
    ax.set_aspect("equal")
    artists = {k: ax.plot([], [], "-o", color=c, lw=3, ms=3)[0]
               for k, c in (("torso", "0.35"), ("left", COLORS["left"]), ("right", COLORS["right"]))}
    (ground_line,) = ax.plot([], [], color="#5a8f5a", lw=2)
    label = ax.text(0.02, 0.93, "", transform=ax.transAxes, fontsize=8)
    ax.set_xlabel("x [m]")

    def draw(k):
        qi = q[idx[k]]
        for name, pts in _skeleton(qi).items():
            artists[name].set_data(pts[:, 0], pts[:, 1])
        x0 = qi[0]
        ax.set_xlim(x0 - 0.8, x0 + 0.8)
        gx = np.linspace(x0 - 0.8, x0 + 0.8, 50)
        gz = np.array([ground_height(v) for v in gx]) if ground_height else np.zeros_like(gx)
        ground_line.set_data(gx, gz)
        ax.set_ylim(gz.min() - 0.05, gz.min() + 1.0)
        label.set_text(f"t = {t[idx[k]]:.2f} s")
        return (*artists.values(), ground_line, label)

    fig.subplots_adjust(bottom=0.17, top=0.97)
    anim = FuncAnimation(fig, draw, frames=n_frames, blit=False)
    anim.save(path, writer=PillowWriter(fps=fps))
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
    base = f"{baseline_cmt:.3f}" if baseline_cmt else "n/a"
    ax.set_title(f"Torque-free windows: C_mt vs no window (C_mt {base}); x = fell", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
