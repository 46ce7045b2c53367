"""The long-run cost of transport (analysis.long_run) on walks whose answer is known, and the divergence
rule by rate on the compiled control update."""

import math

import numpy as np
import pytest
from walkers import fast_config

from drake_biped.analysis.long_run import long_run_cost, t975
from drake_biped.hip_motor import DYN_SIZE


def _walk(steps, period=0.5, length=0.4, work=20.0, start_x=0.0):
    t = np.arange(steps + 1) * period
    x = start_x + np.arange(steps + 1) * length
    w = np.arange(steps + 1) * work
    return t, x, w


def test_a_regular_walk_has_its_steps_cost_and_no_spread():
    t, x, w = _walk(120)
    r = long_run_cost(t, x, w, mass_kg=10.0, g=10.0, transient_m=10.0, batches=10)
    assert r["cost_of_transport"] == pytest.approx(20.0 / (10.0 * 10.0 * 0.4))
    assert r["half_width"] == pytest.approx(0.0, abs=1e-12)
    assert r["dropped_steps"] == 25  # touchdowns less than 10 m beyond the first: 0 .. 9.6 m
    assert r["steps"] == 120 - 25 and r["distance_m"] == pytest.approx(0.4 * 95)
    assert r["step_period_mean_s"] == pytest.approx(0.5) and r["step_period_std_s"] == pytest.approx(0.0)


def test_the_transient_does_not_count_and_the_interval_covers_the_truth():
    """A costly initiation (ten times the work over the first 10 m) is dropped; steps of random work around a
    known mean give an interval that holds that mean in about 95 % of walks."""
    rng = np.random.default_rng(1)
    truth = 20.0 / (10.0 * 10.0 * 0.4)
    covered = 0
    for _ in range(200):
        work = np.where(np.arange(300) < 25, 200.0, 20.0 + rng.normal(0.0, 4.0, 300))
        t = np.arange(301) * 0.5
        x = np.arange(301) * 0.4
        w = np.concatenate([[0.0], np.cumsum(work)])
        r = long_run_cost(t, x, w, 10.0, 10.0, transient_m=10.0, batches=10)
        lo, hi = r["interval_95"]
        covered += lo <= truth <= hi
        assert abs(r["cost_of_transport"] - truth) < 0.05 * truth
    assert 0.88 <= covered / 200 <= 0.99


def test_a_walk_too_short_for_its_batches_has_no_long_run_cost():
    t, x, w = _walk(40)
    r = long_run_cost(t, x, w, 10.0, 10.0, transient_m=10.0, batches=10)
    assert r["cost_of_transport"] is None and r["steps"] == 15
    with pytest.raises(ValueError, match="batches"):
        long_run_cost(t, x, w, 10.0, 10.0, batches=1)
    assert t975(9) == pytest.approx(2.262) and t975(100) == 1.96


def _kernel_inputs():
    from drake_biped import control_kernel as ctl
    from drake_biped.controller import law_vector
    from drake_biped.diagram import initial_state
    from drake_biped.kinematics import TABLE_I_BODY

    config = fast_config()
    q, v, _, liftoff = initial_state(config)
    s = np.zeros(ctl.N_STATE)
    s[ctl.STANCE_RIGHT] = s[ctl.CONTACT_RIGHT] = 1.0
    s[ctl.LIFTOFF_ANGLE] = liftoff
    s[ctl.TARGET_X] = math.inf
    s[ctl.PREV_CLEARANCE] = math.inf
    s[ctl.PREV_RATES: ctl.PREV_RATES + 2] = math.nan
    s[ctl.RECENT_REVERSALS: ctl.RECENT_REVERSALS + ctl.DIVERGED_REVERSALS] = -math.inf
    s[ctl.Q_PREV: ctl.Q_PREV + 6] = q[3:]
    return ctl, law_vector(config), TABLE_I_BODY, np.concatenate([q, v]), s


@pytest.mark.parametrize("every, diverges", [(1, True), (4, True), (5, False), (8, False)])
def test_divergence_is_a_rate_of_reversals_not_a_total(every, diverges):
    """The control update calls the loop diverged when DIVERGED_REVERSALS torque reversals fall within
    DIVERGENCE_SPAN_PERIODS control periods: reversals every 4 periods (5 in 17) do, every 5 (5 in 21) do
    not, however many there are in all."""
    ctl, law, body, x, s = _kernel_inputs()
    assert (ctl.DIVERGED_REVERSALS, ctl.DIVERGENCE_SPAN_PERIODS) == (5, 20)
    tau = np.zeros(6)
    row = np.zeros(1 + len(ctl.TOUCHDOWN_FIELDS))
    fell_at = None
    for k in range(60):
        if k % every == 0:
            tau[:] = 1e3  # the held torques far from what the update computes: a reversal
        code = ctl.control_step(law, body, k * 1e-3, x, s, tau, row, np.zeros(DYN_SIZE),
                                np.zeros(ctl.MOTOR_COMMAND_SIZE))
        if code & ctl.FELL:
            fell_at = k
            break
    if diverges:
        assert s[ctl.FALL] == ctl.DIVERGED_CODE and fell_at == 4 * every
    else:
        assert fell_at is None and s[ctl.REVERSALS] == len(range(0, 60, every))


@pytest.mark.slow
def test_the_default_gait_converges_over_long_walks_and_a_long_control_period_still_diverges():
    """The contact's continuous limit (issue: physics judged on long walks): the default gait without a window,
    110 m at 1, 0.5 and 0.25 ms (the control period kept at 1 ms), walks the whole way, none called diverged,
    and the long-run C_mt of the three agree within 1 %; at a 10 ms step (and control period) the loop is
    caught diverging."""
    from drake_biped.episode import run_episode

    costs = []
    for h in (1e-3, 5e-4, 2.5e-4):
        r = run_episode(fast_config().override({"sim.time_step_s": h, "sim.distance_m": 110.0,
                                                  "sim.max_time_s": 600.0}))
        assert r.termination == "distance"
        costs.append(r.long_run()["cost_of_transport"])
    assert max(costs) / min(costs) - 1.0 < 0.01
    coarse = run_episode(fast_config().override({"sim.time_step_s": 1e-2, "sim.control_period_s": 1e-2}))
    assert coarse.termination == "diverged"


def test_walk_prints_the_long_run_cost_only_for_a_walk_long_enough_for_it():
    """`drake-biped walk` adds the long-run line for a walk of at least 110 m that did not fall, from the walk's
    own long_run(); a shorter walk or a fall gets none."""
    from types import SimpleNamespace

    from drake_biped.experiments.walk import long_run_lines

    lr = {"cost_of_transport": 0.3047, "half_width": 0.0051, "distance_m": 100.2, "steps": 220,
          "step_period_mean_s": 0.5243, "step_period_std_s": 0.0375}

    def walk(distance, fell=False):
        return SimpleNamespace(fell=fell, distance_m=distance, long_run=lambda: lr)

    (line,) = long_run_lines(walk(110.0))
    assert "long-run C_mt 0.3047 ± 0.0051" in line and "100.2 m after the first 10 m" in line
    assert "220 steps of 0.524 ± 0.037 s" in line
    assert long_run_lines(walk(109.9)) == [] and long_run_lines(walk(110.0, fell=True)) == []
    lr["cost_of_transport"] = None  # too few steps for batch means
    assert long_run_lines(walk(110.0)) == []
