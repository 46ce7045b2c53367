"""The lean episode path: what the controller records and when it stops, checked against the logged walk."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from walkers import fast_config

from drake_biped import controller as ctl
from drake_biped.control_kernel import MAX_TOUCHDOWNS, touchdown_capacity
from drake_biped.control_law import L_T1
from drake_biped.diagram import build_diagram, build_replay_diagram, initial_state
from drake_biped.episode import DiagramCache, run_episode
from drake_biped.kinematics import center_of_mass
from drake_biped.params import (
    EpisodeConfig,
    Ground,
    InitialConditions,
    Push,
    SimulationParams,
    TorqueFreeWindow,
)


def _config():
    return fast_config(sim=SimulationParams(distance_m=3.0, max_time_s=15.0))


def test_replaying_the_logged_torques_retraces_the_closed_loop(short_walk):
    """The plant alone, fed the closed loop's torques through a zero-order hold, walks the same walk:
    the benchmark's plant-alone reference sees exactly the closed loop's contacts."""
    T = short_walk.trajectory
    config = _config()
    diagram, plant = build_replay_diagram(config, T["time"], T["actuation"])
    simulator = Simulator(diagram)
    context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    q0, v0, _, _ = initial_state(config)
    plant.SetPositions(context, q0)
    plant.SetVelocities(context, v0)
    for i in (len(T["time"]) // 2, len(T["time"]) - 1):
        simulator.AdvanceTo(T["time"][i])
        np.testing.assert_allclose(plant.GetPositions(context), T["positions"][i], rtol=0, atol=1e-9)


def test_the_benchmarks_plant_timer_counts_every_plant_step_and_changes_nothing():
    """benchmarks/bench.py's plant share within the closed loop (its measure where a replay cannot retrace,
    the plant's hip motors): it times each of the episode's plant steps, the walk is the untimed walk to
    the last digit, and the plant's class is as it was afterwards."""
    import importlib.util
    from pathlib import Path

    from pydrake.multibody.plant import MultibodyPlant

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench.py"
    spec = importlib.util.spec_from_file_location("bench_under_test", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    config = fast_config(sim=SimulationParams(distance_m=0.5, max_time_s=5.0))
    plain = run_episode(config)
    in_plant, loop, steps, cost = bench.plant_share_in_loop(config)
    assert "ExecuteForcedEvents" not in MultibodyPlant.__dict__
    assert steps == round(plain.duration_s / config.sim.time_step_s)
    assert cost == plain.cost_of_transport
    assert 0.0 < in_plant < loop


def test_replay_rejects_a_malformed_log():
    with pytest.raises(ValueError, match="torques"):
        build_replay_diagram(_config(), np.arange(3) * 1e-3, np.zeros((3, 5)))


def test_touchdown_records_are_the_logged_section_states(short_walk):
    """Each recorded touchdown is placed at the moment the swing foot's clearance crossed the touchdown
    height, within the control period before the update that confirmed it: the inter-leg angle (leading
    minus trailing thigh) interpolated there between the two logged states, its rate extrapolated there
    from the two logged states before them (before the impact), the centre of mass of the update."""
    T = short_walk.trajectory
    dt = _config().sim.update_period_s
    assert len(short_walk.steps) >= 3
    backs = []
    for step in short_walk.steps:
        i = int(np.flatnonzero(T["time"] >= step.touchdown_time_s - 1e-9)[0])
        back = T["time"][i] - step.touchdown_time_s
        assert 0.0 <= back < dt
        backs.append(back)
        st, sw = (6, 3) if step.stance_leg == "right" else (3, 6)
        angle = T["positions"][:, st] - T["positions"][:, sw]
        rate = T["velocities"][:, st] - T["velocities"][:, sw]
        f = back / dt
        if step.index > 1:  # the first touchdown ends the initiation, whose stance began on the ground
            assert step.hip_rate_radps == pytest.approx(rate[i - 1] + (rate[i - 1] - rate[i - 2]) * (1 - f),
                                                        abs=1e-9)
            assert abs(step.hip_rate_radps - rate[i - 1]) < 0.05  # a step before, not across, the impact
        assert step.hip_angle_rad == pytest.approx((1 - f) * angle[i] + f * angle[i - 1], abs=1e-12)
        # between the two logged states it was interpolated from (the leg rates are smooth over 1 ms)
        lo, hi = sorted((angle[i - 1], angle[i]))
        assert lo - 1e-6 <= step.hip_angle_rad <= hi + 1e-6
        assert step.com_x_m == pytest.approx(center_of_mass(T["positions"][i])[0], abs=1e-12)
        assert T["stance_right"][i] == (1.0 if step.stance_leg == "right" else 0.0)
        assert T["step_start"][i] == step.touchdown_time_s  # the step clock counts from the crossing
    assert max(backs) > 0.0  # the crossing is placed inside the control period, not on its grid


def _swap_residuals(walk):
    """Per touchdown after the first: the hip and knee torques held over the control period that contains
    T_n, less the blend of the period before it (the old roles) and the period after it (the new roles) by
    the part of the period before T_n; and the jump between those two periods."""
    T = walk.trajectory
    dt = _config().sim.update_period_s
    a = T["actuation"][:, [0, 1, 3, 4]]
    rows = []
    for step in walk.steps[1:]:
        i = int(np.flatnonzero(T["time"] >= step.touchdown_time_s - 1e-9)[0])
        f = (step.touchdown_time_s - T["time"][i - 1]) / dt
        rows.append((np.abs(a[i - 1] - (f * a[i - 2] + (1.0 - f) * a[i])).max(), np.abs(a[i] - a[i - 2]).max()))
    return np.array(rows)


def test_the_roles_swap_at_the_crossing_inside_the_control_period(short_walk):
    """The roles' torques swap at T_n itself: the period that contains the crossing holds the old roles'
    torques for the part of it before T_n and the new roles' after (within how much the new swing hip's
    servo moves in one period), where swapping at the next update would hold the old roles' throughout."""
    predicted = _swap_residuals(short_walk)
    assert len(predicted) >= 2 and predicted[:, 1].min() > 20.0  # the swap moves the hips by > 20 N*m
    assert (predicted[:, 0] / predicted[:, 1]).max() < 0.2
    late = run_episode(_config().override({"gait.swap_timing": "update"}), record_trajectory=True)
    late = _swap_residuals(late)
    assert (late[:, 0] / late[:, 1]).max() > 0.5


def test_episode_ends_at_the_update_that_walks_the_distance(short_walk):
    """The controller stops the run at the first control update with the centre of mass past the
    target: the distance overshoots by at most one control period of walking."""
    dt = _config().sim.update_period_s
    assert 3.0 <= short_walk.distance_m < 3.0 + 2.0 * dt  # well under 2 m/s
    T = short_walk.trajectory
    com = np.array([center_of_mass(q)[0] for q in T["positions"][-3:]]) - center_of_mass(T["positions"][0])[0]
    assert com[-2] < 3.0  # one update earlier it had not arrived


def test_loggers_do_not_change_the_walk(short_walk):
    """The lean diagram (no loggers) and the recording one give the same episode to the last digit."""
    lean = run_episode(_config())
    assert lean.trajectory is None
    assert lean.duration_s == short_walk.duration_s
    assert lean.cost_of_transport == short_walk.cost_of_transport
    assert [s.touchdown_time_s for s in lean.steps] == [s.touchdown_time_s for s in short_walk.steps]


def test_loggers_are_built_only_when_recording():
    def names(record):
        return {s.get_name() for s in build_diagram(_config(), record=record).diagram.GetSystems()}

    logs = {"state_log", "controller_log", "actuation_log"}
    assert not logs & names(False)
    assert logs <= names(True)


def test_touchdown_capacity_covers_the_longest_episode():
    config = _config()
    need = config.sim.max_time_s / config.gait.touchdown_min_step_s
    assert touchdown_capacity(config) >= need
    assert touchdown_capacity(config) <= MAX_TOUCHDOWNS


def test_a_reused_diagram_gives_the_numbers_of_a_fresh_one():
    """Episodes share a built diagram when their structure matches; whatever ran before, an episode's
    numbers are those of a diagram built for it alone."""
    a = fast_config(sim=SimulationParams(distance_m=1.0, max_time_s=15.0))
    b = a.replace(window=TorqueFreeWindow(0.2, 0.5), initial=InitialConditions(hip_angle_rad=0.3, speed_mps=0.4))
    cache = DiagramCache()
    first = run_episode(a, cache=cache)
    other = run_episode(b, cache=cache)
    again = run_episode(a, cache=cache)
    fresh = run_episode(a, cache=None)
    assert len(cache) == 1
    assert other.cost_of_transport != first.cost_of_transport
    for r in (again, fresh):
        assert r.to_dict() | {"wall_time_s": 0, "real_time_factor": 0} == first.to_dict() | {
            "wall_time_s": 0, "real_time_factor": 0}


def test_cache_builds_a_new_diagram_for_a_new_structure():
    cache = DiagramCache(size=2)
    base = fast_config(sim=SimulationParams(distance_m=0.2, max_time_s=5.0))
    run_episode(base, cache=cache)
    run_episode(base.replace(sim=SimulationParams(distance_m=0.2, max_time_s=5.0, time_step_s=5e-4,
                                                  control_period_s=5e-4)), cache=cache)
    run_episode(base.replace(ground=Ground(slope_rad=0.01)), cache=cache)
    assert len(cache) == 2  # the least recently used one was dropped


def test_controller_refuses_a_config_of_another_structure():
    config = _config()
    c = ctl.CpgWalkingController(config)
    context = c.CreateDefaultContext()
    c.set_episode(context, config.replace(window=TorqueFreeWindow(0.1, 0.3)))  # numbers only: fine
    assert c.law(context)[L_T1] == 0.1 and c.law(c.CreateDefaultContext())[L_T1] == config.window.start_s
    with pytest.raises(ValueError, match="another ground"):
        c.set_episode(context, config.replace(ground=Ground(slope_rad=0.02)))


def test_the_compiled_update_gives_the_numbers_of_the_same_code_run_as_python():
    """The control law's kernels compiled by numba (IEEE arithmetic, no fast-math) and the same kernels run
    by the Python interpreter (NUMBA_DISABLE_JIT=1) walk the same walk, to the last digit."""
    import json
    import os
    import subprocess
    import sys

    config = fast_config(sim=SimulationParams(distance_m=1.3, max_time_s=4.0), window=TorqueFreeWindow(0.1, 0.3))
    code = ("import json, sys; from drake_biped.episode import run_episode; "
            "from drake_biped.params import EpisodeConfig; "
            "r = run_episode(EpisodeConfig.from_dict(json.loads(sys.argv[1]))); "
            "print(json.dumps([r.positive_work_j['total'], r.distance_m, [s.hip_rate_radps for s in r.steps]]))")
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", code, json.dumps(config.to_dict())], env=env, capture_output=True,
                         text=True, check=True)
    interpreted = json.loads(out.stdout.strip().splitlines()[-1])
    compiled = run_episode(config)
    assert len(compiled.steps) >= 2
    assert interpreted == [compiled.positive_work_j["total"], compiled.distance_m,
                           [s.hip_rate_radps for s in compiled.steps]]


