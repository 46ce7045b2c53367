"""Bad input gets a clear error naming the value."""

import json
import math

import pytest

from drake_biped.cli import main
from drake_biped.params import (
    EpisodeConfig,
    Ground,
    ParameterError,
    SimulationParams,
    TorqueFreeWindow,
    walked_the_distance,
)


def test_a_walk_has_walked_its_distance_only_to_it_and_without_a_fall():
    assert walked_the_distance(False, 10.0 - 1e-9, 10.0)  # distance = com_x - com_x0, rounded
    assert not walked_the_distance(False, 9.99, 10.0)
    assert not walked_the_distance(True, 10.5, 10.0)  # a fall, however far it went


def test_out_of_range_parameter_named():
    with pytest.raises(ParameterError, match=r"start_s = -0.1"):
        TorqueFreeWindow(-0.1, 0.5)
    with pytest.raises(ParameterError, match="distance_m"):
        SimulationParams(distance_m=-1.0)


def test_unknown_parameter_named():
    with pytest.raises(ParameterError, match="bogus"):
        EpisodeConfig.from_dict({"cpg": {"bogus": 1.0}})


def test_descending_piecewise_ground_rejected():
    with pytest.raises(ParameterError, match="slope_rad"):
        Ground(slope_rad=-0.02, level_length_m=2.0)


def test_ground_height_and_slope():
    assert Ground().height(3.0) == 0.0
    assert Ground(slope_rad=0.1).height(2.0) == pytest.approx(2.0 * math.tan(0.1))
    g = Ground(slope_rad=0.02, level_length_m=2.0)
    assert g.height(1.5) == 0.0 and g.slope_at(1.5) == 0.0
    assert g.height(3.0) == pytest.approx(math.tan(0.02)) and g.slope_at(3.0) == 0.02


def test_config_round_trip():
    c = EpisodeConfig(window=TorqueFreeWindow(0.2, 0.5), seed=3)
    assert EpisodeConfig.from_dict(c.to_dict()) == c


def test_a_partial_section_keeps_the_default_gait(tmp_path):
    """A parameter file that names one gain changes that gain of the default gait, the paper's walker; the
    rest of the section is its. The default is one walker throughout: each section class's defaults are the
    paper walker's, its CPG Table III as `paper.TABLE_III` prints it."""
    from drake_biped.paper import TABLE_III
    from drake_biped.params import CpgParams, GaitParams, InitialConditions
    from drake_biped.resources import load_gait

    path = tmp_path / "one_gain.json"
    path.write_text(json.dumps({"gait": {"torso_kd": 12.0}, "cpg": {"kappa": 2.0}}))
    loaded = load_gait(path)
    assert loaded == EpisodeConfig().override({"gait.torso_kd": 12.0, "cpg.kappa": 2.0})
    assert loaded.gait.torso_kp == EpisodeConfig().gait.torso_kp
    assert EpisodeConfig() == load_gait("paper")
    assert (EpisodeConfig().cpg, EpisodeConfig().gait, EpisodeConfig().initial) == (
        CpgParams(), GaitParams(), InitialConditions())
    assert {name: getattr(CpgParams(), name) for name in ("alpha", "u_a", "u_eta", "u_r", "kappa")} == {
        name: TABLE_III[name] for name in ("alpha", "u_a", "u_eta", "u_r", "kappa")}
    with pytest.raises(ParameterError, match="bogus"):
        EpisodeConfig.from_dict({"gait": {"bogus": 1.0}})


def test_the_params_help_names_every_shipped_gait():
    """`--params`' help lists the shipped gaits by name, so a gait added to drake_biped/gaits/ is offered
    without editing the help text."""
    from drake_biped.cli import build_parser
    from drake_biped.resources import gait_names

    walk = next(a for a in build_parser()._actions if a.dest == "command").choices["walk"]
    text = " ".join(walk.format_help().split())
    assert "paper" in gait_names()
    assert all(name in text for name in gait_names())


