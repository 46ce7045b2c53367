"""Run one episode (walk until a distance, a fall, or a time limit) and return an EpisodeResult record."""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import EventStatus

from analysis.cost_of_transport import cost_of_transport, cost_of_transport_per_kg
from drake_biped import controller as ctl
from drake_biped.diagram import BipedDiagram, build_diagram, initial_state
from drake_biped.kinematics import center_of_mass
from drake_biped.model import JOINT_NAMES
from drake_biped.params import GRAVITY_MPS2, TOTAL_MASS_KG, EpisodeConfig
from drake_biped.versions import versions


@dataclass
class StepRecord:
    """One touchdown: its time and the Poincare section state (inter-leg hip angle and its rate)."""

    index: int
    touchdown_time_s: float
    hip_angle_rad: float
    hip_rate_radps: float
    stance_leg: str
    com_x_m: float


@dataclass
class EpisodeResult:
    """What one episode did, with the inputs that made it.

    Section state: hip_angle_rad = (leading thigh angle) - (trailing thigh angle) at touchdown, i.e. the
    new stance hip minus the new swing hip, and hip_rate_radps its rate. Distances are of the centre of mass.
    """

    config: dict[str, Any]
    distance_m: float
    duration_s: float
    fell: bool
    fall_reason: str
    termination: str
    steps: list[StepRecord]
    positive_work_j: dict[str, float]
    signed_work_j: dict[str, float]
    cost_of_transport: float | None
    cost_of_transport_per_kg: float | None
    mean_speed_mps: float
    step_period_s: float | None
    step_length_m: float | None
    mass_kg: float
    wall_time_s: float
    real_time_factor: float
    seed: int
    versions: dict[str, str | None]
    trajectory: dict[str, np.ndarray] | None = field(default=None, repr=False)

    @property
    def total_positive_work_j(self) -> float:
        return self.positive_work_j["total"]

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d.pop("trajectory")
        return d

    def to_json(self, path: str | Path) -> None:
        Path(path).write_text(json.dumps(self.to_dict(), indent=2, allow_nan=False) + "\n")

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> EpisodeResult:
        d = dict(d)
        d["steps"] = [StepRecord(**s) for s in d["steps"]]
        return cls(**d)

    def save_trajectory(self, path: str | Path) -> None:
        if self.trajectory is None:
            raise ValueError("this result holds no trajectory; run the episode with record_trajectory=True")
        np.savez_compressed(path, **self.trajectory)


