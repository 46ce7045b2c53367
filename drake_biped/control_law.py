"""The controller's numbers for one episode: the schema of its Context parameter (`LAW`), and its documentation.

The compiled update (`controller.control_step`) reads an episode's CPG, gains, window, ground and fall thresholds
from one vector, a numeric parameter of the controller's Context packed once per episode (`controller.law_vector`). Each slot
that copies a field of the configuration takes that field's declaration in `params` (`param`: unit, bounds,
meaning); the others are derived from it (`_DERIVED`). The kernel reads the slots through the `L_*` offsets.
`parameter_markdown` writes docs/PARAMETERS.md from these declarations (`make docs-tables`).
"""

from __future__ import annotations

from drake_biped.layout import Field, VectorLayout
from drake_biped.params import (
    CpgParams,
    EpisodeConfig,
    GaitParams,
    Ground,
    SimulationParams,
    TorqueFreeWindow,
    parameter_info,
)

__all__ = ["LAW", "LAW_COPIED", "parameter_markdown"]


# The episode's numbers as the compiled update takes them: one vector, packed by law_vector() into the context's
# numeric parameter when an episode is set (`set_episode`), read in the kernel through the constants below.
# What the Context parameter copies from the episode's configuration, one slot each, in order: (section,
# field, the slot's name). Each field's doc, unit and bounds are its declaration in params (`param`).
LAW_COPIED = (
    *(("cpg", n, n) for n in ("alpha", "u_a", "u_eta", "u_r", "kappa")),
    *(("gait", n, n) for n in ("swing_offset_rad", "hip_kp", "hip_kd", "hip_ki", "placement_gain",
                               "placement_velocity_gain", "torso_kp", "torso_kd", "torso_pitch_rad")),
    # the swing knee's law, in swing_knee_torque_k's order (gait.knee_law)
    *(("gait", n, n) for n in ("knee_extend_phase", "knee_extend_thigh_rad", "knee_flex_max_rad",
                               "knee_flex_until_phase", "knee_flex_torque", "knee_extend_torque",
                               "knee_hold_torque")),
    *(("gait", n, n) for n in ("stance_knee_torque", "ankle_kp", "ankle_kd")),
    # the touchdown's conditions, in is_touchdown_k's order (gait.touchdown_rule)
    *(("gait", n, n) for n in ("touchdown_min_step_s", "touchdown_height_m", "touchdown_min_advance_m",
                               "touchdown_min_phase")),
    ("window", "start_s", "window_start_s"), ("window", "end_s", "window_end_s"),
    ("window", "first_step", "window_first_step"),
    ("ground", "slope_rad", "ground_slope_rad"), ("ground", "level_length_m", "ground_level_length_m"),
    ("sim", "fall_hip_height_m", "fall_hip_height_m"), ("sim", "fall_pitch_rad", "fall_pitch_rad"),
    ("gait", "motor_limit_nm", "motor_limit_nm"), ("gait", "motor_time_constant_s", "motor_time_constant_s"),
    ("gait", "motor_gain_nms", "motor_gain_nms"),
)
_SECTION_TYPES = {"cpg": CpgParams, "gait": GaitParams, "window": TorqueFreeWindow, "ground": Ground,
                  "sim": SimulationParams}


def _copied(section: str, name: str, slot: str | None = None) -> Field:
    """The LAW slot that copies params section `section`'s field `name`, declared there."""
    info = parameter_info(_SECTION_TYPES[section], name)
    doc = f"{_SECTION_TYPES[section].__name__}.{name}: {info['doc']}"
    if section == "ground" and name == "level_length_m":
        doc += " (NaN for None)"
    if section == "gait" and name == "touchdown_min_phase":
        doc += " (-inf under phase_reading 'entrained': the phase does not follow the steps)"
    return Field(slot or name, 1, doc, info["unit"], info["bounds"])