def _both_paths(monkeypatch, config):
    """(Simulator walk, directly stepped walk) pairs of `config`, without and with a kick of the swing hip, each
    pair asserted to be the same walk to the last bit: work, distance, duration, touchdowns, why it ended."""
    from drake_biped import episode

    kick = episode.Kick(0.6017, 0.01, 0.1)

    def walks():
        return [run_episode(config, cache=None), run_episode(config, cache=None, kick=kick)]

    monkeypatch.setattr(episode, "_DIRECT_STEPS", False)
    simulator = walks()
    monkeypatch.setattr(episode, "_DIRECT_STEPS", True)
    pairs = list(zip(simulator, walks()))
    for a, b in pairs:
        assert (a.termination, a.fall_reason) == (b.termination, b.fall_reason)
        assert a.positive_work_j == b.positive_work_j and a.signed_work_j == b.signed_work_j
        assert (a.distance_m, a.duration_s) == (b.distance_m, b.duration_s)
        assert [vars(s) for s in a.steps] == [vars(s) for s in b.steps]
    return pairs


@pytest.mark.parametrize("change, ending", [
    ({"window": TorqueFreeWindow(0.2, 0.5)}, "distance"),
    ({"sim": SimulationParams(distance_m=1.5, max_time_s=15.0, time_step_s=5e-4)}, "distance"),  # 2 steps a period
    ({"push": Push(-150.0)}, "fall"),
    ({"sim": SimulationParams(distance_m=1.5, max_time_s=0.8345)}, "time limit"),
])
def test_stepping_the_plant_directly_gives_the_simulators_numbers(monkeypatch, change, ending):
    """The episode path that calls the plant's step itself (no Simulator, no Python callback) gives the
    Simulator path's walk to the last bit: work, distance, duration, touchdowns, and why it ended; also with
    a kick of the swing hip between two steps."""
    config = fast_config(sim=SimulationParams(distance_m=1.5, max_time_s=15.0)).replace(**change)
    simulator = [a for a, _ in _both_paths(monkeypatch, config)]
    assert simulator[0].termination == ending


