"""Reading records written before a choice was recorded, kept only so that older records walk again as they walked.

A record's "config" names every field that existed when it was written; a field added since is missing from it.
Records are read with the values of their own time, never today's defaults: a missing field takes its value in
RECORD_BASE, the default configuration every record was read against before the paper's walker became the default
(our gait's CPG, gains and initiation, today's `fast_servo`, at its 1 ms plant step). Three choices recorded later
are read as the records walked (`config_of_record`). A params file a user writes is read against today's default,
the paper's walker (`params.config_of_params`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from drake_biped.params import DRAKE_DEFAULT_CONTACT, EpisodeConfig, SimulationParams

__all__ = ["RECORD_BASE", "STUDY_WALKS_BEFORE_RECORDED", "clock_of_record", "config_of_record"]

# The walks of a time-step study whose record does not list them (written before it did): none, the then default
# gait's learned window and one early in its swing.
STUDY_WALKS_BEFORE_RECORDED = [None, (0.3672, 0.8629), (0.3, 0.6)]

# The sections a record's missing fields are read from (frozen: a record's walk must not move when a default does).
RECORD_BASE = EpisodeConfig.from_dict({
    "cpg": {
        "alpha": 1.0,
        "u_a": 2.3755367036013615,
        "u_eta": 0.0,
        "u_r": 9.164202559982812,
        "kappa": 4.300448011279704,
    },
    "gait": {
        "swing_reading": "anchored",
        "phase_reading": "reset",
        "swap_timing": "predicted",
        "swing_offset_rad": 0.0,
        "hip_kp": 203.6745553930685,
        "hip_kd": 10.703999601430631,
        "hip_ki": 0.0,
        "placement_gain": 0.3320493249583393,
        "placement_velocity_gain": 0.16072233169372896,
        "torso_kp": 312.7599763908924,
        "torso_kd": 17.642142281943457,
        "torso_pitch_rad": -0.4369726563835759,
        "knee_flex_torque": 5.300991480352644,
        "knee_extend_torque": 14.804771892511479,
        "knee_extend_phase": 3.1,
        "knee_flex_max_rad": 0.42621219173395786,
        "knee_extend_thigh_rad": 0.35881932564612357,
        "knee_flex_until_phase": 0.22409554329294284,
        "knee_hold_torque": -0.2817644964158232,
        "stance_knee_torque": 24.224101821366588,
        "ankle_kp": 20.0,
        "ankle_kd": 0.3,
        "touchdown_min_step_s": 0.15,
        "touchdown_height_m": 0.002,
        "touchdown_min_advance_m": 0.05,
        "touchdown_min_phase": 2.5357676480810656,
        "hip_drive": "servo",
        "hip_joint": "swing",
        "motor_limit_nm": 40.0,
        "motor_solve": "plant",
        "motor_gain_nms": 1000.0,
        "motor_time_constant_s": 0.0,
    },
    "initial": {
        "hip_angle_rad": 0.13264502315156904,
        "speed_mps": 0.175,
        "cpg_phase_rad": 0.0,
    },
    "sim": {"time_step_s": 0.001},
}, "legacy.RECORD_BASE")


def config_of_record(data: Any, where: str | None = None) -> EpisodeConfig:
    """The EpisodeConfig of a result record's "config": as `EpisodeConfig.from_dict` against RECORD_BASE (a field
    the record lacks takes the value it walked with), and three kinds of record written before a choice was
    recorded:
    - no "contact" section: it ran on DRAKE_DEFAULT_CONTACT, and is walked again on it;
    - no "controller_clock" in its "sim", with the control period equal to the plant step: its walk is the same
      under either clock, and it is read with the paper's (the controller at every plant step), so that a
      re-walk at another step refines the controller with the plant, as today's records do. A control period
      that differs from the step is the fixed-rate loop that record ran on, and is kept;
    - a hip motor (gait.hip_drive "motor") and no "motor_solve": the controller solved it (the only motor there
      was), and it is walked again so."""
    gait = data.get("gait") if isinstance(data, Mapping) else None
    if isinstance(gait, Mapping) and gait.get("hip_drive") == "motor" and "motor_solve" not in gait:
        data = {**data, "gait": {**gait, "motor_solve": "controller"}}
    config = EpisodeConfig.from_dict(data, where, base=RECORD_BASE)
    if isinstance(data, Mapping) and "contact" not in data:
        config = config.replace(contact=DRAKE_DEFAULT_CONTACT)
    sim = data.get("sim") if isinstance(data, Mapping) else None
    if isinstance(sim, Mapping) and "controller_clock" not in sim and \
            config.sim.control_period_s == config.sim.time_step_s:
        config = config.replace(sim=dataclasses.replace(config.sim, control_period_s=None))
    return config


def clock_of_record(sim: Mapping[str, Any]) -> tuple[str, float]:
    """The controller's clock (reading, update period in s) of a record's "sim" section. A record written before
    the clock was part of the model names a control period: the fixed-rate loop it ran on."""
    if "controller_clock" in sim:
        return sim["controller_clock"], float(sim["update_period_s"])
    period = sim.get("control_period_s")
    if period is None:
        return SimulationParams.PLANT_STEP_CLOCK, float(sim["time_step_s"])
    return SimulationParams.FIXED_RATE_CLOCK, float(period)
