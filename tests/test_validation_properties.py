"""One validation path: every value is checked against its one declaration (`params.param`: type and bounds)
wherever it enters (a params file through the command line and `load_gait`, `EpisodeConfig.from_dict`,
`override`, the dataclasses, a public function's argument, a learner's settings), and the rules that join
fields (`params.check_given`) refuse at every user entry while the internal paths (a learner's sampled window,
a record read back) keep their values. The bad values are generated from the declarations themselves."""

from __future__ import annotations

import json
import math
import tempfile
from dataclasses import fields
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import drake_biped as db
from drake_biped import params
from drake_biped.cli import main
from drake_biped.declared import Validated
from drake_biped.legacy import config_of_record
from drake_biped.params import EpisodeConfig, GaitParams, ParameterError, TorqueFreeWindow
from drake_biped.resources import gait_names, gait_path, load_gait

FAST = settings(max_examples=10, deadline=None, database=None)
# Each command-line example parses the whole command (about 50 ms): a few per field.
CLI = settings(max_examples=2, deadline=None, database=None,
               suppress_health_check=[HealthCheck.function_scoped_fixture])


def _sections() -> dict[str, type]:
    """EpisodeConfig's sections by name, read from its declaration (a section's type names its class)."""
    out = {}
    for f in fields(EpisodeConfig):
        name = str(f.type).removesuffix("| None").strip()
        cls = getattr(params, name, None)
        if isinstance(cls, type) and issubclass(cls, Validated):
            out[f.name] = cls
    return out


SECTIONS = _sections()
# (section or None for EpisodeConfig's own field, the field): every field declared with `param`.
DECLARED = [(section, f) for section, cls in SECTIONS.items() for f in fields(cls) if "bounds" in f.metadata] + \
    [(None, f) for f in fields(EpisodeConfig) if "bounds" in f.metadata]


def _kind(f) -> tuple[str, bool]:
    text = str(f.type)
    return text.removesuffix("| None").strip(), text.endswith("| None")


# Every choice a section declares (GaitParams.HIP_DRIVES, SimulationParams.CONTACT_APPROXIMATIONS, ...).
CHOICES = {v for cls in SECTIONS.values() for attr in dir(cls) if attr.isupper()
           for v in (getattr(cls, attr) if isinstance(getattr(cls, attr), tuple) else ())}


def bad_values(f) -> st.SearchStrategy:
    """Values the declaration of `f` refuses: of another type, out of its bounds, not finite."""
    kind, optional = _kind(f)
    lo, hi = f.metadata["bounds"]
    wrong = [st.booleans(), st.lists(st.integers(), max_size=2), st.dictionaries(st.text(max_size=2), st.integers(),
                                                                                 max_size=1)]
    if not optional:
        wrong.append(st.none())
    if kind == "str":
        return st.one_of(*wrong, st.integers(), st.floats(), st.text(max_size=8).filter(lambda t: t not in CHOICES))
    wrong.append(st.text(max_size=5))
    if kind == "int":  # a float is no integer, whatever its value
        outside = ([] if lo is None else [st.integers(max_value=lo - 1)]) + \
            ([] if hi is None else [st.integers(min_value=hi + 1)])
        return st.one_of(*wrong, *outside, st.floats())
    outside = ([] if lo is None else [st.floats(max_value=lo, exclude_max=True, allow_infinity=False)]) + \
        ([] if hi is None else [st.floats(min_value=hi, exclude_min=True, allow_infinity=False)])
    return st.one_of(*wrong, *outside, st.sampled_from([math.nan, math.inf, -math.inf]))


def _name(section, f) -> str:
    """How an error names the field: its class and field ("CpgParams.u_a")."""
    return f"{(SECTIONS[section] if section else EpisodeConfig).__name__}.{f.name}"


def _file_data(section, f, value) -> dict:
    return {section: {f.name: value}} if section else {f.name: value}


def _one_line(exc: BaseException, *texts: str) -> None:
    message = str(exc)
    assert "\n" not in message, message
    for text in texts:
        assert text in message, (text, message)


IDS = [f"{s or 'config'}.{f.name}" for s, f in DECLARED]


def test_every_section_and_field_is_generated():
    """The strategies read the declarations: every section of EpisodeConfig and each of their fields."""
    assert set(SECTIONS) == {"cpg", "gait", "initial", "window", "ground", "push", "sim", "contact"}
    assert len(DECLARED) == sum(len(fields(c)) for c in SECTIONS.values()) + 1  # + the seed


