"""Floquet multipliers: the Newton / central-difference / eigen code on maps whose answer is known (a
nonlinear map with chosen eigenvalues, Drake's passive rimless wheel with its analytic multiplier
cos²(2α)), and the biped's step map through Drake (restarts reproduce the walk exactly, the held slots do
not matter, the command writes what it promises)."""

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from retired_gaits import STEADY
from walkers import fast_config

from drake_biped.analysis import floquet as fq

EIGENVALUES = np.array([0.6, -0.3, 0.5 + 0.4j, 0.5 - 0.4j])


def _chosen_map():
    """x -> x* + A (x - x*) + a cubic term: A has EIGENVALUES, the cubic spoils large perturbations."""
    rng = np.random.default_rng(0)
    basis = rng.normal(size=(4, 4))
    block = np.diag([0.6, -0.3, 0.5, 0.5])
    block[2, 3], block[3, 2] = 0.4, -0.4
    a = basis @ block @ np.linalg.inv(basis)
    x_star = np.array([0.3, -1.2, 2.0, 0.7])

    def step(x):
        d = x - x_star
        return x_star + a @ d + 0.5 * d**3

    return step, a, x_star


def test_newton_finds_the_fixed_point_and_the_jacobian_its_eigenvalues():
    step, a, x_star = _chosen_map()
    evaluate = fq.serial(step)
    fixed = fq.newton_fixed_point(evaluate, x_star + 0.05, 1e-6, tolerance=1e-12)
    assert fixed.converged and fixed.residual < 1e-12
    assert np.allclose(fixed.state, x_star, atol=1e-11)
    assert fixed.residuals[0] > 1e-3 and fixed.iterations <= 5  # Newton: a few iterations, not a contraction
    jac = fq.difference_jacobian(evaluate, fixed.state, 1e-5)
    assert np.allclose(jac, a, atol=1e-8)
    mult = fq.multipliers(jac)
    expected = sorted(EIGENVALUES, key=lambda v: (-abs(v), -v.real))
    assert np.allclose(sorted(mult.values, key=lambda v: (-abs(v), -v.real)), expected, atol=1e-8)
    assert mult.spectral_radius == pytest.approx(abs(0.5 + 0.4j), abs=1e-8)
    # eigenvectors: J v = λ v
    for k in range(4):
        assert np.allclose(jac @ mult.vectors[:, k], mult.values[k] * mult.vectors[:, k], atol=1e-7)


def test_the_sweep_finds_the_plateau_between_rounding_and_the_cubic():
    step, a, x_star = _chosen_map()
    sweep = fq.epsilon_sweep(fq.serial(step), x_star, [10.0**e for e in range(-14, 1)])
    chosen = fq.converged_epsilon(sweep, 0.05)
    truth = abs(0.5 + 0.4j)
    assert chosen["decades"] >= 2
    assert 1e-12 <= chosen["epsilon"] <= 1e-1
    assert sweep[chosen["index"]]["spectral_radius"] == pytest.approx(truth, rel=1e-4)
    assert abs(sweep[-1]["spectral_radius"] - truth) > 0.05 * truth  # ε = 1: the cubic shows


def test_converged_epsilon_takes_the_longest_run_and_reports_none_without_one():
    rows = [{"epsilon": e, "spectral_radius": r} for e, r in
            [(1e-8, 3.0), (1e-7, 1.0), (1e-6, 1.01), (1e-5, 1.02), (1e-4, 0.5), (1e-3, 0.51)]]
    chosen = fq.converged_epsilon(rows, 0.05)
    assert chosen["plateau"] == [1e-7, 1e-5] and chosen["epsilon"] == 1e-6 and chosen["decades"] == 2.0
    none = fq.converged_epsilon([{"epsilon": e, "spectral_radius": r} for e, r in [(1e-6, 1), (1e-5, 2), (1e-4, 4)]])
    assert none["epsilon"] is None


