"""Parameters of the robot, the CPG controller and an episode, as validated frozen dataclasses.

Everything a simulation depends on lives here, so a result record can hold the exact inputs that made it.
SI units throughout; angles in radians (degrees appear only at the command-line edge).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from drake_biped.declared import ParameterError, Validated, _shown, check_declared, param, parameter_info
from drake_biped.paper import (
    INITIAL_HIP_ANGLE_RAD,
    INITIAL_SPEED_MPS,
    TABLE_I_TOTAL_MASS_KG,
    TABLE_III,
)
from drake_biped.robot_model import RobotModel

__all__ = [
    "ContactParams", "CpgParams", "param", "parameter_info", "EpisodeConfig", "GaitParams", "Ground", "InitialConditions", "ParameterError", "Push",
    "SHORT_NAMES", "SimulationParams", "DRAKE_DEFAULT_CONTACT",
    "with_time_step", "walked_the_distance", "check_settings", "check_declared",
    "check_given", "check_window_given", "config_of_params", "TorqueFreeWindow", "DEFAULT_CPG", "DEFAULT_GAIT", "PAPER_CPG",
    "DEFAULT_INITIAL", "DEFAULT_SIM", "DEFAULT_WINDOW_S", "RobotModel",
]

TOTAL_MASS_KG = TABLE_I_TOTAL_MASS_KG
KNEE_LIMIT_RAD = (0.0, 2.4)  # 0 is full extension: the knee cannot hyper-extend.
# Documented motor torque limits (N*m); the paper does not print them.
EFFORT_LIMITS_NM = {"hip": 40.0, "knee": 30.0, "ankle": 20.0}
# Foot geometry (m), in the ankle frame: heel and toe contact points, sole depth below the ankle.
HEEL_X_M = -0.06
TOE_X_M = 0.12
SOLE_DEPTH_M = 0.03
CONTACT_RADIUS_M = 0.01
GRAVITY_MPS2 = 9.81


@dataclass(frozen=True)
class CpgParams(Validated):
    """The CPG of eq. 2-3 with Table III's symbols; its defaults are Table III as printed (`paper.TABLE_III`).

    Phase: d(gamma)/dt = u_r + kappa * (stance ankle angular velocity).
    Output (desired swing-hip angular velocity, rad/s): zeta = alpha * u_a * sin(gamma) + u_eta.
    The paper prints alpha and u_eta in Table III but not in eq. 3; this affine form contains both and
    reduces to eq. 3 for the paper's alpha = 1, u_eta = 0.
    """

    # Table IV's grid-search ranges bound what the toolkit accepts, widened for u_a and u_r.
    alpha: float = param(TABLE_III["alpha"], "1", "CPG output gain alpha (Table III)", -2.0, 2.0)
    u_a: float = param(TABLE_III["u_a"], "rad/s", "CPG amplitude u_a: zeta = alpha u_a sin(gamma) + u_eta", 0.0, 20.0)
    u_eta: float = param(TABLE_III["u_eta"], "rad/s", "CPG offset u_eta added to zeta", -1.0, 1.0)
    u_r: float = param(TABLE_III["u_r"], "rad/s", "CPG phase rate u_r: d(gamma)/dt = u_r + kappa (stance ankle rate)", 1e-3, 30.0)
    kappa: float = param(TABLE_III["kappa"], "1", "CPG feedback gain kappa on the stance ankle's angular velocity", -10.0, 10.0)

    @property
    def swing_amplitude_rad(self) -> float:
        """Half the thigh excursion of one CPG half-cycle without feedback: alpha * u_a / u_r."""
        return self.alpha * self.u_a / self.u_r


PAPER_CPG = CpgParams(**TABLE_III)  # Table III as printed.


@dataclass(frozen=True)
class GaitParams(Validated):
    """Gains and thresholds of the hip servo, torso balance, knees, ankles and touchdown detection.

    The defaults are the paper's walker's (drake_biped/gaits/paper.json, `--params paper`): the paper prints none
    of them, and its walker's were searched (the gait file's `about` says how). Its hip motor is solved by the
    controller (`motor_solve` "controller"), as its committed full run walked; the plant's solve ("plant") is
    measured beside it (docs/RESULTS.md, "The hip motor solved in the plant's step").

    `swing_reading` says how eq. 2-3's zeta (the desired swing-thigh angular velocity) drives the swing:
    - "anchored": the reference angle runs from the lift-off angle phi_0 to a target,
      phi_0 + (phi_T - phi_0) (1 - cos gamma) / 2, with phi_T = alpha u_a / u_r plus foot-placement feedback;
      its rate equals zeta only when phi_T - phi_0 = 2 alpha u_a / u_r, so feedback rescales the CPG (and the
      target counts u_r, not the phase's real rate u_r + kappa * ankle rate).
    - "integrated": the reference angle is phi_0 + the integral of zeta since T_n, as printed; placement
      feedback (and swing_offset_rad) only add an offset blended in by (1 - cos gamma) / 2. Both readings
      servo the rate to zeta itself.

    `phase_reading` says what a touchdown does to the CPG:
    - "reset": gamma is set to 0 at each confirmed touchdown and the legs swap roles there (phase resetting,
      one CPG half-cycle per step);
    - "entrained": gamma runs free (Section II-C's "the stance and the swing leg are changed by zeta", a CPG
      adapted from Cohen's models): the sign of zeta - u_eta = alpha u_a sin(gamma) chooses which hip swings,
      so the hips swap roles where gamma crosses a multiple of pi, and only the ankle term kappa * (stance
      ankle rate) locks the oscillator to the body (Taga-style entrainment). A touchdown (the foot that did
      not land last crossing the touchdown height) only marks T_n, which the torque-free window and the
      Poincare section count from; touchdown_min_phase is not used.
    Either swing reading applies within each half-cycle.

    `hip_drive` says what realizes zeta at the hip:
    - "servo": a PID servo of the swing thigh's world angle to the swing reading's reference (hip_kp, hip_kd,
      hip_ki), its torque clipped to the motor's limit: ours, a soft explicit servo;
    - "motor": the paper's words, "the desired Hip angular velocity ... realized by the internal PID controller
      of the ODE": zeta is the desired angular velocity of the hip *joint* (`hip_joint`), reached within each
      control update as ODE's joint motor reaches it (a velocity constraint bounded by `motor_limit_nm`),
      found where `motor_solve` says. The swing reading's angle reference is not used (ODE's motor has no angle
      feedback).
    `motor_solve` (motor only) says where its torque is found:
    - "plant": the motor is a velocity-gain actuator inside the plant's implicit step (Drake's PD-controlled
      joint actuator, proportional gain 0, derivative gain `motor_gain_nms`, its effort limit the motor's
      limit), solved together with the contacts and the joint stops, as ODE solves its joint motor with its
      constraints; the stance hip balances the torso against the torque the motor applied over the last step;
    - "controller": the torque that brings the joint's velocity to zeta at the update's end, computed by the
      controller from the plant's dynamics (mass matrix, bias and gravity, the stance foot held by its contact,
      the other joints' torques of the same update; `motor_time_constant_s`), applied as a plain torque. Its model misses the joint stops and the contact's
      compliance, so it chatters and its walk moves with the plant step (docs/RESULTS.md).
    A record naming hip_drive "motor" without motor_solve was written before "plant" existed and is read as
    "controller", as it walked (`config_of_record`).
    `hip_joint` (motor only): "swing", the swing hip joint, the torso balanced by the stance hip as under the
    servo; or "inter_leg", the one inter-leg angle (swing hip minus stance hip, eq. 15's theta^Hip) driven by the
    hips' differential mode, the torso by their common mode. Inside the torque-free window the swing hip's
    torque is exactly zero under every drive.
    """

    swing_reading: str = param("anchored", "", 'how zeta drives the swing (see GaitParams): "anchored" or "integrated"')
    phase_reading: str = param("reset", "", 'what a touchdown does to the CPG (see GaitParams): "reset" or "entrained"')
    swap_timing: str = param(
        "predicted", "", 'when the roles\' torques swap at a touchdown: "predicted", at the instant inside the '
        "control period where the swing foot's clearance, extrapolated over the period, crosses the touchdown "
        "height (the period's torques blend the two roles' by the part of it each holds); \"update\", from the "
        "update that detects the crossing (up to one period late)")
    hip_drive: str = param("motor", "", 'what realizes zeta at the hip (see GaitParams): "servo" or "motor"')
    hip_joint: str = param("swing", "", 'the motor\'s joint (see GaitParams): "swing" or "inter_leg"')
    motor_limit_nm: float = param(8.704, "N*m", "the hip motor's maximum torque (hip_drive \"motor\")", 0.0, 200.0)
    motor_solve: str = param(
        "controller", "", 'where the hip motor\'s torque is found (hip_drive "motor"; see GaitParams): "plant", inside '
        'the plant\'s implicit step; "controller", by the controller from a model of the plant at each update')
    motor_gain_nms: float = param(
        1000.0, "N*m*s/rad", "the hip motor's velocity gain under motor_solve \"plant\" (not printed): its torque "
        "is -gain (rate - zeta), clipped to the limit, solved with the contacts and the stops (ODE's motor is the "
        "limit of a large gain)", 1.0, 1e6)
    motor_time_constant_s: float = param(
        0.0, "s", "the hip motor's time constant under motor_solve \"controller\" (not printed): each update "
        "closes the part min(1, update period / this) of the rate's miss; 0 closes it within each update", 0.0, 0.1)
    swing_offset_rad: float = param(
        0.0, "rad", "integrated reading: a constant offset of the swing reference at the end of the half-cycle",
        -1.5, 1.5)
    hip_kp: float = param(90.0, "N*m/rad", "swing hip servo: gain on the swing thigh's world-angle error", 0.0, 2000.0)
    hip_kd: float = param(11.0, "N*m*s/rad", "swing hip servo: gain on the rate error (zeta)", 0.0, 200.0)
    hip_ki: float = param(0.0, "N*m/(rad*s)", "swing hip servo: gain on the angle error's integral", 0.0, 2000.0)
    placement_gain: float = param(
        0.55, "rad/m", "foot placement: the end-of-swing thigh angle grows by this times (hip x - stance ankle x)",
        -5.0, 5.0)
    placement_velocity_gain: float = param(
        0.1, "rad*s/m", "foot placement: and by this times the hip's forward velocity", -5.0, 5.0)
    torso_kp: float = param(429.7, "N*m/rad", "torso: stance-hip PD to a constant pitch, gain on the pitch error",
                            0.0, 5000.0)
    torso_kd: float = param(14.89, "N*m*s/rad", "torso: gain on the pitch rate", 0.0, 500.0)
    torso_pitch_rad: float = param(-0.3469, "rad", "torso: the pitch held (negative leans forward)", -0.8, 0.8)
    # Swing knee, bang-bang: flex (below knee_flex_max_rad) until the CPG phase passes
    # knee_flex_until_phase, then passive, then extend once the phase passes knee_extend_phase and the
    # thigh is ahead by knee_extend_thigh_rad, until touchdown. Stance knee: constant extending torque.
    knee_flex_torque: float = param(6.894, "N*m", "swing knee: the flexing torque", 0.0, 30.0)
    knee_extend_torque: float = param(5.743, "N*m", "swing knee: the extending torque", 0.0, 30.0)
    knee_extend_phase: float = param(3.1, "rad", "swing knee: extends once the CPG phase passes this", 0.0, math.pi)
    knee_flex_max_rad: float = param(0.3145, "rad", "swing knee: flexes while its angle is below this", 0.0, 2.4)
    knee_extend_thigh_rad: float = param(
        0.05652, "rad", "swing knee: extends only once the swing thigh is this far ahead of vertical (a clearance "
        "guard: a swing slowed by the torque-free period does not put its toe into the ground mid-swing)",
        -1.0, 1.0)
    knee_flex_until_phase: float = param(
        0.5854, "rad", "swing knee: flexing stops once the CPG phase passes this; from there until extension "
        "the knee is passive, as in ballistic walking (pi: flex until extension)", 0.0, math.pi)
    knee_hold_torque: float = param(
        -1.772, "N*m", "swing knee: its torque in that passive middle (positive flexes; 0 leaves it free)",
        -30.0, 30.0)
    stance_knee_torque: float = param(19.19, "N*m", "stance knee: the constant extending torque", 0.0, 30.0)
    ankle_kp: float = param(29.78, "N*m/rad", "ankles: PD keeping each foot parallel to the local ground, gain",
                            0.0, 500.0)
    ankle_kd: float = param(0.08836, "N*m*s/rad", "ankles: rate gain", 0.0, 50.0)
    # Touchdown (stance/swing swap) is accepted only when all of these hold.
    touchdown_min_step_s: float = param(0.15, "s", "touchdown: at least this long after the last one", 0.0, 5.0)
    touchdown_height_m: float = param(0.002, "m", "touchdown: the swing foot's clearance is below this",
                                      0.0, 0.05)
    touchdown_min_advance_m: float = param(
        0.05, "m", "touchdown: the swing ankle is at least this far ahead of the stance ankle", -0.5, 0.5)
    touchdown_min_phase: float = param(1.555, "rad", "touchdown: the CPG phase has passed this", 0.0, math.pi)

    SWING_READINGS = ("anchored", "integrated")
    SWAP_TIMINGS = ("predicted", "update")
    PHASE_READINGS = ("reset", "entrained")
    HIP_DRIVES = ("servo", "motor")
    HIP_JOINTS = ("swing", "inter_leg")
    MOTOR_SOLVES = ("plant", "controller")

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.swing_reading not in self.SWING_READINGS:
            raise ParameterError(f"GaitParams.swing_reading = {self.swing_reading!r} is not one of "
                                 f"{list(self.SWING_READINGS)}")
        if self.phase_reading not in self.PHASE_READINGS:
            raise ParameterError(f"GaitParams.phase_reading = {self.phase_reading!r} is not one of "
                                 f"{list(self.PHASE_READINGS)}")
        if self.swap_timing not in self.SWAP_TIMINGS:
            raise ParameterError(f"GaitParams.swap_timing = {self.swap_timing!r} is not one of "
                                 f"{list(self.SWAP_TIMINGS)}")
        for name, allowed in (("hip_drive", self.HIP_DRIVES), ("hip_joint", self.HIP_JOINTS),
                              ("motor_solve", self.MOTOR_SOLVES)):
            if getattr(self, name) not in allowed:
                raise ParameterError(f"GaitParams.{name} = {getattr(self, name)!r} is not one of {list(allowed)}")
        if self.hip_drive == "servo" and self.hip_joint != "swing":
            raise ParameterError(f"GaitParams.hip_joint = {self.hip_joint!r} reads the motor's joint: it changes "
                                 "nothing under hip_drive 'servo'")
        if self.hip_drive == "motor" and self.motor_solve == "plant" and self.hip_joint != "swing":
            raise ParameterError(f"GaitParams.hip_joint = {self.hip_joint!r} needs motor_solve 'controller': the "
                                 "plant's motors act on one joint each, not on the difference of two")

    # What each reading leaves unread: the controller never reads these fields under it.
    UNREAD_BY_MOTOR = ("swing_reading", "swing_offset_rad", "hip_kp", "hip_kd", "hip_ki", "placement_gain",
                       "placement_velocity_gain")  # the swing reference and its servo: ODE's motor has no angle
    UNREAD_BY_SERVO = ("motor_limit_nm", "motor_solve", "motor_gain_nms", "motor_time_constant_s")
    UNREAD_BY_PLANT_MOTOR = ("motor_time_constant_s",)
    UNREAD_BY_CONTROLLER_MOTOR = ("motor_gain_nms",)
    UNREAD_BY_ENTRAINED = ("touchdown_min_phase",)  # the phase does not follow the steps

    @property
    def plant_motor(self) -> bool:
        """Whether the plant solves the hip motor (hip_drive "motor", motor_solve "plant"): its hips are then
        PD-controlled actuators, driven through the controller's "motor_command" output."""
        return self.hip_drive == "motor" and self.motor_solve == "plant"

    def unread(self) -> tuple[str, ...]:
        """The fields this gait's readings leave unread (`hip_drive`, `phase_reading`): a value given to one
        of them changes no walk."""
        if self.hip_drive == "motor":
            names = self.UNREAD_BY_MOTOR + (self.UNREAD_BY_PLANT_MOTOR if self.motor_solve == "plant"
                                            else self.UNREAD_BY_CONTROLLER_MOTOR)
        else:
            names = self.UNREAD_BY_SERVO
        return names + (self.UNREAD_BY_ENTRAINED if self.phase_reading == "entrained" else ())

    def as_walked(self) -> GaitParams:
        """These gains as the controller reads them: each unread field (`unread`) at its default."""
        defaults = {f.name: f.default for f in fields(self)}
        return dataclasses.replace(self, **{name: defaults[name] for name in self.unread()})


@dataclass(frozen=True)
class InitialConditions(Validated):
    """The paper's initiation: the thighs spread by hip_angle_rad (split evenly about an upright torso),
    all bodies moving forward at speed_mps. Both feet start on the ground; the front leg is the first
    stance leg. (Read as each thigh at +-7.6 deg, the body could not vault over the front foot at
    0.175 m/s: an inverted pendulum of 0.6 m needs 0.33 m/s for that; as the angle between the
    thighs it needs 0.166 m/s.)"""

    hip_angle_rad: float = param(INITIAL_HIP_ANGLE_RAD, "rad", "the angle between the thighs at the start",
                                 0.0, 0.9)
    speed_mps: float = param(INITIAL_SPEED_MPS, "m/s", "every body's forward speed at the start", -2.0, 3.0)
    cpg_phase_rad: float = param(
        0.0, "rad", "the CPG phase gamma the first swing starts from (not printed: 0 starts a whole half-cycle)",
        0.0, math.pi)


@dataclass(frozen=True)
class TorqueFreeWindow(Validated):
    """Swing-hip torque is exactly zero from start_s to end_s after each step start T_n.

    end_s <= start_s means no window (the paper's convention t2 <= t1)."""

    start_s: float = param(0.0, "s", "t1: the hip's torque is zero from this long after each step's start",
                           0.0, 10.0)
    end_s: float = param(0.0, "s", "t2: until this long after it (t2 <= t1: no window)", 0.0, 10.0)
    # Step 0 is the initiation (from the initial state to the first touchdown T_1); the paper's controller,
    # and so its torque-free period, is about the maintenance phase that follows.
    first_step: int = param(1, "1", "the window acts from this step on (0: the initiation too)", 0, None)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not isinstance(self.first_step, int) or isinstance(self.first_step, bool) or self.first_step < 0:
            raise ParameterError(f"TorqueFreeWindow.first_step must be an integer >= 0, got {self.first_step!r}")

    @property
    def active(self) -> bool:
        return self.end_s > self.start_s


@dataclass(frozen=True)
class Push(Validated):
    """A horizontal force on the torso (N, + forward) from start_s for duration_s."""

    force_n: float = param(0.0, "N", "the push's horizontal force on the torso (+ forward)", -1000.0, 1000.0)
    start_s: float = param(0.4, "s", "when the push starts (episode time)", 0.0, None)
    duration_s: float = param(0.1, "s", "how long it lasts", 0.0, 10.0)


@dataclass(frozen=True)
class Ground(Validated):
    """Ground: level (slope 0), tilted everywhere, or level up to level_length_m then tilted.

    slope_rad > 0 ascends in +x. A piecewise ground (level_length_m set) must ascend."""

    slope_rad: float = param(0.0, "rad", "the ground's slope (> 0 ascends in +x)", -0.3, 0.3)
    level_length_m: float | None = param(None, "m", "level ground for this long, then the slope (None: the "
                                         "slope everywhere)", 0.0, 1000.0)
    friction: float = param(1.0, "1", "the ground's Coulomb friction coefficient", 0.05, 5.0)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.level_length_m is not None:
            if self.slope_rad < 0:
                raise ParameterError(
                    f"Ground.slope_rad = {self.slope_rad!r}: a level-then-slope ground must ascend (>= 0)"
                )

    def height(self, x: float) -> float:
        """Ground height (m) at horizontal position x (m)."""
        if self.level_length_m is None:
            return x * math.tan(self.slope_rad)
        return max(0.0, (x - self.level_length_m) * math.tan(self.slope_rad))

    def slope_at(self, x: float) -> float:
        """Local ground angle (rad) at x."""
        if self.level_length_m is None or x >= self.level_length_m:
            return self.slope_rad
        return 0.0

    def normal(self, x: float) -> tuple[float, float]:
        """Upward unit normal (n_x, n_z) of the surface at x (in the sagittal x-z plane)."""
        s = self.slope_at(x)
        return (-math.sin(s), math.cos(s))


@dataclass(frozen=True)
class SimulationParams(Validated):
    """Plant time step, the controller's clock and episode limits.

    The controller's clock is part of the model. `control_period_s` None (the default) is the paper's reading:
    ODE's joint motors act inside every simulation step, so the controller updates at every plant step and its
    limit, as the step is refined, is a continuous controller; refining the step refines both. A number is a
    fixed-rate loop, a property of the robot ("its loop runs at 1/control_period_s Hz"): the plant step is refined
    under it, and it must be a whole multiple of the step. A record holds both the reading and the rate
    (`to_dict`: "controller_clock" and "update_period_s")."""

    time_step_s: float = param(5e-4, "s", "the plant's time step (the paper's walker's shipped step)", 1e-5, 0.02)
    control_period_s: float | None = param(
        None, "s", "the controller's update period as a fixed-rate loop (None: the controller acts at every "
        "plant step, the paper's clock)", 1e-5, 0.05)
    distance_m: float = param(10.0, "m", "the episode ends once the centre of mass has walked this far",
                              1e-3, 1e4)
    max_time_s: float = param(60.0, "s", "the episode's simulated time limit", 1e-3, 1e5)
    fall_hip_height_m: float = param(0.35, "m", "a fall: the hip below this height above the ground", 0.0, 0.6)
    fall_pitch_rad: float = param(1.0, "rad", "a fall: the torso's pitch beyond this", 0.05, math.pi)
    # SAP was chosen by measurement (benchmarks/bench.py): "similar" and "lagged" walk but are no faster, and
    # the gait falls within half a metre under "tamsi".
    contact_approximation: str = param("sap", "", "Drake's discrete contact approximation: \"sap\", \"similar\", \"lagged\" or \"tamsi\"")

    CONTACT_APPROXIMATIONS = ("sap", "similar", "lagged", "tamsi")
    # The two readings of the controller's clock, as records name them.
    PLANT_STEP_CLOCK = "plant step"
    FIXED_RATE_CLOCK = "fixed rate"

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.contact_approximation not in self.CONTACT_APPROXIMATIONS:
            raise ParameterError(
                f"SimulationParams.contact_approximation = {self.contact_approximation!r} is not one of "
                f"{list(self.CONTACT_APPROXIMATIONS)}"
            )
        if self.control_period_s is not None:
            ratio = self.control_period_s / self.time_step_s
            if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
                raise ParameterError(
                    f"SimulationParams.control_period_s = {self.control_period_s!r} must be a whole multiple "
                    f"of time_step_s = {self.time_step_s!r} (or None: the controller acts at every plant step)"
                )

    @property
    def clock(self) -> str:
        """The controller's clock: PLANT_STEP_CLOCK (the paper's reading) or FIXED_RATE_CLOCK."""
        return self.PLANT_STEP_CLOCK if self.control_period_s is None else self.FIXED_RATE_CLOCK

    @property
    def update_period_s(self) -> float:
        """The period (s) at which the controller updates: the plant step, or the fixed-rate loop's period."""
        return self.time_step_s if self.control_period_s is None else self.control_period_s

    def to_dict(self) -> dict[str, Any]:
        return {**super().to_dict(), "controller_clock": self.clock, "update_period_s": self.update_period_s}

    @classmethod
    def from_dict(cls, data: dict[str, Any] | None, where: str | None = None):
        if isinstance(data, Mapping):  # the clock's reading and rate are derived: recorded, not parameters
            data = {k: v for k, v in data.items() if k not in ("controller_clock", "update_period_s")}
        return super().from_dict(data, where)


@dataclass(frozen=True)
class ContactParams(Validated):
    """The contact between the feet and the ground: compliant point contact (or, `model` "hydroelastic", the
    foot spheres as compliant hydroelastic spheres), its physical parameters explicit.

    Each of the four foot spheres and the ground carries the same material (the model file's own values for
    these three are replaced; its friction is kept). Drake combines a pair's stiffnesses in series (k/2 for two
    equal ones) and adds their relaxation times (2 tau). The defaults are the values Drake 1.51 gives a geometry
    that names none (measured: the same walks to the last digit): 1e6 N/m per geometry (5e5 N/m for a sphere on
    the ground, where the robot's weight sinks one sphere 0.2 mm); a relaxation time of 0.1 s per geometry for
    SAP's linear dissipation; a Hunt & Crossley dissipation of 50 s/m, which the "similar", "lagged" and
    "tamsi" approximations use instead.

    `sap_near_rigid_threshold` 0 turns off SAP's near-rigid regime. At Drake's default (1.0) SAP regularises
    a contact it judges too stiff for the step by an amount that depends on the step: the contact changes when
    the step is halved and long walks do not converge (docs/RESULTS.md, "Physics with a continuous limit"). A field left None takes
    Drake's default.

    Under `model` "hydroelastic" a sphere's force grows with the square of its depth (pi E x^2) instead of
    linearly, so a touchdown that falls inside a plant step starts with almost no force wherever in the step it
    falls; its tetrahedral mesh must be fine against the spheres' 1 cm radius (at 2 mm a 0.2 mm sink carries 44 %
    of pi E x^2, at 0.5 mm 95 %), and a fine mesh costs wall time (docs/RESULTS.md). `stiffness_npm` is then
    unread."""

    stiffness_npm: float | None = param(1e6, "N/m", "point-contact stiffness of each foot sphere and the ground "
                                        "(None: Drake's default)", 1e2, 1e9)
    relaxation_time_s: float | None = param(0.1, "s", "SAP's linear dissipation, as a relaxation time (None: Drake's "
                                            "default)", 0.0, 10.0)
    hunt_crossley_dissipation_spm: float | None = param(
        50.0, "s/m", "Hunt & Crossley dissipation, used by the \"similar\", \"lagged\" and \"tamsi\" approximations "
        "(None: Drake's default)", 0.0, 1e3)
    sap_near_rigid_threshold: float = param(0.0, "1", "SAP's near-rigid threshold (0: the regime off; Drake's "
                                            "default 1)", 0.0, 10.0)
    model: str = param("point", "", 'the contact model: "point", each foot sphere a point contact of stiffness_npm; '
                       '"hydroelastic", each foot sphere a compliant hydroelastic sphere (hydroelastic_modulus_pa, '
                       'resolution_hint_m, margin_m) pressed into the rigid ground')
    hydroelastic_modulus_pa: float = param(
        3e8, "Pa", "the foot spheres' hydroelastic modulus (model \"hydroelastic\"): a sphere of radius R pressed x "
        "into the ground carries pi E x^2 (0.23 mm for half the shipped robot's weight at the default)", 1e5, 1e12)
    resolution_hint_m: float = param(
        2e-3, "m", "the foot spheres' tetrahedral mesh, its typical edge (model \"hydroelastic\"): the force "
        "follows the mesh's facets, coarser meshes walk less regularly (5 mm on the 1 cm spheres: measured)",
        1e-4, 0.05)
    margin_m: float = param(
        0.0, "m", "the foot spheres' hydroelastic margin (model \"hydroelastic\"): within it the discrete solver "
        "adds a speculative contact constraint, so a touchdown inside a plant step is met in that step (Drake "
        "recommends 0.1-1 mm; it costs wall time)", 0.0, 0.01)

    MODELS = ("point", "hydroelastic")

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.model not in self.MODELS:
            raise ParameterError(f"ContactParams.model = {self.model!r} is not one of {list(self.MODELS)}")


# What a record written before the contact was made explicit ran on: Drake's defaults for every material
# value and SAP's near-rigid regime at its default threshold.
DRAKE_DEFAULT_CONTACT = ContactParams(stiffness_npm=None, relaxation_time_s=None, hunt_crossley_dissipation_spm=None,
                                      sap_near_rigid_threshold=1.0)


def walked_the_distance(fell: bool, distance_m: float, target_m: float) -> bool:
    """Whether a walk that covered `distance_m`, falling or not, walked `target_m` (to 1 micrometre: the episode
    ends on the control period at which the centre of mass passes it). Every experiment counts walkers by this."""
    return (not fell) and distance_m >= target_m - 1e-6


def with_time_step(sim: SimulationParams, time_step_s: float, option: str = "time_step_s") -> SimulationParams:
    """`sim` at the plant step `time_step_s`, its controller's clock kept. Under the paper's clock (the
    controller at every plant step) the controller is refined with the plant. A fixed-rate loop is part of the
    robot, not a numerical knob: its period is kept, and a step that does not divide it (or is longer) is
    refused with a ParameterError naming `option`."""
    if sim.control_period_s is not None:
        ratio = sim.control_period_s / time_step_s
        if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
            raise ParameterError(f"{option} {time_step_s!r}: the controller's fixed-rate loop of "
                                 f"{sim.control_period_s!r} s is not a whole multiple of it")
    return dataclasses.replace(sim, time_step_s=time_step_s)


@dataclass(frozen=True)
class EpisodeConfig(Validated):
    """Everything one episode depends on. `EpisodeConfig()` is the paper's walker at its shipped step
    (drake_biped/gaits/paper.json: Table III's CPG, the paper's initiation, the hip as ODE's motor); our own faster
    gait is `resources.load_gait("fast_servo")`."""

    cpg: CpgParams = field(default_factory=lambda: DEFAULT_CPG)
    gait: GaitParams = field(default_factory=lambda: DEFAULT_GAIT)
    initial: InitialConditions = field(default_factory=lambda: DEFAULT_INITIAL)
    window: TorqueFreeWindow = field(default_factory=TorqueFreeWindow)
    ground: Ground = field(default_factory=Ground)
    push: Push | None = None
    sim: SimulationParams = field(default_factory=lambda: DEFAULT_SIM)
    contact: ContactParams = field(default_factory=ContactParams)
    seed: int = param(0, "1", "recorded with the result (the episode itself is deterministic)", 0, None)
    # The robot: None for the shipped model (models/biped.urdf, Table I), else a user's model file.
    model: RobotModel | None = None

    def __post_init__(self) -> None:
        if isinstance(self.model, (str, Path)):
            object.__setattr__(self, "model", RobotModel.from_file(self.model, "EpisodeConfig.model"))
        elif isinstance(self.model, Mapping):
            object.__setattr__(self, "model", RobotModel.from_dict(self.model, "EpisodeConfig.model"))
        elif self.model is not None and not isinstance(self.model, RobotModel):
            raise ParameterError(f"EpisodeConfig.model must be a model file's path or a RobotModel, got "
                                 f"{type(self.model).__name__}")
        super().__post_init__()
        if self.push is not None and self.push.force_n != 0.0 and self.push.duration_s == 0.0:
            raise ParameterError(f"Push.duration_s = 0.0 with force_n {self.push.force_n!r}: the push would never "
                                 "act; give a duration, or no push")
        if self.push is not None and self.push.force_n != 0.0 and self.push.start_s >= self.sim.max_time_s:
            raise ParameterError(f"Push.start_s = {self.push.start_s!r} is at or after the time limit "
                                 f"sim.max_time_s = {self.sim.max_time_s!r}: the push would never act")
        if (self.gait.hip_drive == "motor" and self.gait.motor_solve == "plant"
                and self.sim.control_period_s is not None and self.sim.control_period_s != self.sim.time_step_s):
            raise ParameterError(f"sim.control_period_s = {self.sim.control_period_s!r} with the plant's hip motor "
                                 "(gait.motor_solve 'plant'): its torque acts at every plant step and is counted "
                                 "at each update, so the controller must update at the plant step (None)")

    def to_dict(self) -> dict[str, Any]:
        """The record of this configuration: each section as its own `to_dict` gives it (the simulation's with
        the controller's clock), the seed, and the model's record or None."""
        return {f.name: (v.to_dict() if hasattr(v, "to_dict") else v)
                for f in fields(self) for v in (getattr(self, f.name),)}

    def as_walked(self) -> EpisodeConfig:
        """This configuration as the walk sees it: a window that never opens (t2 <= t1), a push of no force or
        no duration, a level stretch before a level ground, the seed (no episode draws on it) put in their
        one no-op form, and the gait's fields its readings leave unread at their defaults (`GaitParams.unread`:
        the servo's gains under the hip motor, the motor's limit under the servo). Two configurations whose
        `as_walked()` are equal walk the same episode: what a sweep, a grid axis or an option that changes
        nothing is told by."""
        window = self.window if self.window.active else TorqueFreeWindow(first_step=TorqueFreeWindow().first_step)
        push = self.push if (self.push is not None and self.push.force_n != 0.0 and self.push.duration_s > 0.0
                             and self.push.start_s < self.sim.max_time_s) else None
        ground = self.ground
        if ground.slope_rad == 0.0 and ground.level_length_m is not None:
            ground = dataclasses.replace(ground, level_length_m=None)
        return dataclasses.replace(self, window=window, push=push, ground=ground, gait=self.gait.as_walked(), seed=0)

    def replace(self, **changes: Any) -> EpisodeConfig:
        """A copy with whole sections (or the seed) replaced: `config.replace(window=TorqueFreeWindow(0.2, 0.5))`."""
        return dataclasses.replace(self, **changes)

    @classmethod
    def from_dict(cls, data: dict[str, Any] | None, where: str | None = None,
                  base: EpisodeConfig | None = None) -> EpisodeConfig:
        """A configuration from a mapping of its sections (a parameter file, a record's "config"); each
        section's missing fields are `base`'s (default `EpisodeConfig()`, the paper's walker; a record's reader
        gives its own), so that {"gait": {"torso_kd": 12}} is that gait with one gain changed. A gait file's
        "about" and "compare_window" are text and the window it is compared with, not parameters."""
        if isinstance(data, Mapping):
            data = {k: v for k, v in data.items() if k not in ("about", "compare_window")}
        return super().from_dict(data, where, base if base is not None else cls())

    def override(self, values: Mapping[str, Any], sampled: bool = False) -> EpisodeConfig:
        """A copy with single fields changed, named `section.field` (`"cpg.u_a"`, `"gait.torso_pitch_rad"`,
        `"sim.distance_m"`) or by a short name of `SHORT_NAMES` (`"u_a"`, `"kappa"`, `"t1"`, ...): the
        names the grid specs use. Applied in order; each section is validated once it is rebuilt, and the
        values given are held to the rules that join fields (`check_given`: a window that never opens, a field
        the gait leaves unread), unless `sampled`: the points a sweep or a search sets one by one, where
        t2 <= t1 is the paper's "no window" for that point and an unread gain is walked as the gait reads it.
        `EpisodeConfig().override({"u_a": 1.8, "window.end_s": 0.5})`"""
        if not isinstance(values, Mapping):
            shown = repr(values) if len(repr(values)) <= 60 else repr(values)[:57] + "..."
            raise ParameterError(f"EpisodeConfig.override: values must be a mapping of field names to values "
                                 f"({{'u_a': 1.8}}), got {type(values).__name__} {shown}")
        if not isinstance(sampled, bool):
            raise ParameterError(f"EpisodeConfig.override: sampled must be a bool, got {_shown(sampled)}")
        sections: dict[str, dict[str, Any]] = {}
        given: dict[str, str] = {}
        seed = self.seed
        for name, value in values.items():
            if name == "seed":  # the one field outside the sections
                seed = value
                continue
            section, attr = resolve_field(name)
            if section not in sections:
                current = getattr(self, section)
                sections[section] = (current or _SECTIONS[section]()).to_dict()
            sections[section][attr] = value
            given[f"{section}.{attr}"] = str(name)
        config = self.replace(seed=seed, **{k: _SECTIONS[k].from_dict(v) for k, v in sections.items()})
        if not sampled:
            check_given(config, given, "EpisodeConfig.override")
        return config


def check_settings(settings: Any, cls: type, where: str) -> None:
    """ParameterError naming `where` unless `settings` is a `cls` (an experiment's run takes its settings
    dataclass, never a mapping or a path)."""
    if not isinstance(settings, cls):
        raise ParameterError(f"{where}: settings must be a {cls.__name__}, got {type(settings).__name__}")


def _named(name: str, value: float) -> str:
    """How a message shows a value by the name the user gave it: "--t1 0.5" for an option, "t1 = 0.5" else."""
    return f"{name} {value:g}" if name.startswith("--") else f"{name} = {value!r}"


def check_window_given(start_s: float, end_s: float, names: tuple[str, str] = ("window.start_s", "window.end_s"),
                       given: tuple[bool, bool] = (True, True), where: str = "") -> None:
    """The torque-free window's rule where a user gives t1 or t2 (a params file, `override`, --t1/--t2): a
    window that never opens (t2 <= t1) is refused, except 0 and 0, the explicit "no window"; ParameterError,
    one line naming `where` and the fields as the user named them (`names`: t1's, t2's). `given`: whether t1,
    t2 were given (the other kept its value). Learners sample windows with t2 <= t1 (the paper reads one as
    no window for that episode) and records hold them: they enter through `TorqueFreeWindow(...)`,
    `from_dict` or `override(..., sampled=True)`, which check each field alone."""
    if end_s > start_s or (start_s == 0.0 and end_s == 0.0):
        return
    prefix = f"{where}: " if where else ""
    t1, t2 = names
    if given[0] and not given[1]:
        raise ParameterError(f"{prefix}{_named(t1, start_s)} without {t2}: the window would end at {end_s:g} s, "
                             f"before it starts, and never open; give {t2} > {start_s:g} too")
    both = f"{_named(t1, start_s)}{' ' if t1.startswith('--') else ', '}{_named(t2, end_s)}"
    raise ParameterError(f"{prefix}{both}: t2 <= t1 is no torque-free window, one that never opens; give t1 < t2, "
                         "or 0 and 0 (or neither) for no window")


def check_given(config: EpisodeConfig, given: Mapping[str, str], where: str) -> None:
    """The rules that join fields, in one place, applied where a user gives values: a params file
    (`resources.load_gait`), `EpisodeConfig.override`, a command's --t1/--t2. `given`: each field the user set
    ("section.field") and the name the user wrote it by ("t1", "gait.hip_kp"). ParameterError, one line naming
    `where` and the field, for
    - a torque-free window that never opens (`check_window_given`), when t1 or t2 was given;
    - a gait field that the gait's readings leave unread (`GaitParams.unread`: the servo's gains under the hip
      motor, the motor's limit under the servo, the touchdown's phase threshold under the entrained phase)
      given another value than its default: it would change no walk.
    The per-field checks (type, bounds) are the dataclasses' own, made wherever a value enters."""
    window = config.window
    ends = ("window.start_s", "window.end_s")
    if any(n in given for n in ends):
        shorts = ("t1", "t2") if any(given.get(n) in ("t1", "t2") for n in ends) else ends
        names = (given.get(ends[0], shorts[0]), given.get(ends[1], shorts[1]))
        check_window_given(window.start_s, window.end_s, names, (ends[0] in given, ends[1] in given), where)
    gait = config.gait
    defaults = {f.name: f.default for f in fields(GaitParams)}
    unread = gait.unread()
    for dotted, name in given.items():
        section, _, attr = dotted.partition(".")
        if section != "gait" or attr not in unread or getattr(gait, attr) == defaults[attr]:
            continue
        if attr in gait.UNREAD_BY_ENTRAINED and gait.phase_reading == "entrained":
            reading, other = f"phase_reading {gait.phase_reading!r}", "phase_reading 'reset'"
        else:
            reading = f"hip_drive {gait.hip_drive!r}"
            other = "hip_drive 'motor'" if gait.hip_drive == "servo" else "hip_drive 'servo'"
        raise ParameterError(f"{where}: {name} = {getattr(gait, attr)!r} is unread under {reading} "
                             f"(GaitParams.unread), so it changes no walk; leave it out (its default is "
                             f"{defaults[attr]!r}), or give {other}")


def config_of_params(data: Any, where: str) -> EpisodeConfig:
    """The EpisodeConfig of a params file's fields (`EpisodeConfig.from_dict`: each field checked against its
    declaration), the fields the file sets held to the rules that join fields (`check_given`). A configuration
    a run wrote (`EpisodeConfig.to_dict`, whose "sim" names the controller's clock: a grid's best_params.json,
    a gait search's best_config.json) is read as a record is: its window may be a sampled point, its gait a
    search's. A shipped gait is held to the same rules as a user's file."""
    config = EpisodeConfig.from_dict(data, where)
    if isinstance(data, Mapping) and isinstance(data.get("sim"), Mapping) and "controller_clock" in data["sim"]:
        return config
    given = {f"{section}.{name}": f"{section}.{name}"
             for section, values in (data.items() if isinstance(data, Mapping) else ())
             if section in _SECTIONS and isinstance(values, Mapping) for name in values}
    check_given(config, given, where)
    return config


_SECTIONS: dict[str, type] = {
    "cpg": CpgParams,
    "gait": GaitParams,
    "initial": InitialConditions,
    "window": TorqueFreeWindow,
    "ground": Ground,
    "push": Push,
    "sim": SimulationParams,
    "contact": ContactParams,
}

# Short names of single fields: the symbols of Tables III-IV, the initiation and the torque-free window.
SHORT_NAMES = {
    "alpha": "cpg.alpha",
    "u_a": "cpg.u_a",
    "u_eta": "cpg.u_eta",
    "u_r": "cpg.u_r",
    "kappa": "cpg.kappa",
    "hip_angle": "initial.hip_angle_rad",
    "speed": "initial.speed_mps",
    "t1": "window.start_s",
    "t2": "window.end_s",
    "slope": "ground.slope_rad",
}


def resolve_field(name: str) -> tuple[str, str]:
    """(section, field) of a dotted or short field name; ParameterError naming it if there is none."""
    dotted = SHORT_NAMES.get(name, name)
    section, _, attr = str(dotted).partition(".")
    cls = _SECTIONS.get(section)
    if cls is None or attr not in {f.name for f in fields(cls)}:
        raise ParameterError(f"{name!r} is not an EpisodeConfig field; use section.field with section in "
                             f"{list(_SECTIONS)}, or one of {sorted(SHORT_NAMES)}")
    return section, attr

def _shipped_default() -> tuple[CpgParams, GaitParams, InitialConditions, SimulationParams, tuple[float, float]]:
    """The default configuration's sections, from the shipped gait file drake_biped/gaits/paper.json, the paper's
    walker (its `about` says why it exists and where it came from): its CPG (Table III), gains, initiation and
    plant step, and the window its file declares for the commands that compare a window with none."""
    import json
    from importlib import resources

    data = json.loads(resources.files("drake_biped").joinpath("gaits", "paper.json").read_text())
    where = "drake_biped/gaits/paper.json"
    window = data["compare_window"]
    return (CpgParams.from_dict(data["cpg"], f"{where}, cpg"), GaitParams.from_dict(data["gait"], f"{where}, gait"),
            InitialConditions.from_dict(data["initial"], f"{where}, initial"),
            SimulationParams.from_dict(data["sim"], f"{where}, sim"), (window["start_s"], window["end_s"]))


# The default configuration's sections: the paper's walker's. DEFAULT_WINDOW_S is the window (t1, t2) in s its gait
# file declares (`compare_window`): what every command that compares a window with none (stability, push-margin,
# basins, slope, time-step-study) takes on it where no --t1/--t2 or --policy is given. Another gait's is its own
# file's, or given (resources.gait_compare_window).
DEFAULT_CPG, DEFAULT_GAIT, DEFAULT_INITIAL, DEFAULT_SIM, DEFAULT_WINDOW_S = _shipped_default()
