"""Run one episode (walk until a distance, a fall, or a time limit) and return an EpisodeResult record."""

from __future__ import annotations

import json
import math
import os
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import EventStatus

from drake_biped import control_kernel as ctl
from drake_biped.analysis.cost_of_transport import cost_of_transport, cost_of_transport_per_kg
from drake_biped.analysis.long_run import BATCHES, TRANSIENT_M, long_run_cost
from drake_biped.control_law import L_MOTOR, L_MOTOR_PLANT
from drake_biped.controller import CpgWalkingController
from drake_biped.diagram import BipedDiagram, build_diagram, initial_state
from drake_biped.kinematics import center_of_mass
from drake_biped.model import JOINT_NAMES, ROLES, joint_index
from drake_biped.params import GRAVITY_MPS2, EpisodeConfig, ParameterError, SimulationParams
from drake_biped.records import atomic_file, write_text_atomic
from drake_biped.resources import gait_identity
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
    positive_work_j: float | None = None  # the motors' positive work from the start to this touchdown (J)


STEP_ARRAY_DTYPE = np.dtype([("index", int), ("touchdown_time_s", float), ("hip_angle_rad", float),
                             ("hip_rate_radps", float), ("stance_right", bool), ("com_x_m", float),
                             ("positive_work_j", float)])


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
    # {role: {"positive_j", "negative_j"}} over the whole episode, roles as model.ROLES (swing hip, stance hip,
    # swing knee, ...), each control period counted for the roles held when it began; None in a record written
    # before it was kept
    work_by_role: dict[str, dict[str, float]] | None = None
    # which gait walked (resources.gait_identity): {"name": a shipped gait's or None, "sha256": the walker's digest};
    # found from `config` when the result is recorded (`to_dict`), not on an episode's own path
    gait: dict[str, str | None] | None = None

    @property
    def total_positive_work_j(self) -> float:
        return self.positive_work_j["total"]

    @property
    def touchdowns(self) -> np.ndarray:
        """The steps as one structured array, a row per touchdown: `touchdowns["hip_angle_rad"]` is the
        section angles, `touchdowns["touchdown_time_s"]` their times (fields: STEP_ARRAY_DTYPE)."""
        return np.array([(s.index, s.touchdown_time_s, s.hip_angle_rad, s.hip_rate_radps, s.stance_leg == "right",
                          s.com_x_m, math.nan if s.positive_work_j is None else s.positive_work_j)
                         for s in self.steps], dtype=STEP_ARRAY_DTYPE)

    def long_run(self, transient_m: float = TRANSIENT_M, batches: int = BATCHES) -> dict:
        """The walk's long-run C_mt after the initiation's transient, with its 95 % interval (batch means over
        steps) and its step periods' statistics: analysis.long_run.long_run_cost on this walk's touchdowns."""
        td = self.touchdowns
        return long_run_cost(td["touchdown_time_s"], td["com_x_m"], td["positive_work_j"], self.mass_kg,
                             GRAVITY_MPS2, transient_m, batches)

    @property
    def sections(self) -> np.ndarray:
        """The Poincare section states (hip angle, hip rate) of the steps, shape (steps, 2): what
        `fit_return_map` takes."""
        return np.array([[s.hip_angle_rad, s.hip_rate_radps] for s in self.steps], dtype=float).reshape(-1, 2)

    def walked_gait(self) -> dict[str, str | None]:
        """Which gait walked (`resources.gait_identity` of this result's configuration)."""
        if self.gait is None:
            from drake_biped.legacy import config_of_record

            self.gait = gait_identity(config_of_record(self.config, "EpisodeResult.config"))
        return self.gait

    def to_dict(self) -> dict[str, Any]:
        self.walked_gait()
        d = asdict(self)
        d.pop("trajectory")
        return d

    def to_json(self, path: str | Path) -> None:
        write_text_atomic(Path(path), json.dumps(self.to_dict(), indent=2, allow_nan=False) + "\n")

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> EpisodeResult:
        d = dict(d)
        d["steps"] = [StepRecord(**s) for s in d["steps"]]
        return cls(**d)

    def save_trajectory(self, path: str | Path) -> None:
        if self.trajectory is None:
            raise ValueError("this result holds no trajectory; run the episode with record_trajectory=True")
        with atomic_file(Path(path).with_suffix(".npz")) as tmp:
            np.savez_compressed(tmp, **self.trajectory)