def test_the_orbit_verdict_needs_newton_and_the_sweep_to_have_converged():
    assert fq.orbit_verdict(0.4, 1e-6, 1e-10, 1e-9) == "stable"
    assert fq.orbit_verdict(13.2, 1e-6, 1e-10, 1e-9) == "unstable"
    # a Jacobian with no plateau, or one taken where Newton stopped short of a fixed point, decides nothing
    assert fq.orbit_verdict(104.0, None, 1e-10, 1e-9) == "not established: the Jacobian did not converge"
    assert fq.orbit_verdict(0.4, 1e-6, 5.1e-3, 1e-9) == ("not established: Newton stopped at residual 5.1e-03, "
                                                         "above 1.0e-09 (the tolerance)")
    # a residual at the map's own noise is a fixed point found; one far above it is not
    assert fq.orbit_verdict(10.652, 1e-6, 1.6e-9, 1e-9, noise=4e-10) == "unstable"
    assert fq.orbit_verdict(10.652, 1e-6, 5.1e-3, 1e-9, noise=4e-10) == (
        "not established: Newton stopped at residual 5.1e-03, above 4.0e-09 (10 x the map's evaluation noise 4.0e-10)")
    assert fq.orbit_verdict(0.4, 1e-6, 5e-10, 1e-9, noise=1e-14) == "stable"  # a quiet map: the tolerance rules
    # a record is judged against its own settings' tolerance, a summary against the one it holds
    record = {"spectral_radius": 13.2, "converged_epsilon": 1e-6, "fixed_point_residual": 1e-6}
    assert fq.record_verdict(record).startswith("not established: Newton stopped at residual 1.0e-06")
    assert fq.record_verdict({**record, "settings": {"newton_tolerance": 1e-5}}) == "unstable"
    assert fq.record_verdict({**record, "newton_tolerance": 1e-5}) == "unstable"
    assert fq.record_verdict({**record, "evaluation_noise": 2e-7}) == "unstable"


def test_evaluation_noise_measures_a_maps_own_noise_and_newton_stops_there():
    """A map with chosen eigenvalues plus a deterministic roughness of known size (the noise of a solver's
    tolerance, of events on a time grid): the measured noise is of that size, a smooth map's far below it,
    and Newton, told to stop at the floor, stops within it instead of running out of iterations."""
    step, a, x_star = _chosen_map()
    roughness = 1e-8

    def rough(x):
        return step(x) + roughness * np.sin(1e9 * x)  # varies on the scale of 1e-9: noise to any ε above it

    size = np.linalg.norm(x_star)
    noise = fq.evaluation_noise(fq.serial(rough), x_star, 1e-7)
    assert 0.05 * roughness / size < noise < 2 * np.sqrt(len(x_star)) * roughness / size  # 4 rough components
    assert fq.evaluation_noise(fq.serial(step), x_star, 1e-7) < 1e-3 * roughness / size  # curvature only
    # Newton asked for 1e-12 stalls at the roughness; at its residual's scale the noise explains the stall
    fixed = fq.newton_fixed_point(fq.serial(rough), x_star + 0.05, 1e-5, tolerance=1e-12, max_halvings=8)
    assert not fixed.converged and fixed.residual < 1e-6
    noise = fq.evaluation_noise(fq.serial(rough), fixed.state, fixed.residual)
    floor = fq.newton_floor(1e-12, noise)
    assert floor == fq.NOISE_FACTOR * noise and fixed.residual <= floor
    assert fq.orbit_verdict(0.64, 1e-5, fixed.residual, 1e-12, noise) == "stable"
    # the smooth map gives Newton no excuse: its floor stays the tolerance
    smooth = fq.newton_fixed_point(fq.serial(step), x_star + 0.05, 1e-5, tolerance=1e-12)
    assert fq.newton_floor(1e-12, fq.evaluation_noise(fq.serial(step), smooth.state, 1e-9)) == 1e-12


def test_prediction_of_a_linear_map_is_exact():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(3, 3)) * 0.4
    delta = rng.normal(size=3)
    predicted = fq.predicted_deviations(a, delta, 5)
    d = delta
    for k in range(5):
        d = a @ d
        assert np.allclose(predicted[k], d)


