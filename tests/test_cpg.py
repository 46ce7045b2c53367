"""The CPG phase and the torque-free gate, as pure functions and inside the controller system."""

import math

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from walkers import fast_config

from drake_biped import controller as ctl
from drake_biped import cpg
from drake_biped.diagram import initial_state
from drake_biped.model import joint_index
from drake_biped.params import CpgParams, TorqueFreeWindow


def test_output_is_equation_three_with_alpha_and_eta():
    p = CpgParams(alpha=0.5, u_a=2.0, u_eta=0.3, u_r=2.1, kappa=0.0)
    assert cpg.output(p, math.pi / 2) == pytest.approx(0.5 * 2.0 + 0.3)
    assert cpg.output(CpgParams(), 1.0) == pytest.approx(2.0 * math.sin(1.0))  # Table III: eq. 3 exactly


def test_swing_reference_endpoints_and_slope():
    assert cpg.swing_reference(0.0, -0.3, 0.4) == pytest.approx(-0.3)
    assert cpg.swing_reference(math.pi, -0.3, 0.4) == pytest.approx(0.4)
    # d(phi_d)/dt = (phi_T - phi_0)/2 sin(gamma) u_r == zeta when phi_T - phi_0 = 2 u_a / u_r
    p = CpgParams(u_a=2.0, u_r=4.0, kappa=0.0)
    a = p.swing_amplitude_rad
    g, h = 1.1, 1e-6
    rate = (cpg.swing_reference(g + h, -a, a) - cpg.swing_reference(g - h, -a, a)) / (2 * h) * p.u_r
    assert rate == pytest.approx(cpg.output(p, g), rel=1e-6)


@pytest.mark.parametrize("t, start, end, inside", [
    (0.25, 0.2, 0.5, True), (0.2, 0.2, 0.5, True), (0.5, 0.2, 0.5, False), (0.1, 0.2, 0.5, False),
    (0.3, 0.5, 0.5, False), (0.3, 0.6, 0.2, False),
    # bounds on the control grid hold despite rounding in t - T_n
    (0.851 - 0.651, 0.2, 0.5, True), (0.577 - 0.077, 0.2, 0.5, False),
])
def test_window_membership(t, start, end, inside):
    """A control period of 1 ms starting at t is wholly inside the window or wholly outside it."""
    assert cpg.torque_free_fraction(t, 1e-3, start, end) == (1.0 if inside else 0.0)


@pytest.mark.parametrize("elapsed, fraction", [
    (0.1, 0.0), (0.2, 1.0), (0.3, 1.0), (0.4995, 0.5), (0.1996, 0.6), (0.5, 0.0), (0.19, 0.0),
])
def test_torque_free_fraction_is_the_overlap_of_period_and_window(elapsed, fraction):
    assert cpg.torque_free_fraction(elapsed, 1e-3, 0.2, 0.5) == pytest.approx(fraction, abs=1e-9)
    assert cpg.torque_free_fraction(elapsed, 1e-3, 0.5, 0.2) == 0.0  # t2 <= t1: no window


def test_window_edges_between_updates_scale_the_torque_by_the_part_outside():
    """An edge inside a control period: that period's swing-hip torque is the servo's (the same walk
    without a window) times the part of the period outside the window; whole periods are 0 or unscaled."""
    window = TorqueFreeWindow(0.0503, 0.1203, first_step=0)
    dt, h = 1e-3, 1e-3
    c_w, sim_w, ctx_w = _controller_alone(fast_config(window=window))
    c_0, sim_0, ctx_0 = _controller_alone(fast_config())
    swing_hip = joint_index("left", "hip")
    seen = set()
    for k in range(1, 150):
        t = round(k * dt, 9)
        sim_w.AdvanceTo(t)
        sim_0.AdvanceTo(t)
        elapsed = t - dt + h
        part = cpg.torque_free_fraction(elapsed, dt, window.start_s, window.end_s)
        tau_w = c_w.get_output_port_actuation().Eval(ctx_w)[swing_hip]
        tau_0 = c_0.get_output_port_actuation().Eval(ctx_0)[swing_hip]
        assert abs(tau_0) > 0.1
        assert tau_w == pytest.approx((1.0 - part) * tau_0, rel=1e-12, abs=1e-12)
        assert c_w.state(ctx_w).torque_free == pytest.approx(part, abs=1e-12)
        seen.add(round(part, 3))
    assert {0.0, 1.0, 0.7, 0.3} <= seen  # both cut periods were met, and whole ones on both sides


