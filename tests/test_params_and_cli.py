"""Bad input gets a clear error naming the value."""

import json
import math

import pytest

from drake_biped.cli import main
from drake_biped.params import (
    CpgParams,
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


def test_nan_parameter_named():
    with pytest.raises(ParameterError, match="u_r"):
        CpgParams(u_r=math.nan)


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
    """A parameter file that names one gain changes that gain of the default gait; the rest of the section
    is the default configuration's, not the bare class's (whose gait does not walk)."""
    from drake_biped.params import GaitParams
    from drake_biped.resources import load_gait

    path = tmp_path / "one_gain.json"
    path.write_text(json.dumps({"gait": {"hip_kd": 12.0}, "cpg": {"kappa": 2.0}}))
    loaded = load_gait(path)
    assert loaded == EpisodeConfig().override({"gait.hip_kd": 12.0, "cpg.kappa": 2.0})
    assert loaded.gait.hip_kp == EpisodeConfig().gait.hip_kp != GaitParams().hip_kp
    with pytest.raises(ParameterError, match="bogus"):
        EpisodeConfig.from_dict({"gait": {"bogus": 1.0}})


def test_the_params_help_names_every_shipped_gait():
    """`--params`' help lists the shipped gaits by name, so a gait added to drake_biped/gaits/ is offered
    without editing the help text."""
    from drake_biped.cli import build_parser
    from drake_biped.resources import gait_names

    walk = next(a for a in build_parser()._actions if a.dest == "command").choices["walk"]
    text = " ".join(walk.format_help().split())
    assert "steady" in gait_names()
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