def _finite_or_none(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


class DiagramCache:
    """Built diagrams and their simulators, kept for reuse by episodes of the same structure.

    Only the numbers of an episode (CPG, gait, window, initial conditions, distance) change between the
    episodes of a learning run or a grid search; rebuilding the diagram for each would cost a few ms and,
    with pydrake 1.51, leak ~0.4 MB per build (RobotLocomotion/drake#24529). An entry is keyed by what the
    diagram is built from: the ground, time step, control period, time limit, minimum step time, contact
    approximation and material, push, robot model and recording. At most `size` entries are kept (least recently used goes first).
    """

    def __init__(self, size: int = 4):
        self._size = size
        self._entries: OrderedDict[tuple, tuple[BipedDiagram, Simulator]] = OrderedDict()

    @staticmethod
    def key(config: EpisodeConfig, record: bool, log_period_s: float | None) -> tuple:
        return (
            CpgWalkingController.structure_key(config),
            config.sim.contact_approximation,
            config.contact,
            config.push,
            None if config.model is None else config.model.sha256,
            record,
            log_period_s,
        )

    def get(self, config: EpisodeConfig, record: bool, log_period_s: float | None) -> tuple[BipedDiagram, Simulator]:
        key = self.key(config, record, log_period_s)
        if key in self._entries:
            self._entries.move_to_end(key)
            return self._entries[key]
        parts = build_diagram(config, record=record, log_period_s=log_period_s)
        entry = (parts, Simulator(parts.diagram))
        self._entries[key] = entry
        while len(self._entries) > self._size:
            self._entries.popitem(last=False)
        return entry

    def __len__(self) -> int:
        return len(self._entries)


_CACHE = DiagramCache()


@dataclass(frozen=True)
class Kick:
    """An instantaneous change of the swing hip's angle (rad) and rate (rad/s) at time_s, as the plant's
    state is found then: a perturbation for finite-difference studies of the step-to-step map (the swing
    leg is in the air, so no contact is broken). Not part of an EpisodeConfig: a tool, not a scenario."""

    time_s: float
    hip_angle_rad: float = 0.0
    hip_rate_radps: float = 0.0

    def __post_init__(self) -> None:
        for name in ("time_s", "hip_angle_rad", "hip_rate_radps"):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"Kick.{name} must be finite, got {getattr(self, name)!r}")
        if self.time_s <= 0:
            raise ValueError(f"Kick.time_s must be > 0, got {self.time_s!r}")


def reset_context(parts: BipedDiagram, simulator: Simulator, config: EpisodeConfig):
    """Put the simulator's context at the start of an episode of `config`: defaults, time 0, empty logs,
    the episode's numbers in the controller's context, the paper's initiation. Returns the plant's and the
    controller's contexts and the initial centre-of-mass x."""
    root = simulator.get_mutable_context()
    parts.diagram.SetDefaultContext(root)
    root.SetTime(0.0)
    for log in (parts.state_log, parts.controller_log, parts.actuation_log):
        if log is not None:
            log.FindMutableLog(root).Clear()
    plant_ctx = parts.plant.GetMyMutableContextFromRoot(root)
    q0, v0, stance_right, liftoff = initial_state(config, parts.body)
    parts.plant.SetPositions(plant_ctx, q0)
    parts.plant.SetVelocities(plant_ctx, v0)
    com_x0 = center_of_mass(q0, parts.body)[0]
    ctrl_ctx = parts.controller.GetMyMutableContextFromRoot(root)
    parts.controller.set_episode(ctrl_ctx, config)
    parts.controller.set_initial_state(ctrl_ctx, q0[3:], com_x0, config.sim.distance_m, stance_right, liftoff,
                                      pitch=q0[2], phase=config.initial.cpg_phase_rad)
    law = parts.controller.law(ctrl_ctx)
    parts.controller.apply_motors(law, ctrl_ctx.get_discrete_state(parts.controller.state_group).value())
    return plant_ctx, ctrl_ctx, com_x0