@pytest.mark.parametrize("section, f", DECLARED, ids=IDS)
@FAST
@given(data=st.data())
def test_a_bad_value_is_refused_by_name_at_every_api_entry(section, f, data):
    value = data.draw(bad_values(f))
    name = _name(section, f)
    dotted = f"{section}.{f.name}" if section else f.name
    entries = {
        "dataclass": lambda: (SECTIONS[section] if section else EpisodeConfig)(**{f.name: value}),
        "from_dict": lambda: EpisodeConfig.from_dict(_file_data(section, f, value)),
        "override": lambda: EpisodeConfig().override({dotted: value}),
        "sampled override": lambda: EpisodeConfig().override({dotted: value}, sampled=True),
    }
    for make in entries.values():
        with pytest.raises(ParameterError) as caught:
            make()
        _one_line(caught.value, name)


@pytest.mark.parametrize("section, f", DECLARED, ids=IDS)
@CLI
@given(data=st.data())
def test_a_bad_value_in_a_params_file_is_exit_2_naming_it_and_creates_nothing(section, f, data, capsys):
    value = data.draw(bad_values(f))
    capsys.readouterr()
    with tempfile.TemporaryDirectory() as tmp:
        path, out = Path(tmp) / "params.json", Path(tmp) / "run" / "out"
        path.write_text(json.dumps(_file_data(section, f, value)))
        with pytest.raises(ParameterError) as caught:
            load_gait(path)
        _one_line(caught.value, f"--params {path}", _name(section, f))
        with pytest.raises(SystemExit) as stop:
            main(["walk", "--params", str(path), "--out", str(out)])
        lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
        assert stop.value.code == 2
        assert len(lines) == 1 and _name(section, f) in lines[0] and "Traceback" not in lines[0], lines
        assert not (Path(tmp) / "run").exists()


# The episode options whose values are fields: each refused by that field's declaration, named by the option.
FLAGS = {"--distance": ("sim", "distance_m"), "--max-time": ("sim", "max_time_s"), "--slope": ("ground", "slope_rad"),
         "--level-length": ("ground", "level_length_m"), "--time-step": ("sim", "time_step_s"),
         "--control-period": ("sim", "control_period_s")}


def _outside(section: str, name: str) -> st.SearchStrategy:
    """Finite numbers outside the declared bounds of `section`.`name`, as an option's text."""
    lo, hi = next(f for f in fields(SECTIONS[section]) if f.name == name).metadata["bounds"]
    above = st.floats(min_value=hi, exclude_min=True, max_value=1e9)
    below = st.floats(max_value=lo, exclude_max=True, min_value=-1e9)
    return st.one_of(above, below) if lo < 0 else above  # the option's type refuses what is <= 0 itself


@pytest.mark.parametrize("flag", FLAGS)
@CLI
@given(data=st.data())
def test_a_flag_outside_its_fields_declaration_is_exit_2_naming_it_and_creates_nothing(flag, data, capsys):
    section, name = FLAGS[flag]
    value = data.draw(_outside(section, name))
    capsys.readouterr()
    with tempfile.TemporaryDirectory() as tmp:
        with pytest.raises(SystemExit) as stop:
            main(["walk", f"{flag}={value!r}", "--out", str(Path(tmp) / "run" / "out")])
        lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
        assert stop.value.code == 2 and len(lines) == 1, lines
        assert f"{flag} " in lines[0] and f"{SECTIONS[section].__name__}.{name}" in lines[0], lines
        assert not (Path(tmp) / "run").exists()


# The rules that join fields.

# t1, t2 (s) within the window's declared bounds, t2 <= t1 and not the explicit no-window 0/0.
_T = st.floats(min_value=0.0, max_value=10.0, allow_nan=False)
NEVER_OPENS = st.tuples(_T, _T).map(lambda w: (max(w), min(w))).filter(lambda w: w != (0.0, 0.0))
OPENS = st.tuples(_T, _T).filter(lambda w: w[0] != w[1]).map(lambda w: (min(w), max(w)))


@FAST
@given(window=NEVER_OPENS)
def test_a_window_that_never_opens_is_refused_where_a_user_gives_it(window):
    t1, t2 = window
    with pytest.raises(ParameterError) as caught:
        EpisodeConfig().override({"t1": t1, "t2": t2})
    _one_line(caught.value, "EpisodeConfig.override", f"t1 = {t1!r}", "never opens")
    with pytest.raises(ParameterError) as caught:
        params.config_of_params({"window": {"start_s": t1, "end_s": t2}}, "--params p.json")
    _one_line(caught.value, "--params p.json: window.start_s", "never opens")
    # what a learner samples, and a record holds, is the paper's "no window" for that episode
    for config in (EpisodeConfig(window=TorqueFreeWindow(t1, t2)),
                   EpisodeConfig().override({"t1": t1, "t2": t2}, sampled=True),
                   EpisodeConfig.from_dict({"window": {"start_s": t1, "end_s": t2}}),
                   config_of_record({"window": {"start_s": t1, "end_s": t2}})):
        assert not config.window.active and config.as_walked().window == TorqueFreeWindow()


