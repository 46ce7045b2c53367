"""Walk a robot of your own: the shipped biped with the torso 20 % heavier and the shanks 10 % longer.

    python examples/own_robot.py [--distance 10] [--out out/own_robot]

The robot is a model file (URDF or SDFormat) with the shipped model's link and joint names; the controller reads
its body (joint positions, centres of mass, foot contact spheres, masses) from the plant. Here the shipped URDF
is copied and edited: the torso's mass and inertia times 1.2; each shank's length, centre of mass, drawn box and
inertia about its end for a 10 % longer uniform bar. Both robots walk the paper's walker from its
initiation; the table compares them. The same from the command line:

    drake-biped walk --model out/own_robot/own_robot.urdf --out out/walk_own
"""

import xml.etree.ElementTree as ET
from pathlib import Path

import drake_biped as db
from drake_biped.analysis.cost_of_transport import format_cost
from drake_biped.cli import number, run_script, script_parser

parser = script_parser(__doc__)
parser.add_argument("--distance", type=number("positive"), default=10.0, help="each walk's length (m)")
parser.add_argument("--out", default="out/own_robot", help="folder for the edited URDF (default out/own_robot)")
args = parser.parse_args()

TORSO_MASS_FACTOR, SHANK_LENGTH_FACTOR = 1.2, 1.1


def scale_xyz(element, factor: float) -> None:
    """Scale the z of an element's xyz attribute (an origin) by `factor`."""
    x, y, z = (float(v) for v in element.get("xyz").split())
    element.set("xyz", f"{x:g} {y:g} {z * factor:.6g}")


def edited_robot(out: Path) -> Path:
    """The shipped URDF with a heavier torso and longer shanks, written to out/own_robot.urdf."""
    tree = ET.parse(db.shipped_model_file())
    root = tree.getroot()
    torso = root.find("link[@name='torso']/inertial")
    for tag, names in (("mass", ("value",)), ("inertia", ("ixx", "iyy", "izz"))):
        element = torso.find(tag)
        for name in names:
            element.set(name, f"{float(element.get(name)) * TORSO_MASS_FACTOR:.6g}")
    k = SHANK_LENGTH_FACTOR
    for leg in ("left", "right"):
        shank = root.find(f"link[@name='{leg}_shank']")
        scale_xyz(shank.find("inertial/origin"), k)
        scale_xyz(shank.find("visual/origin"), k)
        box = shank.find("visual/geometry/box")
        sx, sy, sz = (float(v) for v in box.get("size").split())
        box.set("size", f"{sx:g} {sy:g} {sz * k:.6g}")
        inertia = shank.find("inertial/inertia")
        for name in ("ixx", "iyy"):  # a uniform bar's inertia across it grows with its length squared
            inertia.set(name, f"{float(inertia.get(name)) * k * k:.6g}")
        scale_xyz(root.find(f"joint[@name='{leg}_ankle']/origin"), k)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "own_robot.urdf"
    tree.write(path)
    return path


def main() -> None:
    path = edited_robot(Path(args.out))
    base = db.EpisodeConfig().override({"sim.distance_m": args.distance,
                                        "sim.max_time_s": max(60.0, 6.0 * args.distance)})
    robots = {"shipped (Table I)": base, f"own: torso x{TORSO_MASS_FACTOR:g}, shanks x{SHANK_LENGTH_FACTOR:g}":
              base.replace(model=db.RobotModel.from_file(path))}
    print(f"wrote {path}")
    print(f"{'robot':36s} {'mass kg':>8s} {'C_mt':>7s} {'speed m/s':>9s} {'step s':>7s} {'step m':>7s}  result")
    for label, config in robots.items():
        r = db.run_episode(config)
        cmt = format_cost(r.cost_of_transport, "-")  # 4 significant digits: a heavy robot's small C_mt is not 0
        period = "-" if r.step_period_s is None else f"{r.step_period_s:.3f}"
        length = "-" if r.step_length_m is None else f"{r.step_length_m:.3f}"
        result = f"walked {r.distance_m:.2f} m" if not r.fell else f"fell at {r.distance_m:.2f} m ({r.fall_reason})"
        print(f"{label:36s} {r.mass_kg:8.3f} {cmt:>7s} {r.mean_speed_mps:9.3f} {period:>7s} {length:>7s}  {result}")


if __name__ == "__main__":
    run_script(main)