_DERIVED = {  # the slots computed from the configuration (controller.law_vector), before and among the copied ones
    "update_period_s": Field("update_period_s", 1, "the controller's update period: the plant step under the "
                             "paper's clock, else the fixed-rate loop's (SimulationParams.update_period_s)", "s"),
    "state_lag_s": Field("state_lag_s", 1, "the plant step: the state read at update time t is the state at "
                         "t + lag (SimulationParams.time_step_s)", "s"),
    "swing_amplitude_rad": Field("swing_amplitude_rad", 1, "alpha u_a / u_r (CpgParams.swing_amplitude_rad)", "rad"),
    "integrated": Field("integrated", 1, "1 for GaitParams.swing_reading 'integrated', 0 for 'anchored'", "1"),
    "predicted_swap": Field("predicted_swap", 1, "1 for GaitParams.swap_timing 'predicted', 0 for 'update'", "1"),
    "entrained": Field("entrained", 1, "1 for GaitParams.phase_reading 'entrained', 0 for 'reset'", "1"),
    "ground_tan_slope": Field("ground_tan_slope", 1, "tan(Ground.slope_rad)", "1"),
    "hip_motor": Field("hip_motor", 1, "1 for GaitParams.hip_drive 'motor' (zeta the hip joint's velocity, "
                       "reached each update), 0 for 'servo'", "1"),
    "inter_leg": Field("inter_leg", 1, "1 for GaitParams.hip_joint 'inter_leg', 0 for 'swing'", "1"),
    "motor_plant": Field("motor_plant", 1, "1 for the hip motor solved in the plant's step (GaitParams.hip_drive "
                         "'motor', motor_solve 'plant'), else 0", "1"),
}
_COPIED = {slot: _copied(section, name, slot) for section, name, slot in LAW_COPIED}
# The controller's numbers for one episode, a numeric parameter of its Context: every slot with its doc, unit
# and bounds (docs/PARAMETERS.md is generated from it: `parameter_markdown`).
LAW = VectorLayout("law", tuple(({**_DERIVED, **_COPIED})[name] for name in (
    "update_period_s", "state_lag_s", "alpha", "u_a", "u_eta", "u_r", "kappa", "swing_amplitude_rad",
    "integrated", "predicted_swap", "entrained", "swing_offset_rad", "hip_kp", "hip_kd", "hip_ki",
    "placement_gain", "placement_velocity_gain", "torso_kp", "torso_kd", "torso_pitch_rad",
    "knee_extend_phase", "knee_extend_thigh_rad", "knee_flex_max_rad", "knee_flex_until_phase", "knee_flex_torque",
    "knee_extend_torque", "knee_hold_torque", "stance_knee_torque", "ankle_kp", "ankle_kd",
    "touchdown_min_step_s", "touchdown_height_m", "touchdown_min_advance_m", "touchdown_min_phase",
    "window_start_s", "window_end_s", "window_first_step", "ground_slope_rad", "ground_tan_slope",
    "ground_level_length_m", "fall_hip_height_m", "fall_pitch_rad", "hip_motor", "inter_leg", "motor_limit_nm",
    "motor_time_constant_s", "motor_plant", "motor_gain_nms")))
_o = LAW.offset
L_DT, L_LAG, L_ALPHA, L_UA, L_UETA, L_UR, L_KAPPA = (_o(n) for n in ("update_period_s", "state_lag_s", "alpha", "u_a",
                                                                    "u_eta", "u_r", "kappa"))
L_AMPLITUDE, L_INTEGRATED, L_PREDICTED, L_OFFSET = (_o(n) for n in ("swing_amplitude_rad", "integrated",
                                                                   "predicted_swap", "swing_offset_rad"))
L_ENTRAINED = _o("entrained")
L_HIP_KP, L_HIP_KD, L_HIP_KI, L_PLACE, L_PLACE_V = (_o(n) for n in ("hip_kp", "hip_kd", "hip_ki", "placement_gain",
                                                                   "placement_velocity_gain"))
