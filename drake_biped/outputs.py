"""Files a walk writes: the Drake diagram as SVG/PNG, a standalone Meshcat HTML recording."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
from pydrake.systems.framework import Diagram


class GraphvizMissingError(RuntimeError):
    """The Graphviz `dot` program is not installed."""


def export_diagram(diagram: Diagram, out_dir: Path, stem: str = "diagram", max_depth: int = 2) -> list[Path]:
    """Write `stem`.dot always, and `stem`.svg / `stem`.png through Graphviz `dot`.

    Raises GraphvizMissingError (after writing the .dot file) when `dot` is not on PATH."""
    out_dir = Path(out_dir)
    dot_path = out_dir / f"{stem}.dot"
    dot_path.write_text(diagram.GetGraphvizString(max_depth=max_depth))
    dot = shutil.which("dot")
    if dot is None:
        raise GraphvizMissingError(
            f"Graphviz 'dot' is not installed, so {stem}.svg/.png were not drawn ({dot_path} was written). "
            "Install it (Debian/Ubuntu: apt-get install graphviz) and run again."
        )
    written = [dot_path]
    for fmt in ("svg", "png"):
        path = out_dir / f"{stem}.{fmt}"
        subprocess.run([dot, f"-T{fmt}", str(dot_path), "-o", str(path)], check=True, timeout=60)
        written.append(path)
    return written


def start_meshcat():
    """A headless Meshcat server on a loopback port (7000 upward)."""
    from pydrake.geometry import Meshcat, MeshcatParams

    params = MeshcatParams()
    params.host = "localhost"
    return Meshcat(params)


def write_meshcat_html(meshcat, path: Path, x_range: tuple[float, float] | None = None) -> None:
    """Publish the recording and save Meshcat's self-contained HTML page.

    x_range: the stretch of ground the walk covered (m); the camera looks at it from the side, so the
    whole walk is in view (press play under "Open Controls" > Animations to watch it)."""
    meshcat.StopRecording()
    meshcat.PublishRecording()
    if x_range is not None:
        x_mid = 0.5 * (x_range[0] + x_range[1])
        distance = 0.65 * abs(x_range[1] - x_range[0]) + 2.0
        meshcat.SetCameraPose(np.array([x_mid, -distance, 0.9]), np.array([x_mid, 0.0, 0.35]))
    Path(path).write_text(meshcat.StaticHtml())


def warn(message: str) -> None:
    print(f"drake-biped: warning: {message}", file=sys.stderr)