def _controller_alone(config):
    """The controller with a fixed plant state whose swing foot is high in the air (no touchdown)."""
    q, v, stance_right, liftoff = initial_state(config)
    q = q.copy()
    q[1] += 0.05
    q[3] = -0.3  # left (swing) hip behind: its foot is also behind, so touchdown cannot be accepted
    q[4] = 0.6
    c = ctl.CpgWalkingController(config)
    sim = Simulator(c)
    ctx = sim.get_mutable_context()
    c.get_input_port_plant_state().FixValue(ctx, np.concatenate([q, v * 0.0]))
    c.set_initial_state(ctx, q[3:], 0.0, stance_right=stance_right, liftoff_angle=liftoff)
    return c, sim, ctx


def test_phase_matches_closed_form_when_kappa_is_zero():
    config = fast_config(cpg=CpgParams(u_a=2.0, u_r=2.1, kappa=0.0))
    c, sim, ctx = _controller_alone(config)
    for t in (0.1, 0.5, 1.0, 1.4):
        sim.AdvanceTo(t)
        gamma = c.state(ctx).cpg_phase
        # Updates at 0, dt, ..., t - dt have been applied by time t: gamma = u_r * t (Euler is exact here).
        assert gamma == pytest.approx(min(cpg.closed_form_phase(config.cpg, t), math.pi), abs=1e-9)
    sim.AdvanceTo(2.0)
    assert c.state(ctx).cpg_phase == pytest.approx(math.pi)


def test_kappa_feeds_stance_ankle_rate_into_phase():
    config = fast_config(cpg=CpgParams(u_a=2.0, u_r=2.0, kappa=1.5))
    c, sim, ctx = _controller_alone(config)
    q, v, _, _ = initial_state(config)
    x = c.get_input_port_plant_state().Eval(ctx).copy()
    x[9 + 3 + joint_index("right", "ankle")] = 0.4  # right (stance) ankle rate
    c.get_input_port_plant_state().FixValue(ctx, x)
    sim.AdvanceTo(0.5)
    assert c.state(ctx).cpg_phase == pytest.approx((2.0 + 1.5 * 0.4) * 0.5)


def test_gate_zeroes_swing_hip_and_freezes_integrator():
    window = TorqueFreeWindow(0.05, 0.12, first_step=0)
    config = fast_config(window=window)
    config = config.replace(gait=config.gait.__class__(**{**config.gait.to_dict(), "hip_ki": 50.0}))
    c, sim, ctx = _controller_alone(config)
    swing_hip = joint_index("left", "hip")  # the left leg is the first swing leg
    seen_in, seen_out = 0, 0
    integral_at_start = None
    t = 0.0
    while t < 0.2:
        t = round(t + config.sim.update_period_s, 9)
        sim.AdvanceTo(t)
        tau = c.get_output_port_actuation().Eval(ctx)
        s = c.state(ctx)
        # the torque now held was computed at t - dt and acts over [elapsed, elapsed + dt) after T_n = 0,
        # in plant-state time (the update reads the state one time step ahead)
        elapsed = t - config.sim.update_period_s + config.sim.time_step_s
        inside = window.start_s <= elapsed + 1e-9 and elapsed + config.sim.update_period_s <= window.end_s + 1e-9
        if inside:
            assert tau[swing_hip] == 0.0
            assert s.torque_free == 1.0
            integral_at_start = s.hip_integral if integral_at_start is None else integral_at_start
            assert s.hip_integral == integral_at_start
            seen_in += 1
        elif elapsed >= window.end_s - 1e-9 or elapsed + config.sim.update_period_s <= window.start_s + 1e-9:
            assert abs(tau[swing_hip]) > 0.1
            assert s.torque_free == 0.0
            seen_out += 1
    assert seen_in >= 60 and seen_out >= 100