L_TORSO_KP, L_TORSO_KD, L_TORSO_PITCH, L_KNEE, L_STANCE_KNEE = (_o(n) for n in (
    "torso_kp", "torso_kd", "torso_pitch_rad", "knee_extend_phase", "stance_knee_torque"))
L_ANKLE_KP, L_ANKLE_KD, L_TOUCHDOWN = _o("ankle_kp"), _o("ankle_kd"), _o("touchdown_min_step_s")
L_T1, L_T2, L_FIRST_STEP = _o("window_start_s"), _o("window_end_s"), _o("window_first_step")
L_SLOPE, L_TAN, L_LEVEL = _o("ground_slope_rad"), _o("ground_tan_slope"), _o("ground_level_length_m")
L_FALL_HEIGHT, L_FALL_PITCH = _o("fall_hip_height_m"), _o("fall_pitch_rad")
L_MOTOR, L_INTER_LEG, L_MOTOR_LIMIT = _o("hip_motor"), _o("inter_leg"), _o("motor_limit_nm")
L_MOTOR_TAU, L_MOTOR_PLANT, L_MOTOR_GAIN = _o("motor_time_constant_s"), _o("motor_plant"), _o("motor_gain_nms")
del _o


def _section_markdown(cls: type) -> str:
    """One section of EpisodeConfig as a Markdown table, from its fields' declarations (`param`)."""
    from dataclasses import fields

    def bounds(b) -> str:
        if b is None or b == (None, None):
            return ""
        return f"[{'-inf' if b[0] is None else f'{b[0]:g}'}, {'inf' if b[1] is None else f'{b[1]:g}'}]"

    rows = ["| field | default | unit | bounds | meaning |", "|---|---|---|---|---|"]
    for f in fields(cls):
        if "doc" in f.metadata:
            default = f.default if not isinstance(f.default, float) else f"{f.default:g}"
            rows.append(f"| `{f.name}` | {default!s} | {f.metadata['unit'] or '-'} | {bounds(f.metadata['bounds'])} "
                        f"| {f.metadata['doc'].replace('|', '/')} |")
    return "\n".join(rows) + "\n"


def parameter_markdown() -> str:
    """docs/PARAMETERS.md: the controller's Context parameter (LAW), slot by slot, and every section of an
    episode's configuration, field by field, from their declarations."""
    from drake_biped.params import ContactParams, InitialConditions, Push

    sections = {"cpg": CpgParams, "gait": GaitParams, "initial": InitialConditions, "window": TorqueFreeWindow,
                "ground": Ground, "push": Push, "sim": SimulationParams, "contact": ContactParams,
                "(top level)": EpisodeConfig}
    configuration = "".join(f"\n### `{name}`: {cls.__name__}\n\n" + _section_markdown(cls)
                            for name, cls in sections.items())
    return ("# Parameters\n\n"
            "Generated from the code (`make docs-tables`; tests/test_parameters.py checks it is current).\n\n"
            "## The controller's Context parameter\n\n"
            "The controller's numbers for one episode are one numeric parameter of its Drake Context, `LAW` in "
            "drake_biped/control_law.py: the slots that copy a field of the episode's configuration take its "
            "declaration in drake_biped/params.py (`param`: default, unit, bounds, meaning); the others are "
            "computed from it. Unit `1`: dimensionless (a gain ratio, a flag 1 or 0, a count of steps).\n\n"
            + LAW.markdown()
            + "\n## The episode's configuration\n\n"
            "Every field of `EpisodeConfig`'s sections, as a params file or `config.override({\"section.field\": "
            "value})` names it, with the dataclass's default (`CpgParams()`: Table III; `GaitParams()`: the paper's "
            "walker's gains; `EpisodeConfig()` is the paper's walker, drake_biped/gaits/paper.json, and a shipped gait "
            "file its own), unit, bounds "
            "(the dataclass refuses a value outside them) and meaning. Unit `-`: a choice among named readings.\n"
            + configuration)
