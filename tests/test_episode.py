"""A short walk: it walks, its energy books balance, its record is complete."""

import json
import re

import numpy as np
import pytest
from walkers import fast_config

from drake_biped.analysis.cost_of_transport import positive_work
from drake_biped.diagram import TorsoPush, build_diagram
from drake_biped.episode import EpisodeResult, run_episode, simulate
from drake_biped.model import build_plant
from drake_biped.params import (
    GRAVITY_MPS2,
    TOTAL_MASS_KG,
    EpisodeConfig,
    InitialConditions,
    Push,
    SimulationParams,
    TorqueFreeWindow,
)


def test_short_walk_does_not_fall(short_walk):
    r = short_walk
    assert not r.fell and r.termination == "distance"
    assert r.distance_m >= 3.0
    assert len(r.steps) >= 3
    assert all(s.hip_angle_rad > 0 for s in r.steps)  # the leading leg is ahead at every touchdown
    legs = [s.stance_leg for s in r.steps]
    assert all(a != b for a, b in zip(legs, legs[1:]))  # legs alternate
    assert r.cost_of_transport is not None and 0 < r.cost_of_transport < 5
    assert r.cost_of_transport_per_kg == pytest.approx(GRAVITY_MPS2 * r.cost_of_transport)


def test_in_simulation_work_equals_torque_times_displacement(short_walk):
    """The integrator's positive work equals analysis.positive_work over the logged control steps
    (torque held over each step, joint rate = displacement / step): the audit anyone can run on
    trajectory.npz."""
    T = short_walk.trajectory
    dt = float(np.diff(T["time"])[0])
    omega = np.diff(T["positions"][:, 3:], axis=0) / dt
    offline = positive_work(T["actuation"][:-1], omega, dt)
    np.testing.assert_allclose(T["positive_work"][-1], offline, rtol=1e-9, atol=1e-9)


def test_work_energy_theorem(short_walk):
    """Motor work + gravity work - change of kinetic energy = energy dissipated (contact, limits) >= 0."""
    T = short_walk.trajectory
    plant = build_plant()
    ctx = plant.CreateDefaultContext()

    def energy(i):
        plant.SetPositions(ctx, T["positions"][i])
        plant.SetVelocities(ctx, T["velocities"][i])
        com_z = plant.CalcCenterOfMassPositionInWorld(ctx)[2]
        return plant.CalcKineticEnergy(ctx), com_z

    ke0, z0 = energy(0)
    ke1, z1 = energy(-1)
    dq = np.diff(T["positions"][:, 3:], axis=0)
    motor = float(np.sum(T["actuation"][:-1] * dq))
    gravity = -TOTAL_MASS_KG * GRAVITY_MPS2 * (z1 - z0)
    dissipated = motor + gravity - (ke1 - ke0)
    positive = float(T["positive_work"][-1].sum())
    assert dissipated > -0.02 * positive
    assert dissipated < positive  # cannot lose more than the motors put in plus what gravity gave


def test_window_gives_zero_swing_hip_torque_whenever_gated():
    config = fast_config(window=TorqueFreeWindow(0.1, 0.3), sim=SimulationParams(distance_m=1.0, max_time_s=5.0))
    r = run_episode(config, record_trajectory=True)
    T = r.trajectory
    gated = T["torque_free"] == 1.0  # periods wholly inside the window (an edge period is scaled)
    assert gated.sum() > 50
    swing_hip = np.where(T["stance_right"] > 0.5, T["actuation"][:, 0], T["actuation"][:, 3])
    assert np.all(swing_hip[gated] == 0.0)
    assert np.any(np.abs(swing_hip[~gated]) > 1.0)


def test_result_record_round_trips(short_walk, tmp_path):
    path = tmp_path / "result.json"
    short_walk.to_json(path)
    data = json.loads(path.read_text())
    for key in ("distance_m", "duration_s", "fell", "fall_reason", "steps", "positive_work_j",
                "cost_of_transport", "cost_of_transport_per_kg", "mean_speed_mps", "config", "seed", "versions"):
        assert key in data
    assert data["versions"]["drake"]
    assert set(data["steps"][0]) >= {"touchdown_time_s", "hip_angle_rad", "hip_rate_radps"}
    again = EpisodeResult.from_dict(data)
    assert again.distance_m == short_walk.distance_m
    assert EpisodeConfig.from_dict(data["config"]) == EpisodeConfig.from_dict(short_walk.config)