@pytest.mark.parametrize("argv, needle", [
    (["walk", "--distance", "-1", "--out", "x"], "'-1' must be > 0"),
    (["walk", "--distance", "nan", "--out", "x"], "'nan' is not a finite number"),
    (["walk", "--t1", "-0.1", "--t2", "0.5", "--out", "x"], "'-0.1' must be >= 0"),
    (["walk", "--t1", "0.2", "--out", "x"], "--t1 and --t2 go together"),
    (["walk", "--bogus", "--out", "x"], "--bogus"),
    (["walk", "--slope", "0.9", "--out", "x"], "slope_rad = 0.9"),
])
def test_cli_rejects_bad_input(argv, needle, capsys, tmp_path):
    argv = [a if a != "x" else str(tmp_path / "out") for a in argv]
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert needle in capsys.readouterr().err
    assert not (tmp_path / "out" / "result.json").exists()


def test_every_experiment_owns_its_command_in_one_shape():
    """Each experiment module declares its options, builds its settings from them, runs, and is the one place
    its command is defined; cli.py only loops over them."""
    import inspect

    from drake_biped import cli

    names = set()
    for module in cli.experiment_commands():
        for attr in ("COMMAND", "PARSER", "add_arguments", "settings_from_args", "command", "run"):
            assert hasattr(module, attr), (module.__name__, attr)
        assert list(inspect.signature(module.settings_from_args).parameters) == ["args"], module.__name__
        names.add(module.COMMAND)
    commands = next(a for a in cli.build_parser()._actions if a.dest == "command").choices
    assert names <= set(commands) and {"bifurcation", "basins"} <= names


def test_the_controller_clock_is_the_plant_step_by_default_and_every_record_names_it():
    """The paper's clock (ODE's motors act inside every step): the controller's update period is the plant step,
    refined with it; a fixed-rate loop is a number kept over the step; a record holds the reading and the rate;
    an older record's control period is the fixed-rate loop it ran on."""
    from drake_biped.control_law import L_DT
    from drake_biped.controller import law_vector
    from drake_biped.legacy import clock_of_record
    from drake_biped.params import with_time_step

    config = EpisodeConfig().override({"sim.time_step_s": 2.5e-4})
    assert config.sim.clock == "plant step" and config.sim.update_period_s == 2.5e-4
    assert law_vector(config)[L_DT] == 2.5e-4  # the kernel integrates at the plant step
    record = config.to_dict()["sim"]
    assert (record["controller_clock"], record["update_period_s"]) == ("plant step", 2.5e-4)
    assert EpisodeConfig.from_dict(config.to_dict()) == config
    fixed = EpisodeConfig().override({"sim.control_period_s": 1e-3})
    half = with_time_step(fixed.sim, 5e-4)
    assert (half.clock, half.update_period_s) == ("fixed rate", 1e-3)
    assert clock_of_record(fixed.replace(sim=half).to_dict()["sim"]) == ("fixed rate", 1e-3)
    with pytest.raises(ParameterError, match="time_step_s 0.002"):
        with_time_step(fixed.sim, 2e-3)
    old = {"time_step_s": 5e-4, "control_period_s": 1e-3}  # a record from before the clock was recorded
    assert clock_of_record(old) == ("fixed rate", 1e-3)
    assert EpisodeConfig.from_dict({"sim": old}).sim.update_period_s == 1e-3
    from drake_biped.legacy import config_of_record

    # a record from before: its loop at its own step reads as the paper's clock; a slower loop stays fixed
    legacy = {"sim": {"time_step_s": 1e-3, "control_period_s": 1e-3}, "contact": {}}
    assert config_of_record(legacy).sim.clock == "plant step"
    assert config_of_record({"sim": old, "contact": {}}).sim.update_period_s == 1e-3
    assert config_of_record(fixed.to_dict()).sim.clock == "fixed rate"  # a record that names its clock


def test_the_control_period_option_must_divide_the_plant_step(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["walk", "--out", str(tmp_path / "w"), "--time-step", "0.0004", "--control-period", "0.001"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--control-period 0.001" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "w").exists()
