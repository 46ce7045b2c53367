"""The hip as ODE's joint motor (GaitParams.hip_drive "motor"): zeta is the hip joint's (or the inter-leg
angle's) desired velocity, reached within each control update while the torque is under the motor's limit, whether
the plant solves the motor in its step (motor_solve "plant") or the controller from a model of the plant
("controller"); the torque-free gate still gives exactly zero; the work counted is that of the torque the plant
applied."""

import numpy as np
import pytest
from walkers import FAST

import drake_biped.control_kernel as ctl
from drake_biped.cpg import output
from drake_biped.diagram import build_diagram
from drake_biped.episode import reset_context, run_episode
from drake_biped.kinematics import B_HIP_EFFORT
from drake_biped.params import EpisodeConfig, TorqueFreeWindow

# (hip joint, where the motor is solved): every reading the parameters accept
READINGS = [("swing", "plant"), ("swing", "controller"), ("inter_leg", "controller")]


def _motor(joint: str, solve: str = "plant", **changes) -> EpisodeConfig:
    """Our own fast gait (`fast_servo`, 0.43 s steps at 1 ms) driven by the motor: quick walks that reach its
    limit, its window and the knees' stops."""
    return FAST.override({"gait.hip_drive": "motor", "gait.hip_joint": joint, "gait.motor_solve": solve,
                                     "sim.distance_m": 10.0, **changes})