@FAST
@given(t1=st.floats(min_value=0.0, max_value=10.0, exclude_min=True))
def test_t1_without_t2_is_refused_where_no_window_is_open(t1):
    with pytest.raises(ParameterError) as caught:
        EpisodeConfig().override({"t1": t1})
    _one_line(caught.value, f"t1 = {t1!r} without t2")
    with pytest.raises(ParameterError) as caught:
        params.config_of_params({"window": {"start_s": t1}}, "--params p.json")
    _one_line(caught.value, "window.start_s", "without window.end_s")


@FAST
@given(window=OPENS)
def test_a_window_that_opens_is_taken_at_every_entry(window):
    t1, t2 = window
    config = EpisodeConfig().override({"t1": t1, "t2": t2})
    assert (config.window.start_s, config.window.end_s) == window and config.window.active
    assert params.config_of_params({"window": {"start_s": t1, "end_s": t2}}, "p").window == config.window
    assert EpisodeConfig().override({"t1": 0.0, "t2": 0.0}).window == TorqueFreeWindow()  # the explicit no window


def _unread_cases():
    """(readings, field) for every field a reading leaves unread (GaitParams.unread)."""
    out = []
    for drive in GaitParams.HIP_DRIVES:
        for phase in GaitParams.PHASE_READINGS:
            readings = {"hip_drive": drive, "phase_reading": phase}
            out += [(readings, name) for name in GaitParams(**readings).unread()]
    return out


def _other_value(name: str) -> st.SearchStrategy:
    """A value of gait field `name` inside its declaration and other than its default."""
    f = next(f for f in fields(GaitParams) if f.name == name)
    if str(f.type) == "str":
        return st.sampled_from([v for v in getattr(GaitParams, name.upper() + "S") if v != f.default])
    lo, hi = f.metadata["bounds"]
    return st.floats(min_value=lo, max_value=hi).filter(lambda v: v != f.default)


@pytest.mark.parametrize("readings, name", _unread_cases(),
                         ids=[f"{r['hip_drive']}-{r['phase_reading']}-{n}" for r, n in _unread_cases()])
@FAST
@given(data=st.data())
def test_an_unread_field_given_a_value_is_refused_where_a_user_gives_it(readings, name, data):
    value = data.draw(_other_value(name))
    gait = {**readings, name: value}
    reading = "phase_reading 'entrained'" if name in GaitParams.UNREAD_BY_ENTRAINED else \
        f"hip_drive {readings['hip_drive']!r}"
    with pytest.raises(ParameterError) as caught:
        EpisodeConfig().override({f"gait.{k}": v for k, v in gait.items()})
    _one_line(caught.value, f"gait.{name} = ", f"is unread under {reading}")
    with pytest.raises(ParameterError) as caught:
        params.config_of_params({"gait": gait}, "--params p.json")
    _one_line(caught.value, f"--params p.json: gait.{name} = ", "unread")
    # a search's sampled point, a record and the dataclass keep it: the walk is the one without it
    walked = EpisodeConfig().override({f"gait.{k}": v for k, v in readings.items()}).as_walked()
    for config in (EpisodeConfig().override({f"gait.{k}": v for k, v in gait.items()}, sampled=True),
                   EpisodeConfig.from_dict({"gait": gait}),
                   params.config_of_params({"gait": gait, "sim": EpisodeConfig().sim.to_dict()}, "record")):
        assert getattr(config.gait, name) == getattr(GaitParams(**gait), name) and config.as_walked() == walked


def test_the_command_line_refuses_the_rules_with_exit_2_and_creates_nothing(tmp_path, capsys):
    cases = [({"window": {"start_s": 0.5, "end_s": 0.2}}, "window.start_s = 0.5, window.end_s = 0.2"),
             ({"gait": {"hip_drive": "servo", "motor_limit_nm": 5.0}}, "gait.motor_limit_nm = 5.0 is unread under "
                                                                        "hip_drive 'servo'"),
             ({"gait": {"hip_drive": "motor", "hip_kp": 50}}, "gait.hip_kp = 50.0 is unread under hip_drive 'motor'")]
    for i, (data, text) in enumerate(cases):
        path = tmp_path / f"p{i}.json"
        path.write_text(json.dumps(data))
        with pytest.raises(SystemExit) as stop:
            main(["walk", "--params", str(path), "--out", str(tmp_path / "out" / str(i))])
        lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
        assert stop.value.code == 2 and len(lines) == 1 and f"--params {path}: {text}" in lines[0], lines
    with pytest.raises(SystemExit) as stop:
        main(["walk", "--t1", "0.5", "--t2", "0.3", "--out", str(tmp_path / "out" / "w")])
    assert stop.value.code == 2 and "--t1 0.5 --t2 0.3: t2 <= t1" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_every_shipped_gait_loads_as_a_users_file_would_and_sets_no_unread_field():
    """A shipped gait is held to the rules a user's params file is: loaded by name or by its path alike, none sets
    a field its readings leave unread to another value than its default."""
    defaults = {f.name: f.default for f in fields(GaitParams)}
    for name in gait_names():
        gait = load_gait(name)
        assert load_gait(gait_path(name)) == gait
        assert [n for n in gait.gait.unread() if getattr(gait.gait, n) != defaults[n]] == []