def test_same_config_same_numbers():
    config = fast_config(sim=SimulationParams(distance_m=0.5, max_time_s=3.0), seed=7)
    a, b = run_episode(config), run_episode(config)
    assert a.positive_work_j == b.positive_work_j and a.distance_m == b.distance_m


def test_push_delivers_its_impulse():
    plant = build_plant()
    push = TorsoPush(plant, Push(force_n=20.0, start_s=0.4, duration_s=0.1))
    dt = 1e-4
    ts = np.arange(0.0, 1.0, dt)
    impulse = sum(push.force_at(t) for t in ts) * dt
    assert impulse == pytest.approx(2.0, abs=2 * 20.0 * dt)
    assert push.force_at(0.39) == 0.0 and push.force_at(0.45) == 20.0 and push.force_at(0.51) == 0.0


def test_push_is_wired_only_when_requested():
    names = lambda c: [s.get_name() for s in build_diagram(c).diagram.GetSystems()]  # noqa: E731
    assert "torso_push" not in names(fast_config())
    assert "torso_push" in names(fast_config(push=Push(20.0, 0.4, 0.1)))


def test_a_torque_free_window_saves_the_hips_work_on_a_short_walk():
    """The property of the slow 10 m test below, on 2 m (the first steps, the initiation's included): the hip
    freed from 0.2 s until the foot lands does less positive work per metre (measured -25 %) and the walk
    costs less (-27 %)."""
    sim = SimulationParams(distance_m=2.0, max_time_s=10.0)
    base = run_episode(fast_config(sim=sim))
    gated = run_episode(fast_config(sim=sim, window=TorqueFreeWindow(0.2, 1.2)))
    assert not base.fell and not gated.fell
    hips = lambda r: r.positive_work_j["left_hip"] + r.positive_work_j["right_hip"]  # noqa: E731
    assert hips(gated) / gated.distance_m < 0.8 * hips(base) / base.distance_m
    assert gated.cost_of_transport < base.cost_of_transport


@pytest.mark.slow
def test_torque_free_window_saves_energy_without_a_fall():
    """The default gait's defining property: its swing hip off from 0.3 s after each touchdown until the foot
    lands (t2 past any step), it walks 10 m for much less, and as much less at half the plant step (measured
    with the 0.1326 rad initiation of its search: -49.9 %, and -44.4 % at 0.5 ms)."""
    hips = lambda r: r.positive_work_j["left_hip"] + r.positive_work_j["right_hip"]  # noqa: E731
    for step in (1e-3, 5e-4):
        sim = SimulationParams(time_step_s=step)
        base = run_episode(fast_config(sim=sim))
        gated = run_episode(fast_config(sim=sim, window=TorqueFreeWindow(0.3, 1.2)))
        assert not base.fell and not gated.fell and gated.distance_m >= 10.0
        assert gated.cost_of_transport < 0.65 * base.cost_of_transport
        assert hips(gated) / gated.distance_m < 0.65 * hips(base) / base.distance_m