def _tracking(config: EpisodeConfig, seconds: float) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """Step the plant and the compiled update as episode._step_directly does, and return, for each update whose
    hip torques lie under their limits (the motor's, and both hips' own; roles that do not swap, outside any
    window), the rate
    the motor drives after the plant's next step and the zeta that update aimed at; max |zeta|; and the swing
    hip's torque the plant applied over that step (its net actuation)."""
    from pydrake.systems.analysis import Simulator

    parts = build_diagram(config)
    simulator = Simulator(parts.diagram)
    reset_context(parts, simulator, config)
    root = simulator.get_mutable_context()
    plant, controller = parts.plant, parts.controller
    pc, cc = plant.GetMyMutableContextFromRoot(root), controller.GetMyMutableContextFromRoot(root)
    x = pc.get_discrete_state(0).get_value()
    s = cc.get_mutable_discrete_state(controller.state_group).get_mutable_value()
    tau = cc.get_mutable_discrete_state(controller.torque_group).get_mutable_value()
    command = cc.get_mutable_discrete_state(controller.command_group).get_mutable_value()
    law, body, row = controller.kernel_arguments(cc)
    inter = config.gait.hip_joint == "inter_leg"
    in_plant = config.gait.motor_solve == "plant"
    hip = body[B_HIP_EFFORT]
    h, pending, rates, aims, top, applied = config.sim.time_step_s, None, [], [], 0.0, []
    net = plant.get_net_actuation_output_port()
    for k in range(int(seconds / h)):
        plant.ExecuteForcedEvents(pc, False)
        v = x[9:]
        if pending is not None:
            sw, st, zeta, held = pending
            if in_plant:  # the torques the plant's motors applied over that step
                held = list(net.Eval(pc)[[0, 3]])
            drive = held[(sw - 3) // 3] - (0.5 * sum(held) if inter else 0.0)
            if abs(drive) < 0.99 * config.gait.motor_limit_nm and max(map(abs, held)) < 0.99 * hip:
                rates.append(v[sw] - v[st] if inter else v[sw])
                aims.append(zeta)
                applied.append(held[(sw - 3) // 3])
        stance_right = s[ctl.STANCE_RIGHT] > 0.5
        code = ctl.control_step(law, body, k * h, x, s, tau, row, controller.motor_dynamics(law, x, s), command)
        cc.get_mutable_discrete_state(controller.torque_group)
        cc.get_mutable_discrete_state(controller.command_group)
        controller.apply_motors(law, s)
        sw, st = (ctl.Q_HIP_LEFT, ctl.Q_HIP_RIGHT) if s[ctl.STANCE_RIGHT] > 0.5 else (ctl.Q_HIP_RIGHT, ctl.Q_HIP_LEFT)
        zeta = output(config.cpg, s[ctl.GAMMA])
        top = max(top, abs(zeta))
        free = (stance_right != (s[ctl.STANCE_RIGHT] > 0.5)) or s[ctl.GATE] > 0.0
        pending = None if free else (sw, st, zeta, [tau[0], tau[3]])
        if code & (ctl.FELL | ctl.DONE_BIT):
            break
    return np.array(rates), np.array(aims), top, np.array(applied)


@pytest.mark.parametrize("joint,solve", READINGS)
def test_the_motor_brings_the_joints_velocity_to_zeta_within_the_update(joint, solve):
    """Under its limit the motor reaches the velocity zeta asks for by the end of each update, as ODE's motor
    (a velocity constraint) does: within 1 % of max |zeta| at 95 % of the updates. The controller's motor misses
    the update after an impact (a knee reaching its stop), which its model sees only once it has happened; the
    plant's motor misses by its torque over its gain (1000 N*m*s/rad: 8.7 mrad/s at the paper's limit), exactly as
    Drake's implicit PD law gives it from the rate the plant's step solved for."""
    config = _motor(joint, solve)
    rates, aims, top, applied = _tracking(config, 0.4)
    error = np.abs(rates - aims) / top
    assert len(error) > 200
    if solve == "plant":
        np.testing.assert_allclose(-config.gait.motor_gain_nms * (rates - aims), applied, rtol=1e-9, atol=1e-9)
        assert np.quantile(error, 0.9) <= 0.015, np.quantile(error, [0.5, 0.9, 0.95, 0.99])
    else:
        assert np.quantile(error, 0.95) <= 0.01, np.quantile(error, [0.5, 0.9, 0.95, 0.99])
    assert np.median(error) <= 0.002


@pytest.mark.parametrize("joint,solve", READINGS)
def test_inside_the_window_the_motors_torque_is_exactly_zero(joint, solve):
    """The torque the plant applied (recorded from its net actuation where it solves the motor) is exactly zero
    on the swing hip for every update inside the window."""
    config = _motor(joint, solve).replace(window=TorqueFreeWindow(0.05, 0.15, first_step=0))
    T = run_episode(config.override({"sim.distance_m": 0.5, "sim.max_time_s": 1.0}), record_trajectory=True,
                    cache=None).trajectory
    gated = T["torque_free"] == 1.0
    swing_hip = np.where(T["stance_right"] > 0.5, T["actuation"][:, 0], T["actuation"][:, 3])
    assert gated.sum() > 50
    assert np.all(swing_hip[gated] == 0.0)
    assert np.any(np.abs(swing_hip[~gated]) > 1.0)


@pytest.mark.parametrize("solve", ["plant", "controller"])
def test_the_work_counted_is_that_of_the_torque_the_plant_applied(solve):
    """The plant's own net actuation (its output port) is the torque the walk records, and the positive work
    counted equals that torque's work over the logged joint displacements, held over each update. Where the plant
    solves the motor, the controller counts the torque each hip's actuator applied (`realized_hip_torques_k`)
    and it equals the plant's to rounding; where the controller solves it, the plant applies the torque held."""
    from drake_biped.analysis.cost_of_transport import positive_work
    from drake_biped.episode import simulate

    config = _motor("swing", solve, **{"sim.distance_m": 0.5, "sim.max_time_s": 1.0})
    parts, simulator, _, _ = simulate(config, record=True, cache=None)
    root = simulator.get_context()
    applied = parts.plant.get_net_actuation_output_port().Eval(parts.plant.GetMyContextFromRoot(root))
    held = parts.actuation_log.FindLog(root).data()  # one column per update
    if solve == "plant":
        # each update's gains, targets, bounds and feedforward (the controller's log), the rate the plant's next
        # step ended at (the state's): the torque the controller counts is the plant's, sample by sample
        rows, log = ctl.CONTROLLER_STATE.rows, parts.controller_log.FindLog(root).data()
        gain, target, bound = (rows(log, f"hip_motor_{n}") for n in ("gain_nms", "target_radps", "bound_nm"))
        feedforward = rows(log, "torques_nm")[:, [0, 3]]
        rate = parts.state_log.FindLog(root).data()[[9 + 3, 9 + 6]].T
        counted = np.clip(-gain[:-1] * (rate[1:] - target[:-1]) + feedforward[:-1], -bound[:-1], bound[:-1])
        np.testing.assert_allclose(counted, held[[0, 3], 1:].T, rtol=1e-12, atol=1e-12)
    if solve == "controller":
        # the plant's output is sampled: what it applied over its last step, the torques the update before held
        np.testing.assert_array_equal(applied, held[:, -2])
    T = run_episode(config, record_trajectory=True, cache=None).trajectory
    dt = float(np.diff(T["time"])[0])
    offline = positive_work(T["actuation"][:-1], np.diff(T["positions"][:, 3:], axis=0) / dt, dt)
    np.testing.assert_allclose(T["positive_work"][-1], offline, rtol=1e-9, atol=1e-9)
    assert np.max(np.abs(T["actuation"][:, [0, 3]])) > 5.0  # the motor did work


@pytest.mark.slow
def test_the_paper_gait_walks_table_iii_with_the_paper_hip():
    """The shipped `paper` gait (Table III, the paper's initiation, the ODE motor on the swing hip) walks: 30 m at
    its step and at half of it, and through the paper's +-20 N pushes at 0.4 s over 10 m."""
    from drake_biped.params import Push
    from drake_biped.resources import load_gait

    paper = load_gait("paper")
    for h in (paper.sim.time_step_s, 0.5 * paper.sim.time_step_s):
        r = run_episode(paper.override({"sim.time_step_s": h, "sim.distance_m": 30.0, "sim.max_time_s": 120.0}))
        assert not r.fell and r.distance_m >= 30.0 and 0.8 < r.step_period_s < 1.0
    for force in (20.0, -20.0):
        r = run_episode(paper.replace(push=Push(force, 0.4, 0.1)))
        assert not r.fell and r.distance_m >= 10.0


def test_the_fields_a_reading_leaves_unread_change_no_walk_and_a_grid_refuses_them():
    """Under the hip motor the servo's gains and the swing reference's terms are unread (GaitParams.unread):
    changed, the walk is the same to the last digit and `as_walked` says so; the motor's limit is read and
    changes the walk. So for the entrained reading's touchdown threshold, read where the phase is reset. A grid
    axis over an unread gain is refused before any work."""
    from drake_biped.experiments.grid import Axis, check_axes
    from drake_biped.params import ParameterError
    from drake_biped.resources import load_gait

    paper = load_gait("paper").override({"gait.motor_solve": "plant", "sim.distance_m": 10.0, "sim.max_time_s": 2.0})
    assert set(paper.gait.unread()) >= {"hip_kp", "placement_gain", "motor_time_constant_s"}
    assert "motor_limit_nm" not in paper.gait.unread() and "motor_gain_nms" not in paper.gait.unread()
    assert {"motor_limit_nm", "motor_solve", "motor_gain_nms"} <= set(FAST.gait.unread())
    controller_solved = paper.override({"gait.motor_solve": "controller"})
    assert "motor_gain_nms" in controller_solved.gait.unread()
    assert "motor_time_constant_s" not in controller_solved.gait.unread()

    def walked(config):
        r = run_episode(config, cache=None)
        return r.distance_m, r.positive_work_j, r.touchdowns["touchdown_time_s"].tolist()

    base = walked(paper)
    unread = paper.override({"gait.hip_kp": 10.0, "gait.placement_gain": 2.0, "gait.swing_offset_rad": 0.3,
                             "gait.swing_reading": "anchored", "gait.motor_time_constant_s": 0.01},
                            sampled=True)  # a user is told they are unread
    assert unread.as_walked() == paper.as_walked() and walked(unread) == base
    for read in (paper.override({"gait.motor_limit_nm": 0.5 * paper.gait.motor_limit_nm}),
                 paper.override({"gait.motor_gain_nms": 0.1 * paper.gait.motor_gain_nms})):
        assert read.as_walked() != paper.as_walked() and walked(read) != base
    # the entrained reading leaves the touchdown's phase threshold unread: the CPG runs free of the steps
    entrained = load_gait("paper_entrained").override({"sim.distance_m": 10.0, "sim.max_time_s": 2.0})
    assert "touchdown_min_phase" in entrained.gait.unread()
    moved = entrained.override({"gait.touchdown_min_phase": 3.0}, sampled=True)
    assert moved.as_walked() == entrained.as_walked() and walked(moved) == walked(entrained)
    reset = entrained.override({"gait.phase_reading": "reset"})  # where the phase is reset, it is read
    assert "touchdown_min_phase" not in reset.gait.unread()
    assert walked(reset.override({"gait.touchdown_min_phase": 3.0})) != walked(reset)
    with pytest.raises(ParameterError, match="axis gait.placement_gain .* changes nothing"):
        check_axes(paper, [Axis("gait.placement_gain", (0.1, 0.5))])


@pytest.mark.slow
def test_a_controller_motor_of_fixed_time_constant_chatters_less_and_one_of_an_update_is_the_per_update_motor():
    """GaitParams.motor_time_constant_s T (motor_solve "controller"): each update closes dt / T of the rate's miss.
    T at or under the update period is the per-update motor to the last digit; a 2 ms motor's swing-hip torque
    changes sign far less often on the paper's walker (at 10 m: 93 against 179 times a second, RESULTS "The
    motor's bandwidth")."""
    from drake_biped.analysis.series import swing_hip_sign_changes_per_s
    from drake_biped.resources import load_gait

    def changes(trajectory) -> float:
        return swing_hip_sign_changes_per_s(trajectory, after_s=2.0)

    base = load_gait("paper").override({"gait.motor_solve": "controller", "sim.distance_m": 4.0})
    shipped = run_episode(base, record_trajectory=True)
    one_update = run_episode(base.override({"gait.motor_time_constant_s": base.sim.time_step_s}))
    assert one_update.cost_of_transport == shipped.cost_of_transport
    slower = run_episode(base.override({"gait.motor_time_constant_s": 0.002}), record_trajectory=True)
    assert not shipped.fell and not slower.fell
    assert changes(shipped.trajectory) > 1.5 * changes(slower.trajectory), (changes(shipped.trajectory),
                                                                            changes(slower.trajectory))


def test_a_record_written_before_motor_solve_is_read_as_the_controllers_motor_it_walked():
    """A record naming hip_drive "motor" without motor_solve (every record before the plant's motor) is read as
    motor_solve "controller"; one that names it as written; a parameter file takes the default ("plant"); the plant's
    motor refuses what it cannot hold (the inter-leg angle, a controller clock of its own), naming the field."""
    from drake_biped.legacy import config_of_record
    from drake_biped.params import ParameterError, config_of_params
    from drake_biped.resources import load_gait

    plant = load_gait("paper").override({"gait.motor_solve": "plant"}).to_dict()
    old = {**plant, "gait": {k: v for k, v in plant["gait"].items() if k not in ("motor_solve", "motor_gain_nms")}}
    assert config_of_record(old, "record").gait.motor_solve == "controller"
    assert config_of_record(plant, "record").gait.motor_solve == "plant"
    # a parameter file is not a record: its missing fields are the defaults' (the paper walker's)
    paper = {**plant, "sim": {k: v for k, v in plant["sim"].items() if k != "controller_clock"}}
    for solve in ("plant", "controller"):
        written = {**paper, "gait": {**old["gait"], "motor_solve": solve}}
        assert config_of_params(written, "params").gait.motor_solve == solve
    assert config_of_params({"gait": {"torso_kd": 12.0}}, "x").gait.motor_solve == EpisodeConfig().gait.motor_solve
    with pytest.raises(ParameterError, match="hip_joint = 'inter_leg' needs motor_solve 'controller'"):
        _motor("inter_leg", "plant")
    with pytest.raises(ParameterError, match=r"sim.control_period_s = 0.002 with the plant's hip motor"):
        _motor("swing", "plant", **{"sim.control_period_s": 2e-3})
    _motor("swing", "controller", **{"sim.control_period_s": 2e-3})  # the controller's motor has a clock


@pytest.mark.slow
def test_the_plant_solved_motor_converges_where_the_controllers_did_not():
    """The cause of the paper walker's dependence on its step (RESULTS "The hip motor solved in the plant's step"):
    the motor computed by the controller from a model that misses the stops and the contact's compliance. On the
    10 m walk from the paper's initiation, its C_mt at 0.5 ms is 1 % above its 0.125 ms walk, and its swing hip's
    torque changes sign over 150 times a second; solved in the plant's step, within 0.5 % and under 50 times."""
    from drake_biped.analysis.series import swing_hip_sign_changes_per_s
    from drake_biped.resources import load_gait

    def walk(solve, h):
        r = run_episode(load_gait("paper").override({"gait.motor_solve": solve, "sim.time_step_s": h}),
                        record_trajectory=h == 5e-4)
        assert not r.fell
        return r

    gap = {}
    for solve in ("controller", "plant"):
        coarse, fine = walk(solve, 5e-4), walk(solve, 1.25e-4)
        gap[solve] = (coarse.cost_of_transport / fine.cost_of_transport - 1.0,
                      swing_hip_sign_changes_per_s(coarse.trajectory))
    assert abs(gap["controller"][0]) > 0.01 and gap["controller"][1] > 150, gap
    assert abs(gap["plant"][0]) < 0.005 and gap["plant"][1] < 50, gap
