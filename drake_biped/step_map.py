"""The biped's full-state step map through Drake, on a smooth Poincaré section.

The section is mid-stance: the hip (the floating base's origin) passing forward over the stance ankle,
g = x_hip − x_stance_ankle crossing zero from below. It is located inside the control period by linear
interpolation of the whole discrete state between the two updates around the crossing, so the map is
continuous in the state (the touchdown, which the controller already places at sub-step accuracy, lies
between two sections, away from them).

The state on the section is everything that carries over a step, in stance/swing coordinates (so one step
maps the section to itself with the legs' roles swapped): the plant's state less the horizontal position
(the height is taken above the ground under the hip, so a uniform slope is translation-invariant too), the
controller's memory that the next updates read (CPG phase, time since the touchdown, the swing thigh's
lift-off angle, the hip integrator, and the swing travel under the integrated reading) and the six torques
held for the next plant step (the actuation group). The controller's other slots are, at mid-stance, either
bookkeeping (work integrals, centre of mass, counters) or lagged copies that the next update overwrites
before a touchdown reads them (previous joint angles, pitch, clearance and section rates): they are held at
the steady walk's values, and tests/test_floquet.py checks that the map does not depend on them.

`SectionMap(config)` evaluates the map in one process; `evaluate_task` is the same on a Dask worker.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydrake.systems.analysis import Simulator

from drake_biped import control_kernel as ctl
from drake_biped.diagram import build_diagram
from drake_biped.episode import reset_context
from drake_biped.kinematics import B_ANKLE_X, B_ANKLE_Z, B_KNEE_X, B_KNEE_Z, TABLE_I_BODY, leg_points
from drake_biped.model import JOINTS_OF_A_LEG, joint_index
from drake_biped.params import EpisodeConfig, ParameterError

POSITION_NAMES = ("pitch_rad", "stance_thigh_rad", "swing_hip_rad", "swing_knee_rad", "swing_ankle_rad")
VELOCITY_NAMES = ("pitch_rate_radps", "stance_thigh_rate_radps", "swing_hip_rate_radps", "swing_knee_rate_radps",
                  "swing_ankle_rate_radps")
CONTROLLER_NAMES = ("cpg_phase_rad", "time_since_touchdown_s", "liftoff_angle_rad", "hip_integral_rad_s")
TRAVEL_NAME = "swing_travel_rad"


def coordinate_names(config: EpisodeConfig) -> tuple[str, ...]:
    """The section state's coordinates, in order (the swing travel only under the integrated reading)."""
    travel = (TRAVEL_NAME,) if config.gait.swing_reading == "integrated" else ()
    return POSITION_NAMES + VELOCITY_NAMES + CONTROLLER_NAMES + travel


def _legs(stance_right: bool) -> tuple[list[int], list[int]]:
    """Indices (0..5, JOINT_NAMES order) of the stance leg's and the swing leg's hip, knee, ankle."""
    stance, swing = ("right", "left") if stance_right else ("left", "right")
    return ([joint_index(stance, j) for j in JOINTS_OF_A_LEG], [joint_index(swing, j) for j in JOINTS_OF_A_LEG])


def _turned(body, x_slot: int, z_slot: int, angle: float) -> tuple[float, float]:
    """d/d(angle) of a joint's offset (body[x_slot], body[z_slot]) turned by `angle` in the x-z plane: the
    (x, z) velocity of the joint per unit rate of its parent link."""
    c, s = math.cos(angle), math.sin(angle)
    return -body[x_slot] * s - body[z_slot] * c, body[x_slot] * c - body[z_slot] * s


def section_value(q: np.ndarray, stance_right: bool, body=TABLE_I_BODY) -> float:
    """g = x_base − x_stance_ankle (m), the torso frame's origin (the hips, in the shipped model) ahead of the
    stance ankle: negative after touchdown, zero at the section."""
    st = _legs(stance_right)[0]
    leg = leg_points(q[0], q[1], q[2], q[3 + st[0]], q[3 + st[1]], q[3 + st[2]], body)
    return float(q[0] - leg.ankle_x)