def test_push_changes_the_airborne_robot_momentum_by_exactly_its_impulse():
    """Physics, not bookkeeping: lifted 5 m above the ground (no contact for the 0.6 s simulated), the
    robot's horizontal momentum changes only by external horizontal forces, so across the push it must
    change by 20 N x 0.1 s = 2 N*s, and not before or after it (the motors' torques are internal). The
    discrete scheme conserves momentum to O(h) per step only (velocities updated at q_n, read at q_n+1):
    the swinging legs make it wander by < 0.01 N*s over 0.1 s here, hence the tolerance of 1 %."""
    from pydrake.systems.analysis import Simulator

    from drake_biped.diagram import initial_state

    config = fast_config(push=Push(force_n=20.0, start_s=0.4, duration_s=0.1),
                           sim=SimulationParams(max_time_s=1.0))
    parts = build_diagram(config)
    sim = Simulator(parts.diagram)
    root = sim.get_mutable_context()
    ctx = parts.plant.GetMyMutableContextFromRoot(root)
    q0, v0, _, _ = initial_state(config)
    q0 = q0.copy()
    q0[1] += 5.0
    parts.plant.SetPositions(ctx, q0)
    parts.plant.SetVelocities(ctx, v0)

    def momentum_x():
        return parts.plant.CalcSpatialMomentumInWorldAboutPoint(ctx, np.zeros(3)).translational()[0]

    p = {}
    for t in (0.3, 0.4, 0.5, 0.6):
        sim.AdvanceTo(t)
        p[t] = momentum_x()
    assert p[0.4] - p[0.3] == pytest.approx(0.0, abs=0.02)
    assert p[0.5] - p[0.4] == pytest.approx(2.0, abs=0.02)
    assert p[0.6] - p[0.5] == pytest.approx(0.0, abs=0.02)


def test_a_kick_changes_the_swing_hip_and_nothing_else_changes_without_one():
    from drake_biped.episode import Kick

    config = fast_config(sim=SimulationParams(distance_m=2.0, max_time_s=8.0))
    plain = run_episode(config)
    assert run_episode(config, kick=Kick(time_s=100.0)).steps == plain.steps  # after the end: no kick
    kicked = run_episode(config, kick=Kick(time_s=1.0, hip_rate_radps=0.3))
    before = [s for s in plain.steps if s.touchdown_time_s < 1.0]
    assert kicked.steps[: len(before)] == before  # identical up to the kick
    assert kicked.steps[len(before)].hip_rate_radps != plain.steps[len(before)].hip_rate_radps
    with pytest.raises(ValueError, match="time_s"):
        Kick(time_s=0.0)
    with pytest.raises(ValueError, match="finite"):
        Kick(time_s=1.0, hip_angle_rad=float("nan"))


def test_the_first_swing_starts_from_the_initial_cpg_phase():
    """InitialConditions.cpg_phase_rad seeds gamma: the first update advances it from there (eq. 2)."""

    config = fast_config(initial=InitialConditions(cpg_phase_rad=1.2),
                           sim=SimulationParams(distance_m=0.05, max_time_s=0.0105))
    parts, simulator, _, _ = simulate(config, cache=None)
    s = parts.controller.state(parts.controller.GetMyContextFromRoot(simulator.get_context()))
    assert 1.2 < s.cpg_phase < 1.2 + 0.0115 * (config.cpg.u_r + 3 * config.cpg.kappa)
    zero = simulate(config.replace(initial=InitialConditions()), cache=None)
    s0 = zero[0].controller.state(zero[0].controller.GetMyContextFromRoot(zero[1].get_context()))
    assert s.cpg_phase - s0.cpg_phase == pytest.approx(1.2, abs=0.01)


def test_a_diverging_control_loop_is_named_diverged_not_a_fall():
    """At a 10 ms control period the servos chatter between their limits (the work 2273 J in 0.94 s, C_mt
    803, was reported as an ordinary fall): the episode now ends as 'diverged' at the fifth torque reversal,
    while the walk at 1 ms has none."""
    from drake_biped import control_kernel as ctl

    coarse = run_episode(fast_config().override({"sim.time_step_s": 0.01, "sim.control_period_s": 0.01,
                                                   "sim.distance_m": 1.0}))
    assert coarse.termination == "diverged" and coarse.fell
    reversals = re.match(r"the control loop diverged: (\d+) torque reversals", coarse.fall_reason)
    assert reversals and 5 <= int(reversals.group(1)) <= 8  # the fifth ends it; one update may add a few
    assert coarse.duration_s < 0.2  # caught within a few periods, not after a second of chattering
    parts, simulator, reason, _ = simulate(fast_config(sim=SimulationParams(distance_m=2.0, max_time_s=8.0)))
    state = parts.controller.state(parts.controller.GetMyContextFromRoot(simulator.get_context()))
    assert reason == "distance" and state.torque_reversals == 0.0 and ctl.DIVERGED_REVERSALS == 5