def simulate(
    config: EpisodeConfig,
    meshcat=None,
    progress: Callable[[float, float], None] | None = None,
    record: bool = False,
    log_period_s: float | None = None,
    cache: DiagramCache | None = _CACHE,
    kick: Kick | None = None,
) -> tuple[BipedDiagram, Simulator, str, float]:
    """Run one episode; return the diagram, the simulator, the termination reason and the wall time.

    The diagram comes from `cache` when one of the same structure was built before (never with Meshcat;
    cache=None always builds a new one); its context is reset to the defaults and this episode's numbers
    and initial state. The controller ends the episode itself (a fall, or the distance walked). An episode
    that records nothing and draws nothing steps the plant directly, the controller's compiled update between
    its steps (`_step_directly`: the Simulator's numbers to the last bit, at a lower cost per step); one that
    records or draws runs under the Simulator, the controller a Drake system in the diagram. `progress`
    is called every 0.25 simulated s with the time and the distance walked. Reasons: "distance", "fall",
    "time limit", "diverged" (the control loop: see controller.REVERSAL_FACTOR), or "simulation failed: ..." (a diverging contact solve).
    """
    if meshcat is None and cache is not None:
        parts, simulator = cache.get(config, record, log_period_s)
    else:
        parts = build_diagram(config, meshcat=meshcat, record=record, log_period_s=log_period_s)
        simulator = Simulator(parts.diagram)
    plant_ctx, ctrl_ctx, com_x0 = reset_context(parts, simulator, config)
    if not record and meshcat is None and _DIRECT_STEPS:
        wall0 = time.perf_counter()
        try:
            _step_directly(parts, simulator.get_mutable_context(), config, progress, kick, com_x0)
            reason = _reason(parts.controller.state(ctrl_ctx))
        except RuntimeError as exc:  # a diverging contact solve: the episode is a fall, not a crash
            reason = f"simulation failed: {exc}".splitlines()[0]
        return parts, simulator, reason, time.perf_counter() - wall0
    group = parts.controller.state_group
    if progress is not None:
        next_report = [0.0]

        def monitor(context):
            if context.get_time() >= next_report[0]:
                next_report[0] += 0.25
                progress(context.get_time(), ctrl_ctx.get_discrete_state(group).GetAtIndex(ctl.COM_X) - com_x0)
            return EventStatus.Succeeded()

        simulator.set_monitor(monitor)
    else:
        simulator.clear_monitor()
    simulator.Initialize()
    wall0 = time.perf_counter()
    try:
        if kick is not None and kick.time_s < config.sim.max_time_s:
            simulator.AdvanceTo(kick.time_s)
            s = parts.controller.state(ctrl_ctx)
            if s.fall_code == 0.0 and s.done == 0.0:
                _kick(parts.plant, plant_ctx, s.stance_right > 0.5, kick)
        simulator.AdvanceTo(config.sim.max_time_s)
        reason = _reason(parts.controller.state(ctrl_ctx))
    except RuntimeError as exc:  # a diverging contact solve: the episode is a fall, not a crash
        reason = f"simulation failed: {exc}".splitlines()[0]
    wall = time.perf_counter() - wall0
    return parts, simulator, reason, wall