@dataclass
class Snapshot:
    """The diagram's discrete state at an update time: plant state (18), held torques (6), controller, and
    the plant's hip motors' held command (the "motor_command" group; None in a record written before it was
    kept, restored as the group's default)."""

    time_s: float
    plant: np.ndarray
    torques: np.ndarray
    controller: np.ndarray
    command: np.ndarray | None = None

    @property
    def stance_right(self) -> bool:
        return self.controller[ctl.STANCE_RIGHT] > 0.5

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON: a non-finite controller slot (the distance target, a lagged value not yet read) as None."""
        out = {"time_s": self.time_s, "plant": self.plant.tolist(), "torques": self.torques.tolist(),
               "controller": [float(v) if math.isfinite(v) else None for v in self.controller]}
        if self.command is not None:
            out["command"] = self.command.tolist()
        return out

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Snapshot:
        command = d.get("command")
        return cls(float(d["time_s"]), np.array(d["plant"], float), np.array(d["torques"], float),
                   np.array([math.nan if v is None else v for v in d["controller"]], float),
                   None if command is None else np.array(command, float))


class SectionMap:
    """The step map of `config`'s gait on the mid-stance section, through its own Drake diagram.

    `start(steps)` walks from the paper's initiation to the section after touchdown `steps` and returns
    its state (the start of a fixed-point search) and the snapshot that supplies the held slots; `step(z)`
    maps a section state to the next one (None when the walker falls or no section follows within
    `max_step_s`)."""

    CHUNK = 10  # control periods advanced at a time before the touchdown (no Python in between)

    def __init__(self, config: EpisodeConfig, max_step_s: float = 3.0):
        if config.ground.level_length_m is not None:
            raise ParameterError("floquet: the ground must be uniform (level or one slope); a piecewise "
                                 f"ground (level_length_m {config.ground.level_length_m!r}) has no periodic gait")
        if config.push is not None and config.push.force_n != 0.0:
            raise ParameterError("floquet: the step map is of the undisturbed gait; leave the push out")
        self.config = config
        self.names = coordinate_names(config)
        self._integrated = config.gait.swing_reading == "integrated"
        self._parts = build_diagram(config)
        self._simulator = Simulator(self._parts.diagram)
        self._dt = config.sim.update_period_s
        self._max_step_s = max_step_s
        self.template: Snapshot | None = None

    # --- coordinates -------------------------------------------------------------------------------
    def pack(self, snap: Snapshot) -> np.ndarray:
        """The section coordinates of a snapshot (stance/swing by its stance leg)."""
        st, sw = _legs(snap.stance_right)
        q, v, c = snap.plant[:9], snap.plant[9:], snap.controller
        z = [q[2], q[2] + q[3 + st[0]]] + [q[3 + i] for i in sw]
        z += [v[2], v[2] + v[3 + st[0]]] + [v[3 + i] for i in sw]
        z += [c[ctl.GAMMA], snap.time_s - c[ctl.STEP_START], c[ctl.LIFTOFF_ANGLE], c[ctl.INTEGRAL]]
        if self._integrated:
            z.append(c[ctl.TRAVEL])
        return np.array(z, dtype=float)

    def unpack(self, z: np.ndarray, template: Snapshot) -> Snapshot:
        """A snapshot at time 0 with the section state `z`; the stance foot's pose and velocity, the stance
        knee and the held slots are the template's (see the module's docstring)."""
        z = np.asarray(z, dtype=float)
        st, sw = _legs(template.stance_right)
        tq, tv = template.plant[:9], template.plant[9:]
        hip, knee, ankle = (3 + i for i in st)
        # the template's stance foot: ankle point, foot angle, and their rates
        th0, dth0 = tq[2] + tq[hip], tv[2] + tv[hip]
        sh0, dsh0 = th0 - tq[knee], dth0 - tv[knee]
        body = self._parts.body
        stance = leg_points(tq[0], tq[1], tq[2], tq[hip], tq[knee], tq[ankle], body)
        ax, az = stance.ankle_x, stance.ankle_z
        (kx0, kz0), (ax0, az0) = _turned(body, B_KNEE_X, B_KNEE_Z, th0), _turned(body, B_ANKLE_X, B_ANKLE_Z, sh0)
        dax = tv[0] + kx0 * dth0 + ax0 * dsh0
        daz = tv[1] + kz0 * dth0 + az0 * dsh0
        foot, dfoot = sh0 + tq[ankle], dsh0 + tv[ankle]
        pitch, th, dpitch, dth = z[0], z[1], z[5], z[6]
        sh, dsh = th - tq[knee], dth - tv[knee]
        plant = template.plant.copy()
        q, v = plant[:9], plant[9:]
        q[2], q[hip], q[ankle] = pitch, th - pitch, foot - sh
        leg = leg_points(0.0, 0.0, pitch, q[hip], q[knee], q[ankle], body)  # the ankle relative to the base
        q[0], q[1] = ax - leg.ankle_x, az - leg.ankle_z
        (kx, kz), (ax1, az1) = _turned(body, B_KNEE_X, B_KNEE_Z, th), _turned(body, B_ANKLE_X, B_ANKLE_Z, sh)
        v[0] = dax - kx * dth - ax1 * dsh
        v[1] = daz - kz * dth - az1 * dsh
        v[2], v[hip], v[ankle] = dpitch, dth - dpitch, dfoot - dsh
        for k, i in enumerate(sw):
            q[3 + i], v[3 + i] = z[2 + k], z[7 + k]
        c = template.controller.copy()
        c[ctl.GAMMA], c[ctl.STEP_START], c[ctl.LIFTOFF_ANGLE], c[ctl.INTEGRAL] = z[10], -z[11], z[12], z[13]
        if self._integrated:
            c[ctl.TRAVEL] = z[14]
        c[ctl.STATE_TIME] -= template.time_s
        c[ctl.TARGET_X] = math.inf
        c[ctl.DONE] = c[ctl.FALL] = 0.0
        return Snapshot(0.0, plant, template.torques.copy(), c,
                        None if template.command is None else template.command.copy())

    def section_normal(self) -> np.ndarray:
        """∇g in section coordinates at the template: with the stance knee held at the template's angle,
        g = −(THIGH sin θ + SHANK sin(θ − knee)) depends on the stance thigh's world angle θ alone."""
        if self.template is None:
            raise RuntimeError("SectionMap: call start() first")
        q = self.template.plant
        knee = q[3 + _legs(self.template.stance_right)[0][1]]
        th = self.pack(self.template)[1]
        grad = np.zeros(len(self.names))
        body = self._parts.body
        grad[1] = -(_turned(body, B_KNEE_X, B_KNEE_Z, th)[0] + _turned(body, B_ANKLE_X, B_ANKLE_Z, th - knee)[0])
        return grad

    # --- simulation --------------------------------------------------------------------------------
    def _snapshot(self) -> Snapshot:
        root = self._simulator.get_context()
        ctrl = self._parts.controller
        ctrl_ctx = ctrl.GetMyContextFromRoot(root)
        return Snapshot(root.get_time(),
                        self._parts.plant.GetPositionsAndVelocities(self._parts.plant.GetMyContextFromRoot(root)),
                        ctrl_ctx.get_discrete_state(ctrl.torque_group).value().copy(),
                        ctrl_ctx.get_discrete_state(ctrl.state_group).value().copy(),
                        ctrl_ctx.get_discrete_state(ctrl.command_group).value().copy())

    def _restore(self, snap: Snapshot) -> None:
        root = self._simulator.get_mutable_context()
        self._parts.diagram.SetDefaultContext(root)
        root.SetTime(snap.time_s)
        plant_ctx = self._parts.plant.GetMyMutableContextFromRoot(root)
        self._parts.plant.SetPositionsAndVelocities(plant_ctx, snap.plant)
        ctrl = self._parts.controller
        ctrl_ctx = ctrl.GetMyMutableContextFromRoot(root)
        ctrl.set_episode(ctrl_ctx, self.config)
        ctrl_ctx.get_mutable_discrete_state(ctrl.torque_group).SetFromVector(snap.torques)
        ctrl_ctx.get_mutable_discrete_state(ctrl.state_group).SetFromVector(snap.controller)
        if snap.command is not None:
            ctrl_ctx.get_mutable_discrete_state(ctrl.command_group).SetFromVector(snap.command)
        # The plant's hip motors take their gains and bounds from the plant's model, not from a Context: give
        # them the restored state's, as an episode's start does (else they keep the last walk's roles).
        ctrl.apply_motors(ctrl.law(ctrl_ctx), snap.controller)

    def _advance(self, k: int) -> Snapshot | None:
        """Advance to update k; None on a fall, a diverging solve or a finished distance."""
        try:
            self._simulator.AdvanceTo(k * self._dt)
        except RuntimeError:
            return None
        snap = self._snapshot()
        if snap.controller[ctl.FALL] != 0.0 or snap.controller[ctl.DONE] != 0.0:
            return None
        return snap

    def _to_section(self, touchdowns: int, k: int, limit_s: float) -> Snapshot | None:
        """From update k, run until `touchdowns` touchdowns are counted and then to the section, for at
        most `limit_s`; the snapshot interpolated there."""
        k_limit = k + int(math.ceil(limit_s / self._dt))
        snap = self._snapshot()
        while snap.controller[ctl.STEP_COUNT] < touchdowns:
            k += self.CHUNK
            snap = self._advance(k)
            if snap is None or k > k_limit:
                return None
        previous, g_prev = snap, section_value(snap.plant, snap.stance_right, self._parts.body)
        while True:
            k += 1
            snap = self._advance(k)
            if snap is None or k > k_limit:
                return None
            g = section_value(snap.plant, snap.stance_right, self._parts.body)
            if g_prev < 0.0 <= g:
                f = -g_prev / (g - g_prev)
                mix = Snapshot(
                    previous.time_s + f * (snap.time_s - previous.time_s),
                    (1 - f) * previous.plant + f * snap.plant,
                    (1 - f) * previous.torques + f * snap.torques,
                    (1 - f) * previous.controller + f * snap.controller,
                    (1 - f) * previous.command + f * snap.command,
                )
                # the slots no update changes mid-stance, copied rather than rounded by the blend
                for slot in (ctl.STANCE_RIGHT, ctl.STEP_COUNT, ctl.STEP_START):
                    mix.controller[slot] = snap.controller[slot]
                return mix
            previous, g_prev = snap, g

    def start(self, steps: int = 8) -> tuple[np.ndarray, Snapshot]:
        """Walk from the initiation to the section after touchdown `steps`; its state and snapshot (kept
        as this map's template)."""
        if not isinstance(steps, int) or steps < 1:
            raise ParameterError(f"steps {steps!r}: must be an integer >= 1")
        _, ctrl_ctx, _ = reset_context(self._parts, self._simulator, self.config)
        # walk as far as the section needs, whatever distance the episode would walk
        ctrl_ctx.get_mutable_discrete_state(self._parts.controller.state_group).SetAtIndex(ctl.TARGET_X, math.inf)
        self._simulator.Initialize()
        found = self._to_section(steps, 0, self.config.sim.max_time_s)
        if found is None:
            raise ParameterError(f"the gait does not reach the section after touchdown {steps}: it falls")
        self.template = found
        return self.pack(found), found

    def step(self, z: np.ndarray, template: Snapshot | None = None) -> np.ndarray | None:
        """The next section state from section state `z` (None: a fall, or no section within max_step_s)."""
        snap = self.trajectory(z, 1, template)
        return None if snap is None else snap[0]

    def trajectory(self, z: np.ndarray, steps: int, template: Snapshot | None = None) -> list[np.ndarray] | None:
        """The section states of the next `steps` steps from `z` (None when the walker falls first)."""
        template = template or self.template
        if template is None:
            raise RuntimeError("SectionMap: call start() first, or pass a template snapshot")
        snap = self.unpack(z, template)
        self._restore(snap)
        self._simulator.Initialize()
        out = []
        count = int(template.controller[ctl.STEP_COUNT])
        k = 0
        for n in range(1, steps + 1):
            found = self._to_section(count + n, k, self._max_step_s)
            if found is None:
                return None
            out.append(self.pack(found))
            k = int(round(self._simulator.get_context().get_time() / self._dt))
        return out


_MAPS: dict[str, SectionMap] = {}


def evaluate_task(config: dict[str, Any], template: dict[str, Any], points: list[list[float]]) -> list[list[float] | None]:
    """On a worker: the map at each point (None: a fall). The worker keeps one SectionMap per configuration."""
    key = json.dumps(config, sort_keys=True)
    if key not in _MAPS:
        _MAPS.clear()
        _MAPS[key] = SectionMap(EpisodeConfig.from_dict(config))
    section_map = _MAPS[key]
    snap = Snapshot.from_dict(template)
    out: list[list[float] | None] = []
    for p in points:
        y = section_map.step(np.array(p, dtype=float), snap)
        out.append(None if y is None else [float(v) for v in y])
    return out