def test_an_interrupted_analysis_resumes_from_its_kept_evaluations_to_the_same_numbers(tmp_path):
    """Each finished task's evaluations are kept as it finishes: a rerun after an interrupt evaluates only the
    points not kept, each once, and finds the same fixed point and Jacobians, to the bit; another map's kept
    evaluations are not read."""
    from drake_biped.common.floquet_runs import kept_batch

    step, _, x_star = _chosen_map()
    evaluated = []

    def runner(stop_after=None):
        def run_chunks(groups):
            for i, group in reversed(list(enumerate(groups))):  # finishing in any order
                if stop_after is not None and len(evaluated) >= stop_after:
                    raise KeyboardInterrupt
                evaluated.extend(group)
                yield i, [step(np.array(p)).tolist() for p in group]
        return run_chunks

    def analysis(evaluate):
        fixed = fq.newton_fixed_point(evaluate, x_star + 0.05, 1e-5, tolerance=1e-12)
        sweep = fq.epsilon_sweep(evaluate, fixed.state, [1e-6, 1e-5, 1e-4])
        return [fixed.state, *(r["jacobian"] for r in sweep)]

    identity = {"config": {"gait": "chosen"}}
    reference = analysis(kept_batch(runner(), 2, identity))
    total, evaluated[:] = len(evaluated), []
    with pytest.raises(KeyboardInterrupt):
        analysis(kept_batch(runner(stop_after=total // 2), 2, identity, tmp_path / "kept"))
    kept = len(evaluated)
    assert 0 < kept < total and len(list((tmp_path / "kept").glob("*.json"))) > 0
    evaluated[:] = []
    resumed = analysis(kept_batch(runner(), 2, identity, tmp_path / "kept"))
    assert len(evaluated) == total - kept
    assert all(np.array_equal(a, b) for a, b in zip(resumed, reference))
    evaluated[:] = []
    analysis(kept_batch(runner(), 2, {"config": {"gait": "another"}}, tmp_path / "kept"))
    assert len(evaluated) == total


def test_a_failed_step_is_reported():
    with pytest.raises(fq.StepFailed, match="failed"):
        fq.difference_jacobian(fq.serial(lambda x: None if x[0] > 0 else x), np.zeros(2), 0.1)


# --- Drake's passive rimless wheel: multiplier cos²(2α) ------------------------------------------------
def _rimless_wheel():
    from pydrake.examples import RimlessWheel, RimlessWheelParams
    from pydrake.systems.analysis import Simulator

    wheel = RimlessWheel()
    simulator = Simulator(wheel)
    params = RimlessWheelParams()
    slope = params.slope()
    dt = 1e-3

    def state(context):
        return context.get_continuous_state_vector().CopyToVector()

    def step(x):
        """(θ, θ̇) -> the state at the next crossing of θ = slope (mid-stance) after an impact."""
        context = simulator.get_mutable_context()
        wheel.SetDefaultContext(context)
        context.SetTime(0.0)
        context.SetAccuracy(1e-12)
        simulator.get_mutable_integrator().set_target_accuracy(1e-12)
        context.get_mutable_continuous_state_vector().SetFromVector(x)
        simulator.Initialize()
        previous, impacted, k = state(context), False, 0
        while k < 5000:
            k += 1
            simulator.AdvanceTo(k * dt)
            now = state(context)
            if now[0] < previous[0] - 0.3:
                impacted = True
            elif impacted and previous[0] < slope <= now[0]:
                # cubic Hermite between the two samples (θ̈ = g/l sin θ gives no better end data)
                (p0, v0), (p1, v1) = previous, now
                s = (slope - p0) / (p1 - p0)
                for _ in range(50):
                    h = (2 * s**3 - 3 * s**2 + 1) * p0 + (s**3 - 2 * s**2 + s) * dt * v0 + \
                        (-2 * s**3 + 3 * s**2) * p1 + (s**3 - s**2) * dt * v1 - slope
                    dh = (6 * s**2 - 6 * s) * p0 + (3 * s**2 - 4 * s + 1) * dt * v0 + \
                        (-6 * s**2 + 6 * s) * p1 + (3 * s**2 - 2 * s) * dt * v1
                    s -= h / dh
                rate = ((6 * s**2 - 6 * s) * p0 + (3 * s**2 - 4 * s + 1) * dt * v0 +
                        (-6 * s**2 + 6 * s) * p1 + (3 * s**2 - 2 * s) * dt * v1) / dt
                return np.array([slope, rate])
            previous = now
        return None

    return step, params


@pytest.mark.slow
def test_the_rimless_wheel_multiplier_is_cos_squared_two_alpha():
    step, params = _rimless_wheel()
    alpha = math.pi / params.number_of_spokes()
    slope, g_over_l = params.slope(), params.gravity() / params.length()
    post = math.sqrt(4 * g_over_l * math.sin(alpha) * math.sin(slope)) / math.tan(2 * alpha)
    mid = math.sqrt(post**2 + 2 * g_over_l * (math.cos(slope - alpha) - math.cos(slope)))
    evaluate = fq.serial(step)
    fixed = fq.newton_fixed_point(evaluate, np.array([slope, 1.2 * mid]), 1e-5, tolerance=1e-9)
    assert fixed.converged
    assert fixed.state[1] == pytest.approx(mid, rel=1e-5)
    jac = fq.difference_jacobian(evaluate, fixed.state, 1e-5)
    mult = fq.multipliers(jac, section_normal=np.array([1.0, 0.0]))
    assert mult.values[0].real == pytest.approx(math.cos(2 * alpha) ** 2, abs=1e-4)
    assert mult.trivial == [None, "section"] and abs(mult.values[1]) < 1e-6


# --- the biped's step map through Drake ----------------------------------------------------------------
@pytest.fixture(scope="module")
def biped_map():
    from drake_biped.step_map import SectionMap

    section_map = SectionMap(fast_config())
    z0, template = section_map.start(6)
    return section_map, z0, template


@pytest.mark.slow
def test_the_step_map_is_deterministic_and_packs_losslessly(biped_map):
    section_map, z0, template = biped_map
    assert np.array_equal(section_map.pack(section_map.unpack(z0, template)), z0)
    assert np.allclose(section_map.unpack(z0, template).plant, template.plant, atol=1e-12)
    a, b = section_map.step(z0), section_map.step(z0)
    assert np.array_equal(a, b)
    # on the section the hip is over the stance ankle: the stance thigh is vertical (knee at its stop)
    assert abs(z0[section_map.names.index("stance_thigh_rad")]) < 1e-3


@pytest.mark.slow
def test_a_restart_from_an_update_continues_the_walk_exactly(biped_map):
    """The map's restart (defaults, then the plant, torques and controller state set) loses nothing: from a
    snapshot taken at an update, with its clocks moved to time 0, the walk to the next section is the
    walk that continued, to the bit."""
    from drake_biped import control_kernel as ctl
    from drake_biped.step_map import Snapshot

    section_map, z0, template = biped_map
    section_map.step(z0)  # leaves the simulator just past the next section
    k = int(round(section_map._simulator.get_context().get_time() / section_map._dt)) + 1
    snap = section_map._advance(k)
    target = int(snap.controller[ctl.STEP_COUNT]) + 1
    continued = section_map._to_section(target, k, 3.0)
    c = snap.controller.copy()
    c[ctl.STEP_START] -= snap.time_s
    c[ctl.STATE_TIME] -= snap.time_s
    section_map._restore(Snapshot(0.0, snap.plant, snap.torques, c))
    section_map._simulator.Initialize()
    restarted = section_map._to_section(target, 0, 3.0)
    assert np.array_equal(restarted.plant, continued.plant)
    assert restarted.time_s == pytest.approx(continued.time_s - snap.time_s, abs=1e-12)


@pytest.fixture(scope="module")
def plant_motor_map():
    """The paper's walker under the plant's hip motor, whose gains and bounds live in the plant's model."""
    from drake_biped.resources import load_gait
    from drake_biped.step_map import SectionMap

    section_map = SectionMap(load_gait("paper").override({"gait.motor_solve": "plant"}))
    z0, template = section_map.start(6)
    return section_map, z0, template


@pytest.mark.slow
def test_under_the_plant_motor_a_restart_continues_the_walk_exactly_and_no_evaluation_leaks_into_the_next(
        plant_motor_map):
    """The plant's hip motors take their gains and bounds from the plant's model and their command from the
    controller's motor_command group: a restart sets both from the snapshot, so that a restart from an update
    is the walk that continued, to the bit, and the map at a point is the same on a fresh map, right after
    start(), and after evaluations that ended with the legs' roles swapped."""
    from drake_biped import control_kernel as ctl
    from drake_biped.step_map import SectionMap, Snapshot

    section_map, z0, template = plant_motor_map
    first = section_map.step(z0, template)
    assert np.array_equal(section_map.step(z0, template), first)
    assert np.array_equal(SectionMap(section_map.config).step(z0, template), first)
    k = int(round(section_map._simulator.get_context().get_time() / section_map._dt)) + 1
    snap = section_map._advance(k)
    target = int(snap.controller[ctl.STEP_COUNT]) + 1
    continued = section_map._to_section(target, k, 3.0)  # through a touchdown: the hips swap roles
    c = snap.controller.copy()
    c[ctl.STEP_START] -= snap.time_s
    c[ctl.STATE_TIME] -= snap.time_s
    section_map._restore(Snapshot(0.0, snap.plant, snap.torques, c, snap.command))
    section_map._simulator.Initialize()
    restarted = section_map._to_section(target, 0, 3.0)
    assert np.array_equal(restarted.plant, continued.plant)
    assert restarted.time_s == pytest.approx(continued.time_s - snap.time_s, abs=1e-12)


@pytest.mark.slow
def test_the_held_slots_do_not_change_the_map(biped_map):
    from drake_biped import control_kernel as ctl
    from drake_biped.step_map import Snapshot

    section_map, z0, template = biped_map
    base = section_map.step(z0, template)
    c = template.controller.copy()
    for slot in (ctl.Q_PREV, ctl.Q_PREV + 4, ctl.PREV_PITCH, ctl.PREV_CLEARANCE, ctl.PREV_RATES,
                 ctl.POSITIVE_WORK, ctl.SIGNED_WORK + 2, ctl.COM_X):
        c[slot] += 0.01
    shifted = Snapshot(template.time_s, template.plant, template.torques, c)
    assert np.array_equal(section_map.step(z0, shifted), base)


@pytest.mark.slow
def test_floquet_command_writes_its_record(tmp_path):
    """On `steady`, a saddle (rho about 13): its perturbations grow well above the map's evaluation noise, so the
    iterated map can be checked against the linearisation (the default gait's orbit attracts, rho about 0.53,
    and a 1e-6 perturbation decays below that noise within two steps)."""
    from drake_biped import cli
    from drake_biped.params import DRAKE_DEFAULT_CONTACT
    from drake_biped.resources import load_gait

    # measured on Drake's default contact (the near-rigid regime on), where this saddle's Jacobian converges
    # over the three perturbations; on the contact with a continuous limit its radius spreads 8-14 over them
    params = tmp_path / "steady_drake_contact.json"
    params.write_text(json.dumps(load_gait(STEADY).replace(contact=DRAKE_DEFAULT_CONTACT).to_dict()))
    out = tmp_path / "fl"
    assert cli.main(["floquet", "--params", str(params), "--epsilons", "1e-7,1e-6,1e-5", "--workers", "1",
                     "--regression-samples", "30", "--regression-sizes", "1e-7,3e-7,1e-6", "--out", str(out)]) == 0
    record = json.loads((out / "floquet.json").read_text())
    names = record["coordinates"]
    assert len(record["multipliers"]) == len(names) == len(record["fixed_point"])
    assert record["trivial"].count("section") == 1
    assert record["fixed_point_residual"] < 1e-3
    assert [r["epsilon"] for r in record["epsilon_sweep"]] == [1e-7, 1e-6, 1e-5]
    assert record["converged_epsilon"] is not None
    rho = [r["spectral_radius"] for r in record["epsilon_sweep"]]
    assert max(rho) - min(rho) <= 0.05 * max(rho)
    assert record["spectral_radius"] == pytest.approx(max(math.hypot(*m) for m in record["multipliers"]))
    # where the map is smooth, the least-squares fit is the central differences' Jacobian, and establishes it
    fit = record["regression"]
    assert [r["size"] for r in fit["rows"]] == [1e-7, 3e-7, 1e-6] and fit["plateau"]["decades"] > 0
    assert fit["verdict"] == "unstable" and fit["fixed_point_residual"] <= fit["noise"]
    assert fit["radius"] == pytest.approx(record["nontrivial_spectral_radius"], rel=0.05)
    assert "Least-squares Jacobian" in (out / "floquet.md").read_text()
    # the map iterated follows the linearisation over the checked steps
    ratios = record["decay"]["map_iterated_ratio"]
    assert all(0.8 < r < 1.25 for r in ratios)
    assert record["versions"]["drake"] and record["config"]["window"]["end_s"] == 0.0
    assert (out / "floquet.png").stat().st_size > 0 and "Spectral radius" in (out / "floquet.md").read_text()
    assert "the phase of the 1 ms control update" in (out / "floquet.md").read_text()  # the default gait's period
    # the stability report's section (`stability --floquet`) carries the same text, headings one level down
    from drake_biped.analysis.floquet_report import markdown
    from drake_biped.analysis.stability_report import _floquet_sections

    section = "\n".join(_floquet_sections({"floquet": {"without": {"markdown": markdown(record)}}}))
    assert "#### Floquet multipliers of the periodic orbit (no torque-free period)" in section
    assert f"{record['spectral_radius']:.4f}" in section and "floquet_without/floquet.png" in section
    # the sampling-phase sentence names the record's own control period
    half = {**record, "config": {**record["config"], "sim": {**record["config"]["sim"], "update_period_s": 5e-4}}}
    assert "the phase of the 0.5 ms control update" in markdown(half)


def test_the_decay_check_stays_inside_the_linear_range():
    """A growing mode gets a perturbation small enough that J^k delta stays below the plateau's top; a
    decaying one the plateau's top (the largest still linear, the furthest above rounding); a sweep without
    a plateau the settings' size; never below the floor."""
    from drake_biped.common.floquet_runs import FloquetSettings, decay_size

    settings = FloquetSettings(decay_size=1e-6, decay_floor=1e-12, decay_steps=5)
    plateau = {"plateau": [1e-8, 3e-5]}
    size = decay_size(settings, plateau, 4.0)
    assert size == pytest.approx(3e-5 / 4.0**5) and size * 4.0**5 <= 3e-5 * (1 + 1e-12)
    assert decay_size(settings, plateau, 0.5) == 3e-5
    assert decay_size(settings, {"plateau": None}, 4.0) == 1e-6
    assert decay_size(FloquetSettings(decay_floor=1e-9), plateau, 100.0) == 1e-9


def test_floquet_reports_the_period_the_map_settles_on():
    """A map whose attractor is the logistic map's period-2 orbit at r = 3.2 (the 2-fold map's multiplier
    4 + 2r - r^2 = 0.16), beside a coordinate the section normal marks trivial; then one with no period."""
    from drake_biped.common.floquet_runs import FloquetSettings, orbit_period

    def logistic(r):
        def evaluate(points):
            return [np.array([r * p[0] * (1 - p[0]), 0.0]) for p in points]
        return evaluate

    settings = FloquetSettings(period_transient=200, newton_tolerance=1e-12)
    found = orbit_period(settings, logistic(3.2), np.array([0.3, 0.5]), np.array([0.0, 1.0]))
    assert found["period"] == 2
    assert len(found["multipliers"]) == 1
    assert found["multipliers"][0][0] == pytest.approx(0.16, abs=1e-5)
    chaos = orbit_period(settings, logistic(4.0), np.array([0.3, 0.5]), np.array([0.0, 1.0]))
    assert chaos["period"] is None and chaos["spread"] > 0.5


def _jumpy_map(values, noise, seed=3, fall_beyond=None):
    """A linear map with the multipliers `values` about x* = (1, ..., n), plus a bounded sawtooth of
    amplitude `noise` that rises steeply and jumps back every 1e-6 along a fixed direction (as a contact that
    begins one plant step earlier or later moves a simulated step's image); None beyond `fall_beyond`."""
    rng = np.random.default_rng(seed)
    n = len(values)
    basis = rng.standard_normal((n, n))
    jac = basis @ np.diag(values) @ np.linalg.inv(basis)
    star = np.arange(1.0, n + 1)
    w, u = rng.standard_normal(n), rng.standard_normal(n)

    def step(x):
        d = x - star
        if fall_beyond is not None and np.linalg.norm(d) > fall_beyond:
            return None
        saw = 2.0 * ((1e6 * (w @ x)) % 1.0) - 1.0
        return star + jac @ d + noise * saw * u / np.linalg.norm(u)

    return fq.serial(step), star, jac


def test_a_least_squares_fit_finds_the_multipliers_of_a_map_whose_jumps_defeat_central_differences():
    values = [0.6, -0.45, 0.3, 0.15, 0.05]
    evaluate, star, jac = _jumpy_map(values, noise=1e-3)
    x0 = star + 0.02
    # central differences see the steep pieces, or the jumps' size over epsilon
    for epsilon in (1e-8, 1e-6, 1e-5):
        assert fq.spectral_radius(fq.difference_jacobian(evaluate, x0, epsilon)) > 20
    rows = [fq.regression_jacobian(evaluate, x0, np.ones(5), size, 400, seed=k)
            for k, size in enumerate((1e-4, 1e-2, 3e-2, 1e-1))]
    # far below the jumps' size the fit is noise, and its bootstrap says so; above it, the multipliers
    assert not rows[0].resolved(0.05)
    for r in rows[1:]:
        assert r.resolved(0.05) and abs(r.radius - 0.6) < 0.03 and r.interval[0] < 0.6 < r.interval[1] + 0.01
        assert abs(r.noise * np.linalg.norm(x0) - 1e-3 / 3 ** 0.5) < 1e-4  # the sawtooth's spread, η/√3
    plateau = fq.regression_plateau(rows, 0.05)
    assert plateau["plateau"] == [1e-2, 1e-1] and plateau["size"] == 3e-2 and abs(plateau["decades"] - 1) < 1e-12
    # the fitted map's fixed point is the map's, to within the jumps
    x_star = fq.affine_fixed_point(rows[plateau["index"]], x0)
    assert np.linalg.norm(x_star - star) < 3e-3 < np.linalg.norm(x0 - star)


def test_perturbations_that_fall_are_left_out_counted_and_keep_their_size_off_the_plateau():
    evaluate, star, _ = _jumpy_map([0.7, 0.2, -0.1], noise=1e-4, fall_beyond=0.05)
    rows = [fq.regression_jacobian(evaluate, star, np.ones(3), size, 60, seed=k)
            for k, size in enumerate((3e-3, 1e-2, 3e-2))]
    assert [r.falls > 0 for r in rows] == [False, False, True]
    assert rows[2].samples + rows[2].falls == 60
    assert fq.regression_plateau(rows, 0.05)["plateau"] == [3e-3, 1e-2]
    with pytest.raises(fq.StepFailed, match="too few"):
        fq.regression_jacobian(evaluate, star, np.ones(3), 1.0, 60)
    with pytest.raises(ValueError, match="samples"):
        fq.regression_jacobian(evaluate, star, np.ones(3), 1e-2, 4)


def test_newton_stops_at_its_best_iterate_when_a_perturbed_step_falls():
    jac = np.array([[0.5, 0.1], [0.0, 0.2]])
    star = np.array([1.0, 0.5])

    def step(x):  # falls wherever the second coordinate is below 0.4
        return None if x[1] < 0.4 else star + jac @ (x - star)

    start = np.array([1.2, 0.4])
    fixed = fq.newton_fixed_point(fq.serial(step), start, 1e-3)
    assert not fixed.converged and np.array_equal(fixed.state, start) and len(fixed.residuals) == 1
    ok = fq.newton_fixed_point(fq.serial(step), np.array([1.2, 0.6]), 1e-3, tolerance=1e-12)
    assert ok.converged and np.allclose(ok.state, star)


@given(samples=st.integers(-5, 19), sizes=st.lists(st.floats(-1.0, 1.0) | st.just(math.nan), min_size=0, max_size=5))
@settings(max_examples=25, deadline=None, database=None)
def test_the_regressions_settings_are_refused_by_name(samples, sizes):
    from drake_biped.common.floquet_runs import FloquetSettings
    from drake_biped.params import ParameterError

    if samples != 0:
        with pytest.raises(ParameterError, match=f"regression_samples {samples}"):
            FloquetSettings(regression_samples=samples)
    if len(sizes) < 3 or not all(math.isfinite(v) and v > 0 for v in sizes):
        with pytest.raises(ParameterError, match="regression_sizes"):
            FloquetSettings(regression_samples=40, regression_sizes=tuple(sizes))
    else:
        assert FloquetSettings(regression_samples=40, regression_sizes=tuple(sizes)).regression_sizes == tuple(sizes)
