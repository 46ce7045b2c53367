"""Data shipped inside the installed package: the robot model, the named gaits and the grid specs.

Everything is found through the package itself (`importlib.resources`), never through a path relative to
the source tree, so an installed wheel, an editable checkout and a Dask worker on another machine see the
same files. The model is loaded by `package://drake_biped/biped.urdf` once `model_package_xml()` is added to
Drake's PackageMap.
"""

from __future__ import annotations

import functools
import os
from importlib import resources
from pathlib import Path

from drake_biped.legacy import config_of_record
from drake_biped.params import EpisodeConfig, ParameterError, config_of_params

__all__ = ["full_run_digest", "gait_about", "gait_compare_window", "gait_identity", "gait_names", "gait_path", "grid_spec_names", "grid_spec_path", "load_gait", "model_package_xml",
           "shipped_model_file"]


def _package_path(package: str, *parts: str) -> Path:
    # The package is installed as plain files (a wheel or an editable checkout; pydrake cannot run from a
    # zip), so its resources are files on disk.
    return Path(str(resources.files(package).joinpath(*parts)))


def model_package_xml() -> Path:
    """The `package.xml` of the `drake_biped` model package (biped.urdf beside it)."""
    return _package_path("drake_biped.models", "package.xml")


def shipped_model_file() -> Path:
    """The shipped robot's URDF (Table I): the file to copy and edit for a robot of one's own (`--model`)."""
    return _package_path("drake_biped.models", "biped.urdf")


def full_run_digest() -> dict:
    """The shipped full reproduction's verdicts and learned windows (its verdicts.json, shipped as
    drake_biped/results/full_run.json): what a quick run shows and checks beside its own numbers."""
    import json

    return json.loads(_package_path("drake_biped", "results", "full_run.json").read_text())


def gait_names() -> list[str]:
    """Names of the shipped gaits (`--params NAME`): parameter files in drake_biped/gaits/."""
    return sorted(p.stem for p in _package_path("drake_biped", "gaits").glob("*.json"))


def grid_spec_names() -> list[str]:
    """Names of the shipped grid specs (`--spec NAME`): YAML files in drake_biped/grids/."""
    return sorted(p.stem for p in _package_path("drake_biped", "grids").glob("*.yaml"))


def _named_or_path(value: str | Path, folder: str, suffix: str, names: list[str], what: str) -> Path:
    if not isinstance(value, (str, os.PathLike)):
        raise ParameterError(f"{what} {value!r}: expected a shipped name (one of {names}) or a file's path, got "
                             f"{type(value).__name__}")
    text = str(value)
    if text in names:
        return _package_path("drake_biped", folder, text + suffix)
    path = Path(value)
    if path.is_file():
        return path
    raise ParameterError(f"{what} {text!r}: neither a file nor a shipped name (one of {names})")


def gait_about(name: str) -> str:
    """Why the shipped gait `name` exists, where it came from and the claim it carries: its file's `about`."""
    import json

    return str(json.loads(gait_path(name).read_text()).get("about", ""))


def gait_compare_window(value: str | Path) -> tuple[tuple[float, float], str] | None:
    """The torque-free window (t1, t2) in s that a gait file declares for the commands that compare a window
    with none (stability, push-margin, ...), and where it comes from: its optional `compare_window`
    {"start_s", "end_s", "source"}; None where the file declares none. ParameterError naming the file and the
    field for a malformed one."""
    from drake_biped.records import read_json

    path = gait_path(value)
    data = read_json(path, "--params")
    declared = data.get("compare_window") if isinstance(data, dict) else None
    if declared is None:
        return None
    where = f"--params {path}: compare_window"
    if not isinstance(declared, dict) or set(declared) != {"start_s", "end_s", "source"}:
        raise ParameterError(f"{where} {declared!r}: expected {{\"start_s\", \"end_s\", \"source\"}}")
    t1, t2, source = declared["start_s"], declared["end_s"], declared["source"]
    if not all(isinstance(t, (int, float)) and not isinstance(t, bool) for t in (t1, t2)) or not 0 <= t1 < t2:
        raise ParameterError(f"{where}: start_s {t1!r}, end_s {t2!r}: need 0 <= start_s < end_s (s)")
    if not isinstance(source, str) or not source.strip():
        raise ParameterError(f"{where}: source {source!r}: say where the window comes from")
    return (float(t1), float(t2)), source


def gait_path(value: str | Path) -> Path:
    """A shipped gait by name (`climbing`, `climbing_2deg`, ...) or a parameter file by path."""
    return _named_or_path(value, "gaits", ".json", gait_names(), "--params")


def walker_digest(config: EpisodeConfig) -> str:
    """The SHA-256 of what makes a walker: its CPG, its gains as the controller reads them (`GaitParams.as_walked`:
    a gain its readings leave unread is no difference) and its initiation, as canonical JSON. The window, the
    ground, the plant step and the episode's limits are not the walker's."""
    import hashlib
    import json

    walker = {"cpg": config.cpg.to_dict(), "gait": config.gait.as_walked().to_dict(), "initial": config.initial.to_dict()}
    return hashlib.sha256(json.dumps(walker, sort_keys=True).encode()).hexdigest()


@functools.lru_cache(maxsize=1)
def _shipped_digests(names: tuple[str, ...]) -> dict[str, str]:
    return {walker_digest(load_gait(name)): name for name in names}


def gait_identity(config: EpisodeConfig) -> dict[str, str | None]:
    """Which gait walks `config`: {"name": the shipped gait (`--params NAME`) whose CPG, gains and initiation it
    walks, or None for another gait; "sha256": `walker_digest(config)`}. A shipped gait walked at another plant
    step, with a window or pushed is still that gait."""
    digest = walker_digest(config)
    return {"name": _shipped_digests(tuple(gait_names())).get(digest), "sha256": digest}


def gait_text(identity: dict[str, str | None] | None) -> str:
    """A gait's identity in words: "paper (sha256 1a2b3c4d5e6f)", "another gait (sha256 ...)"."""
    if not identity:
        return "a gait not recorded"
    return f"{identity.get('name') or 'another gait'} (sha256 {str(identity.get('sha256'))[:12]})"


def grid_spec_path(value: str | Path) -> Path:
    """A shipped grid spec by name (`slope_2deg`, ...) or a spec file by path."""
    return _named_or_path(value, "grids", ".yaml", grid_spec_names(), "--spec")


def load_gait(value: str | Path) -> EpisodeConfig:
    """The EpisodeConfig of a shipped gait (by name) or of a parameter file: EpisodeConfig fields as JSON,
    or a result record (a walk's result.json, a grid's best_params.json), whose "config" is used. Its "model"
    is a model file's path (relative to the parameter file) or a record of one (its name, SHA-256 and text).
    A parameter file's fields are held to the rules that join fields (`params.config_of_params`); a record's
    configuration is read as it was walked (`params.config_of_record`)."""
    from drake_biped.records import read_json

    path = gait_path(value)
    data = read_json(path, "--params")
    record = isinstance(data, dict) and "config" in data
    if record:
        data = data["config"]
    if isinstance(data, dict):
        # a gait file's reasons and the window it is compared with: not parameters of its walk
        data = {k: v for k, v in data.items() if k not in ("about", "compare_window")}
    if isinstance(data, dict) and isinstance(data.get("model"), str):
        # a model file named in a parameter file: a relative path is relative to the parameter file
        data = {**data, "model": str(Path(path).parent / data["model"])}
    if record:  # written by a run: its window may be a learner's sample, its gait any reading's full record
        return config_of_record(data, f"--params {path}")
    return config_of_params(data, f"--params {path}")