def _kick(plant, plant_ctx, stance_right: bool, kick: Kick) -> None:
    """Add `kick` to the swing hip's angle and rate in the plant's state."""
    i = 3 + joint_index("left" if stance_right else "right", "hip")  # the swing hip
    q = plant.GetPositions(plant_ctx).copy()
    v = plant.GetVelocities(plant_ctx).copy()
    q[i] += kick.hip_angle_rad
    v[i] += kick.hip_rate_radps
    plant.SetPositions(plant_ctx, q)
    plant.SetVelocities(plant_ctx, v)


def _reason(s) -> str:
    """Why an episode ended, from the controller's state at its end."""
    if s.fall_code == ctl.DIVERGED_CODE:
        return "diverged"
    return "fall" if s.fall_code != 0.0 else ("distance" if s.done else "time limit")


# Whether `simulate` steps the plant itself when it records nothing (see _step_directly); the Simulator path
# stays for recording, Meshcat and comparison (tests/test_hot_path.py).
_DIRECT_STEPS = True


def _step_directly(parts: BipedDiagram, root, config: EpisodeConfig, progress, kick: Kick | None,
                   com_x0: float) -> None:
    """The episode of simulate() without the Simulator: the plant's discrete step (its forced update, the
    one its periodic event runs) called in a loop, and the controller's compiled update called with the
    state that step produced at every control period, exactly as the Simulator orders the two events that
    fall at the same time (the controller reads the plant's sampled output: the state the step makes; the
    step acts with the torques held before). The same numbers as the Simulator path to the last bit
    (tests/test_hot_path.py), without the Simulator's event dispatch and the Python callback it makes every
    control period: the default walk at 0.91 of the plant's speed instead of 0.73 (docs/HISTORY.md, "The
    plant stepped directly")."""
    plant, controller = parts.plant, parts.controller
    plant_ctx = plant.GetMyMutableContextFromRoot(root)
    ctrl_ctx = controller.GetMyMutableContextFromRoot(root)
    h = config.sim.time_step_s
    every = int(round(config.sim.update_period_s / h))
    x = plant_ctx.get_discrete_state(0).get_value()
    s = ctrl_ctx.get_mutable_discrete_state(controller.state_group).get_mutable_value()
    tau = ctrl_ctx.get_mutable_discrete_state(controller.torque_group).get_mutable_value()
    touchdowns = ctrl_ctx.get_mutable_discrete_state(controller.touchdown_group).get_mutable_value()
    command = ctrl_ctx.get_mutable_discrete_state(controller.command_group).get_mutable_value()
    law, body, row = controller.kernel_arguments(ctrl_ctx)
    plant_motor = law[L_MOTOR_PLANT] != 0.0  # the plant's hip motors take their gains after each update
    apply_motors = controller.apply_motors
    motor = law[L_MOTOR] != 0.0 and not plant_motor  # the controller's motor reads the plant's dynamics
    dyn = controller.motor_dynamics(law, x, s)
    store = controller.store_touchdown
    torques = controller.torque_group
    step = plant.ExecuteForcedEvents
    set_time, mutable = root.SetTime, ctrl_ctx.get_mutable_discrete_state
    pushed = config.push is not None and config.push.force_n != 0.0 and config.push.duration_s > 0.0
    end = config.sim.max_time_s
    next_report = 0.0
    k = 0
    kick_time = kick.time_s if kick is not None and kick.time_s < end else None
    while True:
        t = k * h
        if kick_time is not None and t >= kick_time:
            kick_time = None
            if s[ctl.FALL] == 0.0 and s[ctl.DONE] == 0.0:
                _kick(plant, plant_ctx, s[ctl.STANCE_RIGHT] > 0.5, kick)
                x = plant_ctx.get_discrete_state(0).get_value()
        if t >= end:
            break
        if pushed:
            set_time(t)
        step(plant_ctx, False)
        if k % every == 0:
            if motor:
                dyn = controller.motor_dynamics(law, x, s)
            code = ctl.control_step(law, body, t, x, s, tau, row, dyn, command)
            # the held torques changed (and the motors' command): what reads them is out of date
            if plant_motor:
                mutable()  # every group, in one call
            else:
                mutable(torques)
            if code:
                if code & ctl.MOTORS:
                    apply_motors(law, s)
                if code & ctl.TOUCHED:
                    store(touchdowns)
                if code & (ctl.FELL | ctl.DONE_BIT):
                    break
        k += 1
        if progress is not None and k * h >= next_report:
            next_report += 0.25
            progress(k * h, s[ctl.COM_X] - com_x0)
    set_time(k * h)
    ctrl_ctx.get_mutable_discrete_state()  # every group was written in place