def _finite_or_none(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def simulate(
    config: EpisodeConfig,
    meshcat=None,
    progress: Callable[[float, float], None] | None = None,
    log_period_s: float | None = None,
) -> tuple[BipedDiagram, Simulator, str, float]:
    """Build and run the diagram; return it, the simulator, the termination reason and the wall time."""
    parts = build_diagram(config, meshcat=meshcat, log_period_s=log_period_s)
    simulator = Simulator(parts.diagram)
    root = simulator.get_mutable_context()
    plant_ctx = parts.plant.GetMyMutableContextFromRoot(root)
    q0, v0, _, _ = initial_state(config)
    parts.plant.SetPositions(plant_ctx, q0)
    parts.plant.SetVelocities(plant_ctx, v0)
    com_x0 = center_of_mass(q0)[0]
    ctrl_ctx = parts.controller.GetMyMutableContextFromRoot(root)
    parts.controller.set_initial_state(ctrl_ctx, q0[3:], com_x0)
    group = parts.controller.state_group
    target = com_x0 + config.sim.distance_m
    diagram = parts.diagram
    reason = ["time limit"]
    next_report = [0.0]

    def monitor(context):
        s = ctrl_ctx.get_discrete_state(group)
        if s.GetAtIndex(ctl.FALL) != 0.0:
            reason[0] = "fall"
            return EventStatus.ReachedTermination(diagram, "fell")
        com_x = s.GetAtIndex(ctl.COM_X)
        if com_x >= target:
            reason[0] = "distance"
            return EventStatus.ReachedTermination(diagram, "distance reached")
        if progress is not None and context.get_time() >= next_report[0]:
            next_report[0] += 0.25
            progress(context.get_time(), com_x - com_x0)
        return EventStatus.Succeeded()

    simulator.set_monitor(monitor)
    simulator.Initialize()
    wall0 = time.perf_counter()
    try:
        simulator.AdvanceTo(config.sim.max_time_s)
    except RuntimeError as exc:  # a diverging contact solve: the episode is a fall, not a crash
        reason[0] = f"simulation failed: {exc}".splitlines()[0]
    wall = time.perf_counter() - wall0
    return parts, simulator, reason[0], wall


def run_episode(
    config: EpisodeConfig | None = None,
    meshcat=None,
    record_trajectory: bool = False,
    progress: Callable[[float, float], None] | None = None,
) -> EpisodeResult:
    """Walk one episode and summarise it (see EpisodeResult)."""
    config = config or EpisodeConfig()
    parts, simulator, reason, wall = simulate(config, meshcat=meshcat, progress=progress)
    context = simulator.get_context()
    t_end = context.get_time()
    ctrl_state = parts.controller.GetMyContextFromRoot(context).get_discrete_state(parts.controller.state_group)
    s = ctrl_state.value().copy()
    fall_code = int(s[ctl.FALL])
    fell = reason != "distance" and reason != "time limit"
    fall_reason = ctl.FALL_REASONS.get(fall_code, "") if reason == "fall" else ("" if not fell else reason)

    plant_ctx = parts.plant.GetMyContextFromRoot(context)
    q0, _, _, _ = initial_state(config)
    q_end = parts.plant.GetPositions(plant_ctx)
    distance = center_of_mass(q_end)[0] - center_of_mass(q0)[0]

    positive = {n: float(s[ctl.POSITIVE_WORK + i]) for i, n in enumerate(JOINT_NAMES)}
    positive["total"] = float(sum(s[ctl.POSITIVE_WORK : ctl.POSITIVE_WORK + 6]))
    signed = {n: float(s[ctl.SIGNED_WORK + i]) for i, n in enumerate(JOINT_NAMES)}
    signed["total"] = float(sum(s[ctl.SIGNED_WORK : ctl.SIGNED_WORK + 6]))

    steps = extract_steps(parts, context)
    if len(steps) >= 3:
        times = np.array([st.touchdown_time_s for st in steps])
        xs = np.array([st.com_x_m for st in steps])
        step_period = float(np.mean(np.diff(times[1:])))
        step_length = float(np.mean(np.diff(xs[1:])))
    else:
        step_period = step_length = None

    cmt = cost_of_transport(positive["total"], TOTAL_MASS_KG, distance, GRAVITY_MPS2)
    cmt_kg = cost_of_transport_per_kg(positive["total"], TOTAL_MASS_KG, distance)
    trajectory = _trajectory(parts, context) if record_trajectory else None
    return EpisodeResult(
        config=config.to_dict(),
        distance_m=float(distance),
        duration_s=float(t_end),
        fell=fell,
        fall_reason=fall_reason,
        termination=reason,
        steps=steps,
        positive_work_j=positive,
        signed_work_j=signed,
        cost_of_transport=_finite_or_none(cmt),
        cost_of_transport_per_kg=_finite_or_none(cmt_kg),
        mean_speed_mps=float(distance / t_end) if t_end > 0 else 0.0,
        step_period_s=step_period,
        step_length_m=step_length,
        mass_kg=TOTAL_MASS_KG,
        wall_time_s=wall,
        real_time_factor=float(t_end / wall) if wall > 0 else math.inf,
        seed=config.seed,
        versions=versions(),
        trajectory=trajectory,
    )


def extract_steps(parts: BipedDiagram, context) -> list[StepRecord]:
    """Touchdowns from the controller log: the first sample after each increment of the step counter."""
    log = parts.controller_log.FindLog(context)
    data = log.data()
    if data.shape[1] == 0:
        return []
    counts = data[ctl.STEP_COUNT]
    idx = np.flatnonzero(np.diff(counts) > 0) + 1
    states = parts.state_log.FindLog(context).data()
    steps = []
    for k, i in enumerate(idx):
        x = states[:, i]
        stance_right = data[ctl.STANCE_RIGHT, i] > 0.5
        st, sw = (6, 3) if stance_right else (3, 6)
        steps.append(
            StepRecord(
                index=k + 1,
                touchdown_time_s=float(data[ctl.STEP_START, i]),
                hip_angle_rad=float(x[st] - x[sw]),
                hip_rate_radps=float(x[9 + st] - x[9 + sw]),
                stance_leg="right" if stance_right else "left",
                com_x_m=float(center_of_mass(x[:9])[0]),
            )
        )
    return steps


def _trajectory(parts: BipedDiagram, context) -> dict[str, np.ndarray]:
    states = parts.state_log.FindLog(context)
    acts = parts.actuation_log.FindLog(context)
    ctrl = parts.controller_log.FindLog(context)
    return {
        "time": states.sample_times().copy(),
        "positions": states.data()[:9].T.copy(),
        "velocities": states.data()[9:].T.copy(),
        "actuation": acts.data().T.copy(),
        "cpg_phase": ctrl.data()[ctl.GAMMA].copy(),
        "torque_free": ctrl.data()[ctl.GATE].copy(),
        "stance_right": ctrl.data()[ctl.STANCE_RIGHT].copy(),
        "step_start": ctrl.data()[ctl.STEP_START].copy(),
        "positive_work": ctrl.data()[ctl.POSITIVE_WORK : ctl.POSITIVE_WORK + 6].T.copy(),
        "position_names": np.array(["x", "z", "pitch", *JOINT_NAMES]),
        "actuator_names": np.array([f"{n}_motor" for n in JOINT_NAMES]),
    }