def test_a_record_read_back_keeps_a_sampled_window_and_any_reading(tmp_path):
    sampled = EpisodeConfig(window=TorqueFreeWindow(0.6, 0.3))
    motor = load_gait("paper")
    for i, config in enumerate((sampled, motor)):
        record, written = tmp_path / f"result{i}.json", tmp_path / f"best{i}.json"
        record.write_text(json.dumps({"config": config.to_dict()}))
        written.write_text(json.dumps(config.to_dict()))  # a grid's best_params.json, a search's best_config.json
        assert load_gait(record) == config == load_gait(written)


# Public functions' arguments and the other entries.

@FAST
@given(flag=st.one_of(st.text(max_size=4), st.integers(), st.none(), st.floats(), st.lists(st.booleans())))
def test_a_flag_of_the_api_takes_only_a_bool(flag):
    from drake_biped.episode import run_episode

    for make, name in ((lambda: db.run_episode(EpisodeConfig(), record_trajectory=flag), "record_trajectory"),
                       (lambda: run_episode(EpisodeConfig(), record_trajectory=flag), "record_trajectory"),
                       (lambda: db.simulate(EpisodeConfig(), record=flag), "record"),
                       (lambda: db.build_diagram(EpisodeConfig(), record=flag), "record"),
                       (lambda: EpisodeConfig().override({}, sampled=flag), "sampled")):
        with pytest.raises(ParameterError) as caught:
            make()
        _one_line(caught.value, f"{name} must be a bool")


@FAST
@given(data=st.data())
def test_a_function_argument_is_checked_against_its_declaration(data):
    f = next(f for f in fields(params.SimulationParams) if f.name == "time_step_s")
    value = data.draw(bad_values(f))
    with pytest.raises(ParameterError) as caught:
        db.build_plant(time_step_s=value)
    _one_line(caught.value, "build_plant: SimulationParams.time_step_s")


NOT_A_NUMBER = st.one_of(st.booleans(), st.text(max_size=3), st.lists(st.booleans(), min_size=1, max_size=2), st.none())


@FAST
@given(cost=st.one_of(NOT_A_NUMBER.filter(lambda v: v is not None), st.floats(max_value=0.0, exclude_max=True)),
       distance=st.floats(allow_nan=False, allow_infinity=False))
def test_the_reward_refuses_what_no_episode_gives(cost, distance):
    with pytest.raises(ValueError) as caught:
        db.reward(cost, distance, 10.0)
    _one_line(caught.value, "reward: cost_of_transport")
    for bad, name in ((True, "distance_m"), ("10", "target_m")):
        with pytest.raises(ValueError) as caught:
            db.reward(0.5, *((bad, 10.0) if name == "distance_m" else (distance, bad)))
        _one_line(caught.value, f"reward: {name} must be a number")


@pytest.mark.parametrize("learner", ["garb", "cmaes", "pgpe"])
@FAST
@given(variance=st.one_of(NOT_A_NUMBER, st.floats(max_value=0.0), st.sampled_from([math.nan, math.inf])),
       mean=st.one_of(NOT_A_NUMBER, st.tuples(st.booleans(), st.floats(0, 1)), st.tuples(st.floats(0, 1)),
                      st.tuples(st.sampled_from([math.nan, math.inf]), st.floats(0, 1))))
def test_a_learners_settings_are_refused_by_name(learner, variance, mean):
    with pytest.raises(ParameterError) as caught:
        db.make_learner(learner, variance=variance)
    _one_line(caught.value, "variance must be a finite number > 0")
    with pytest.raises(ParameterError) as caught:
        db.make_learner(learner, mean=mean)
    _one_line(caught.value, "mean must be two finite numbers (t1, t2)")


@FAST
@given(beta=st.one_of(NOT_A_NUMBER, st.floats(min_value=1.0), st.floats(max_value=0.0, exclude_max=True)),
       rate=st.one_of(NOT_A_NUMBER, st.floats(max_value=0.0, exclude_max=True)))
def test_garbs_own_settings_are_refused_by_name(beta, rate):
    with pytest.raises(ParameterError) as caught:
        db.GarbLearner(beta=beta)
    _one_line(caught.value, "GarbLearner: beta must be a finite number in [0, 1)")
    with pytest.raises(ParameterError) as caught:
        db.GarbLearner(schedule=[(None, rate)])
    _one_line(caught.value, "schedule[0]: learning rate must be a finite number >= 0")