def check_record_memory(config: EpisodeConfig) -> None:
    """ParameterError naming the time limit, before any work, when a recorded episode (its state, controller
    state and torques logged at every update, or a Meshcat recording) could fill more than half this machine's
    memory: a walk that may last `sim.max_time_s`, recorded, is bounded by it."""
    samples = config.sim.max_time_s / config.sim.update_period_s
    need = samples * 8.0 * 2 * (18 + ctl.N_STATE + 6)  # float64, the logs and their copy in the result
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        total = 8 << 30
    if need > total / 2:
        raise ParameterError(f"sim.max_time_s = {config.sim.max_time_s:g} (--max-time): a recorded walk that long would "
                             f"hold about {need / 2**30:,.1f} GiB of logs at one sample per "
                             f"{1e3 * config.sim.update_period_s:g} ms update, more than half this machine's "
                             f"{total / 2**30:.0f} GiB; give a shorter time limit, or walk without recording")


def run_episode(
    config: EpisodeConfig | None = None,
    meshcat=None,
    record_trajectory: bool = False,
    progress: Callable[[float, float], None] | None = None,
    cache: DiagramCache | None = _CACHE,
    kick: Kick | None = None,
) -> EpisodeResult:
    """Walk one episode and summarise it (see EpisodeResult). `cache`, `kick`: see simulate() and Kick.

    The episode ends at the control update that detects a fall or the distance walked; its duration,
    distance and work are those of the plant state that update read (see controller "Timing").
    """
    config = EpisodeConfig() if config is None else config
    if not isinstance(config, EpisodeConfig):
        raise ParameterError(f"run_episode: config must be an EpisodeConfig (or None for the default), got "
                             f"{type(config).__name__}")
    if cache is not None and not isinstance(cache, DiagramCache):
        raise ParameterError(f"run_episode: cache must be a DiagramCache or None, got {type(cache).__name__} "
                             f"{cache!r}")
    if kick is not None and not isinstance(kick, Kick):
        raise ParameterError(f"run_episode: kick must be a Kick or None, got {type(kick).__name__}")
    if not isinstance(record_trajectory, bool):  # "no" would record
        raise ParameterError(f"run_episode: record_trajectory must be a bool, got {type(record_trajectory).__name__} "
                             f"{record_trajectory!r:.60}")
    if record_trajectory or meshcat is not None:
        check_record_memory(config)
    parts, simulator, reason, wall = simulate(
        config, meshcat=meshcat, progress=progress, record=record_trajectory, cache=cache, kick=kick
    )
    context = simulator.get_context()
    ctrl_ctx = parts.controller.GetMyContextFromRoot(context)
    s = parts.controller.state(ctrl_ctx)
    t_end = s.state_time_s
    fall_code = int(s.fall_code)
    fell = reason != "distance" and reason != "time limit"
    if reason == "diverged":
        fall_reason = (f"the control loop diverged: {ctl.DIVERGED_REVERSALS} torque reversals of more than "
                       f"{ctl.REVERSAL_FACTOR:g} x a motor's limit within {ctl.DIVERGENCE_SPAN_PERIODS} control "
                       f"periods ({int(s.torque_reversals)} in all; the control period "
                       f"{config.sim.update_period_s:g} s is too long for the servos)")
    else:
        fall_reason = ctl.FALL_REASONS.get(fall_code, "") if reason == "fall" else ("" if not fell else reason)

    q0, _, _, _ = initial_state(config, parts.body)
    distance = s.com_x_m - center_of_mass(q0, parts.body)[0]

    work = s.positive_work_j
    positive = {n: float(work[i]) for i, n in enumerate(JOINT_NAMES)}
    positive["total"] = float(sum(work))
    work = s.signed_work_j
    signed = {n: float(work[i]) for i, n in enumerate(JOINT_NAMES)}
    signed["total"] = float(sum(work))
    by_role = {role: {"positive_j": float(p), "negative_j": float(n)}
               for role, p, n in zip(ROLES, s.positive_work_by_role_j, s.negative_work_by_role_j)}

    steps = step_records(parts.controller.touchdowns(ctrl_ctx))
    if len(steps) >= 3:
        times = np.array([st.touchdown_time_s for st in steps])
        xs = np.array([st.com_x_m for st in steps])
        step_period = float(np.mean(np.diff(times[1:])))
        step_length = float(np.mean(np.diff(xs[1:])))
    else:
        step_period = step_length = None

    mass = parts.masses.total  # the model's, not Table I's
    cmt = cost_of_transport(positive["total"], mass, distance, GRAVITY_MPS2)
    cmt_kg = cost_of_transport_per_kg(positive["total"], mass, distance)
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
        mass_kg=mass,
        wall_time_s=wall,
        real_time_factor=float(t_end / wall) if wall > 0 else math.inf,
        seed=config.seed,
        versions=versions(),
        trajectory=trajectory,
        work_by_role=by_role,
    )