def _paper(distance: float = 1.5, **changes) -> EpisodeConfig:
    from drake_biped.resources import load_gait

    return load_gait("paper").override({"gait.motor_solve": "plant", "sim.distance_m": distance, "sim.max_time_s": 15.0,
                                        **changes})


def test_the_plant_solved_motor_walks_the_simulators_numbers_stepped_directly(monkeypatch):
    """The paper's walker, its hip motor solved in the plant's step (its actuators' gains and bounds set between
    steps: controller.PlantMotors), stepped directly and by the Simulator: the same walk to the last bit, with a
    window (the bound drops to zero and back), across touchdowns (the roles' actuators swap) and with a kick."""
    config = _paper().replace(window=TorqueFreeWindow(0.1, 0.2))
    assert config.gait.motor_solve == "plant"
    for a, _ in _both_paths(monkeypatch, config):
        assert a.termination == "distance" and len(a.steps) >= 2


def test_a_reused_plant_solved_motor_gives_the_numbers_of_a_fresh_diagram():
    """The plant's hip actuators keep the gains and bounds the last episode left them (Drake holds them in the
    model, not in a Context); each episode sets its own before the first step, so an episode on a reused diagram
    walks as on a fresh one, whatever the one before did (here: ended inside a window, the bound at zero)."""
    a = _paper(1.0)
    b = a.replace(window=TorqueFreeWindow(0.05, 5.0, first_step=0)).override({"sim.distance_m": 0.05})
    cache = DiagramCache()
    first = run_episode(a, cache=cache)
    run_episode(b, cache=cache)
    again = run_episode(a, cache=cache)
    fresh = run_episode(a, cache=None)
    assert len(cache) == 1
    for r in (again, fresh):
        assert r.to_dict() | {"wall_time_s": 0, "real_time_factor": 0} == first.to_dict() | {
            "wall_time_s": 0, "real_time_factor": 0}
