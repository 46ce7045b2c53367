"""The paper's published numbers, in one place (Takita, Azuma, Shibata; tables and figures as printed).

These are targets that results are compared with, never inputs forced onto the model: the robot's masses and
lengths are read from the model file (and tested against Table I), the gait's gains come from `params`.
Imports nothing from the package.
"""

from __future__ import annotations

import math

# Table I: link lengths (m) and masses (kg) of the 7-link robot; joint ranges.
TABLE_I_LENGTHS_M = {"torso": 0.312, "thigh": 0.280, "shank": 0.317, "foot": 0.180}
TABLE_I_MASSES_KG = {"torso": 6.646, "thigh": 0.673, "shank": 0.707, "foot": 0.398}
TABLE_I_TOTAL_MASS_KG = TABLE_I_MASSES_KG["torso"] + 2 * sum(
    TABLE_I_MASSES_KG[k] for k in ("thigh", "shank", "foot")
)
HIP_LIMIT_RAD = math.radians(51.0)
ANKLE_LIMIT_RAD = math.radians(26.0)

# Table II: GARB's learning rate alpha_p as (last episode of the band, alpha_p); the last band runs on.
TABLE_II: tuple[tuple[int | None, float], ...] = ((100, 0.1), (200, 0.05), (300, 0.01), (400, 0.005), (None, 0.001))

# Table III: the CPG parameters of eq. 2-3 the paper walks with.
TABLE_III = {"alpha": 1.0, "u_a": 2.0, "u_eta": 0.0, "u_r": 2.1, "kappa": 1.8}

# Table IV: the grid search's ranges of the CPG parameters.
TABLE_IV: dict[str, tuple[float, float]] = {
    "alpha": (-2.0, 2.0),
    "u_a": (0.0, 3.0),
    "u_eta": (-1.0, 1.0),
    "u_r": (0.0, 3.0),
    "kappa": (0.0, 2.0),
}

# Table V: cost of transport (dimensionless, as Collins et al. 2005).
TABLE_V = {"ASIMO": 1.60, "CPG without torque-free period": 0.58, "CPG with torque-free period": 0.29,
           "human": 0.05}
# The reduction of C_mt the torque-free period gives in Table V: 1 - 0.29 / 0.58 = 50 %.
TABLE_V_REDUCTION = 1.0 - TABLE_V["CPG with torque-free period"] / TABLE_V["CPG without torque-free period"]

# Table VI: eigenvalues of the 2-D return map of (hip angle, hip rate), as (real, imaginary) pairs.
TABLE_VI: dict[str, dict[str, list[tuple[float, float]]]] = {
    "without": {"undisturbed": [(0.064, 0.101), (0.064, -0.101)],
                "forward": [(0.318, 0.0), (-0.234, 0.0)],
                "backward": [(0.378, 0.0), (-0.109, 0.0)]},
    "with": {"undisturbed": [(-0.200, 0.0), (0.129, 0.0)],
             "forward": [(0.140, 0.164), (0.140, -0.164)],
             "backward": [(0.326, 0.0), (0.0345, 0.0)]},
}

# Table VII: the CPG parameters that climb 2.0 deg, as (Table III, Table VII).
TABLE_VII = {"u_a": (2.0, 2.74), "u_r": (2.1, 2.63), "kappa": (1.8, 2.72)}

# The experiments' settings as printed.
INITIAL_HIP_ANGLE_RAD = math.radians(7.6)  # the initiation's hip angle
INITIAL_SPEED_MPS = 0.175  # the initiation's body speed
EPISODE_DISTANCE_M = 10.0  # an episode walks 10 m or falls
GARB_MEAN_S = (0.5, 0.5)  # the policy's initial mean (t1, t2)
GARB_VARIANCE_S2 = 0.04  # the policy's variance per time
GARB_BETA = 0.8  # the eligibility trace's discount
LEARNING_TRIALS = 5
LEARNING_EPISODES = 500
PUSH_FORCE_N = 20.0  # Experiment 2: 20 N forward or backward on the body
PUSH_START_S = 0.4
PUSH_DURATION_S = 0.1
SLOPE_RAD = 0.02  # Experiment 3: 2 m level, then this ascending slope
SLOPE_2DEG_RAD = math.radians(2.0)
SLOPE_LEVEL_LENGTH_M = 2.0
SLOPE_MOVING_AVERAGE = 20  # episodes, Figs. 8-11