def step_records(touchdowns: np.ndarray) -> list[StepRecord]:
    """StepRecords from the controller's touchdown rows (columns: controller.TOUCHDOWN_FIELDS)."""
    return [
        StepRecord(
            index=k + 1,
            touchdown_time_s=float(row[0]),
            hip_angle_rad=float(row[1]),
            hip_rate_radps=float(row[2]),
            stance_leg="right" if row[3] > 0.5 else "left",
            com_x_m=float(row[4]),
            positive_work_j=float(row[5]),
        )
        for k, row in enumerate(touchdowns)
    ]


def _trajectory(parts: BipedDiagram, context) -> dict[str, np.ndarray]:
    """The logged signals (the diagram must have been built with record=True)."""
    states = parts.state_log.FindLog(context)
    acts = parts.actuation_log.FindLog(context)
    ctrl = parts.controller_log.FindLog(context).data()
    rows = ctl.CONTROLLER_STATE.rows
    actuation = acts.data().T.copy()
    if parts.actuation_applied and len(actuation) > 1:
        # row k: the torques over [t_k, t_k+1), which the plant reports with the state at t_k+1; the last
        # period, which the walk did not finish, repeats the one before
        actuation = np.vstack([actuation[1:], actuation[-1:]])
    return {
        "time": states.sample_times().copy(),
        "positions": states.data()[:9].T.copy(),
        "velocities": states.data()[9:].T.copy(),
        "actuation": actuation,
        "cpg_phase": rows(ctrl, "cpg_phase"),
        "torque_free": rows(ctrl, "torque_free"),
        "stance_right": rows(ctrl, "stance_right"),
        "contact_right": rows(ctrl, "contact_right"),
        "step_start": rows(ctrl, "step_start_s"),
        "positive_work": rows(ctrl, "positive_work_j"),
        "positive_work_by_role": rows(ctrl, "positive_work_by_role_j"),  # columns: model.ROLES
        "negative_work_by_role": rows(ctrl, "negative_work_by_role_j"),
        "position_names": np.array(["x", "z", "pitch", *JOINT_NAMES]),
        "actuator_names": np.array([f"{n}_motor" for n in JOINT_NAMES]),
    }


def warm_up() -> None:
    """Compile (or load from numba's cache) every kernel of the control loop by walking a few control
    periods, so that the first timed episode of a process spends nothing on compiling."""
    run_episode(EpisodeConfig(sim=SimulationParams(distance_m=0.05, max_time_s=0.05)), cache=None)
