"""Data shipped inside the installed package: the robot model, the named gaits and the grid specs.

Everything is found through the package itself (`importlib.resources`), never through a path relative to
the source tree, so an installed wheel, an editable checkout and a Dask worker on another machine see the
same files. The model is loaded by `package://drake_biped/biped.urdf` once `model_package_xml()` is added to
Drake's PackageMap.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

from drake_biped.params import EpisodeConfig, ParameterError

__all__ = ["full_run_digest", "gait_about", "gait_names", "gait_path", "grid_spec_names", "grid_spec_path", "load_gait", "model_package_xml",
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


def gait_path(value: str | Path) -> Path:
    """A shipped gait by name (`climbing`, `climbing_2deg`, ...) or a parameter file by path."""
    return _named_or_path(value, "gaits", ".json", gait_names(), "--params")


def grid_spec_path(value: str | Path) -> Path:
    """A shipped grid spec by name (`slope_2deg`, ...) or a spec file by path."""
    return _named_or_path(value, "grids", ".yaml", grid_spec_names(), "--spec")


def load_gait(value: str | Path) -> EpisodeConfig:
    """The EpisodeConfig of a shipped gait (by name) or of a parameter file: EpisodeConfig fields as JSON,
    or a result record (a walk's result.json, a grid's best_params.json), whose "config" is used. Its "model"
    is a model file's path (relative to the parameter file) or a record of one (its name, SHA-256 and text)."""
    from drake_biped.records import read_json

    path = gait_path(value)
    data = read_json(path, "--params")
    if isinstance(data, dict) and "config" in data:
        data = data["config"]
    if isinstance(data, dict):
        data = {k: v for k, v in data.items() if k != "about"}  # a gait file's reasons, not a parameter
    if isinstance(data, dict) and isinstance(data.get("model"), str):
        # a model file named in a parameter file: a relative path is relative to the parameter file
        data = {**data, "model": str(Path(path).parent / data["model"])}
    return EpisodeConfig.from_dict(data, f"--params {path}")