def test_integrated_reading_drives_the_swing_by_zeta_unscaled():
    """Under the integrated reading, without placement feedback, the swing reference is the lift-off
    angle plus the integral of zeta, and the servo's rate reference is zeta: recovered from the hip torque
    of the controller on a fixed plant state (the thigh at rest)."""
    from drake_biped.params import PAPER_CPG, GaitParams

    gait = GaitParams(hip_drive="servo", swing_reading="integrated", placement_gain=0.0, placement_velocity_gain=0.0,
                      swing_offset_rad=0.0, hip_kp=80.0, hip_kd=9.0, hip_ki=0.0,
                      torso_pitch_rad=-0.06)  # a torso near upright: the servo starts below its limit
    config = fast_config(cpg=PAPER_CPG.__class__(**{**PAPER_CPG.to_dict(), "kappa": 0.0}), gait=gait)
    c, sim, ctx = _controller_alone(config)
    x = c.get_input_port_plant_state().Eval(ctx)
    q = x[:9]
    thigh = q[2] + q[3]  # the left (swing) thigh's world angle
    liftoff = c.state(ctx).liftoff_angle_rad
    dt = config.sim.update_period_s
    travel = 0.0
    swing_hip = joint_index("left", "hip")
    read = 0
    for k in range(1, 400):
        sim.AdvanceTo(round(k * dt, 9))
        gamma = c.state(ctx).cpg_phase
        zeta = cpg.output(config.cpg, gamma)
        travel += dt * zeta
        tau = c.get_output_port_actuation().Eval(ctx)[swing_hip]
        if abs(tau) < 39.0:  # below the torque limit the PID's terms can be read back
            reference = thigh + (tau - gait.hip_kd * zeta) / gait.hip_kp
            assert reference - liftoff == pytest.approx(travel, abs=1e-9)
            read += 1
    assert read > 150
    assert travel == pytest.approx(PAPER_CPG.u_a * (1 - math.cos(min(math.pi, 399 * dt * PAPER_CPG.u_r)))
                                   / PAPER_CPG.u_r, abs=0.01)


@pytest.mark.parametrize("gait, reading", [(None, "reset"), ("paper_entrained", "entrained")])
def test_the_phase_reading_decides_what_swaps_the_legs(gait, reading):
    """Under "reset" the legs swap roles at each touchdown and the phase starts again from 0 there; under
    "entrained" the phase runs on through touchdowns and the roles swap where it crosses pi (where zeta's
    sign changes), each touchdown only moving the step's clock and the leg in contact."""
    from drake_biped.episode import run_episode
    from drake_biped.resources import load_gait

    config = (fast_config() if gait is None else load_gait(gait)).override({"sim.distance_m": 3.0})
    if gait == "paper_entrained":  # it falls in its first step at 1 ms, and at 0.5 ms under the paper's clock;
        # it walks at 0.5 ms under a 1 kHz loop: the reading is what is tested
        config = config.override({"sim.time_step_s": 5e-4, "sim.control_period_s": 1e-3})
    assert config.gait.phase_reading == reading
    r = run_episode(config, record_trajectory=True, cache=None)
    T = r.trajectory
    gamma, roles, contact, clock = T["cpg_phase"], T["stance_right"], T["contact_right"], T["step_start"]
    role_swaps = set(np.flatnonzero(np.diff(roles) != 0) + 1)
    touchdowns = set(np.flatnonzero(np.diff(clock) != 0) + 1)
    wraps = set(np.flatnonzero(np.diff(gamma) < -1.0) + 1)  # the phase falling back by more than 1 rad
    assert len(touchdowns) >= 3 and len(role_swaps) >= 3
    assert touchdowns == set(np.flatnonzero(np.diff(contact) != 0) + 1)  # a touchdown changes the contact leg
    if reading == "reset":
        assert role_swaps == touchdowns == wraps
        assert np.array_equal(roles, contact)
    else:
        assert role_swaps == wraps  # the phase, not the feet, swaps the roles
        assert touchdowns - role_swaps  # and most touchdowns fall elsewhere in the half-cycle
        assert gamma.max() < math.pi and gamma.min() >= 0.0
