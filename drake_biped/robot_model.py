"""A robot model file given by the user (URDF or SDFormat), carried by its content in an episode's
configuration (`EpisodeConfig.model`) and in its records."""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from drake_biped.declared import ParameterError

__all__ = ["MODEL_FORMATS", "RobotModel"]

MODEL_FORMATS = {".urdf": "urdf", ".sdf": "sdf"}


@dataclass(frozen=True)
class RobotModel:
    """A robot model file given by the user (URDF or SDFormat), carried by its content: an episode on a Dask
    worker on another machine parses the same text, and a record names the file and its SHA-256.

    `package_xml`: the package.xml beside the file when there was one (its packages resolve the file's
    package:// URIs on the machine where it is found; the shipped `drake_biped` package always resolves).
    As a record (`to_dict`) it is {"name", "sha256", "format", "package_xml", "text"}; `from_dict` checks the
    text against the SHA-256."""

    name: str
    text: str
    format: str = "urdf"
    sha256: str = ""
    package_xml: str | None = None
    # The folder the file was read from: its relative file names (meshes) resolve against it.
    directory: str | None = None

    def __post_init__(self) -> None:
        if self.format not in MODEL_FORMATS.values():
            raise ParameterError(f"model {self.name!r}: format {self.format!r} is not one of "
                                 f"{sorted(MODEL_FORMATS.values())}")
        digest = hashlib.sha256(self.text.encode()).hexdigest()
        if self.sha256 and self.sha256 != digest:
            raise ParameterError(f"model {self.name!r}: its text's SHA-256 is {digest}, not the recorded "
                                 f"{self.sha256}")
        object.__setattr__(self, "sha256", digest)

    @classmethod
    def from_file(cls, path: str | Path, option: str = "--model") -> RobotModel:
        """The model in `path`; ParameterError naming `option` and the path when it is missing, unreadable or
        of another kind than .urdf or .sdf."""
        path = Path(path)
        kind = MODEL_FORMATS.get(path.suffix.lower())
        if kind is None:
            raise ParameterError(f"{option} {str(path)!r}: not a .urdf or .sdf file")
        if not path.is_file():
            raise ParameterError(f"{option} {str(path)!r}: no such file")
        try:
            text = path.read_text()
        except (OSError, UnicodeDecodeError) as exc:
            raise ParameterError(f"{option} {str(path)!r}: cannot be read ({exc})") from None
        beside = path.resolve().parent / "package.xml"
        return cls(path.name, text, kind, package_xml=str(beside) if beside.is_file() else None,
                   directory=str(path.resolve().parent))

    @classmethod
    def from_dict(cls, data: Any, where: str = "model") -> RobotModel:
        if not isinstance(data, Mapping) or not isinstance(data.get("text"), str) or \
                not isinstance(data.get("name"), str):
            raise ParameterError(f"{where}: expected a model file's path or a record with its name and text, "
                                 f"got {type(data).__name__}")
        unknown = sorted(set(data) - {f.name for f in fields(cls)})
        if unknown:
            raise ParameterError(f"{where}: unknown field(s) {unknown}")
        return cls(**data)

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "sha256": self.sha256, "format": self.format, "package_xml": self.package_xml,
                "directory": self.directory, "text": self.text}
