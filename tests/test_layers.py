"""The package's layers (core below analysis of records, below experiments, below the CLI): every import runs downwards or within a layer, and no file imports
itself round a circle. Read from the source with `ast`, function-level imports included."""

import ast
import importlib.util
from pathlib import Path

# Layer of every module (by dotted name); a module may import modules of its own layer or lower ones.
PURE, CORE, RECORDS, EXPERIMENTS, CLI = 0, 1, 2, 3, 4
LAYERS = {
    "drake_biped.paper": PURE,
    "drake_biped.declared": PURE,
    "drake_biped.robot_model": PURE,
    "drake_biped.analysis.cost_of_transport": PURE,
    "drake_biped.analysis.reward": PURE,
    "drake_biped.analysis.return_map": PURE,
    "drake_biped.analysis.series": PURE,
    "drake_biped.analysis.long_run": PURE,
    "drake_biped.analysis.attractor": PURE,
    "drake_biped.analysis.landscape": PURE,
    "drake_biped.analysis.learner_comparison": PURE,
    "drake_biped.analysis.floquet": PURE,
    "drake_biped.analysis.rewalks": PURE,
    "drake_biped.analysis.grid_ranking": PURE,
    "drake_biped.analysis.report_text": PURE,
    "drake_biped.analysis.verdicts": PURE,
    "drake_biped.params": CORE,
    "drake_biped.legacy": CORE,
    "drake_biped.resources": CORE,
    "drake_biped.records": CORE,
    "drake_biped.versions": CORE,
    "drake_biped.api_guard": CORE,
    "drake_biped.layout": CORE,
    "drake_biped.jit": CORE,
    "drake_biped.model": CORE,
    "drake_biped.kinematics": CORE,
    "drake_biped.cpg": CORE,
    "drake_biped.gait": CORE,
    "drake_biped.control_law": CORE,
    "drake_biped.hip_motor": CORE,
    "drake_biped.control_kernel": CORE,
    "drake_biped.controller": CORE,
    "drake_biped.diagram": CORE,
    "drake_biped.episode": CORE,
    "drake_biped.analysis.figures": RECORDS,
    "drake_biped.step_map": CORE,
    "drake_biped.analysis.stability_report": RECORDS,
    "drake_biped.analysis.basins_report": RECORDS,
    "drake_biped.analysis.time_step_report": RECORDS,
    "drake_biped.analysis.bifurcation_report": RECORDS,
    "drake_biped.analysis.push_margin_report": RECORDS,
    "drake_biped.analysis.floquet_report": RECORDS,
    "drake_biped.analysis.energy": RECORDS,
    "drake_biped.analysis.energy_report": RECORDS,
    "drake_biped.analysis.reproduce_report": RECORDS,
    "drake_biped.analysis.dynamics_report": RECORDS,
    "drake_biped.analysis.report_figures": RECORDS,
    "drake_biped.experiments.rewalk": EXPERIMENTS,
    "drake_biped.learners.garb": EXPERIMENTS,
    "drake_biped.learners.cmaes": EXPERIMENTS,
    "drake_biped.learners.pgpe": EXPERIMENTS,
    "drake_biped.learners.registry": EXPERIMENTS,
    "drake_biped.learners.common": EXPERIMENTS,
    "drake_biped.learners.base": EXPERIMENTS,
    "drake_biped.cli": CLI,
    "drake_biped.__main__": CLI,
}
# Package __init__ files hold docstrings and re-exports only (drake_biped's own imports lazily).
PACKAGES = {"drake_biped", "drake_biped.analysis", "drake_biped.common", "drake_biped.experiments",
            "drake_biped.learners", "drake_biped.models"}


def modules() -> dict[str, Path]:
    """Every module of the installed package, by dotted name (the mapped analysis/ and models/ included)."""
    found = {}
    for package in PACKAGES:
        spec = importlib.util.find_spec(package)
        for folder in spec.submodule_search_locations:
            for path in Path(folder).glob("*.py"):
                name = package if path.stem == "__init__" else f"{package}.{path.stem}"
                found[name] = path
    return found


def layer(name: str) -> int:
    if name.startswith(("drake_biped.experiments.", "drake_biped.common.")):
        return EXPERIMENTS
    return LAYERS[name]


def imports(path: Path, known: set[str]) -> set[str]:
    """The package's modules that the file imports (outside `if TYPE_CHECKING:` blocks)."""
    tree = ast.parse(path.read_text())
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skip.update(id(n) for n in ast.walk(node))
    out = set()
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("drake_biped"))
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("drake_biped"):
            for a in node.names:  # `from drake_biped.experiments import walk` imports a module
                sub = f"{node.module}.{a.name}"
                out.add(sub if sub in known else node.module)
    return {m for m in out if m in known}


def graph() -> dict[str, set[str]]:
    found = modules()
    return {name: imports(path, set(found)) - {name} for name, path in found.items()}


def test_every_module_has_a_layer():
    for name in modules():
        if name not in PACKAGES:
            layer(name)  # KeyError names a module added without a layer


def test_imports_run_downwards():
    upward = []
    for name, targets in graph().items():
        if name in PACKAGES:
            continue
        for target in targets:
            if target in PACKAGES:
                if target != "drake_biped":
                    upward.append(f"{name} imports the package {target}: import its modules")
                continue
            if layer(target) > layer(name):
                upward.append(f"{name} (layer {layer(name)}) imports {target} (layer {layer(target)})")
    assert not upward, "\n".join(upward)


def test_pure_math_imports_nothing_above_it():
    for name, targets in graph().items():
        if name not in PACKAGES and layer(name) == PURE:
            assert all(layer(t) == PURE for t in targets if t not in PACKAGES), (name, targets)


def find_circles(g: dict[str, set[str]]) -> list[str]:
    """Every import circle a depth-first search meets, as "a -> b -> a"."""
    state: dict[str, int] = {}  # 1: on the current path, 2: finished
    path: list[str] = []
    circles = []

    def visit(node: str) -> None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(g.get(node, ())):
            if state.get(nxt) == 1:
                circles.append(" -> ".join(path[path.index(nxt):] + [nxt]))
            elif nxt not in state:
                visit(nxt)
        path.pop()
        state[node] = 2

    for node in sorted(g):
        if node not in state:
            visit(node)
    return circles


def test_no_import_circle():
    assert find_circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == ["a -> b -> c -> a"]
    circles = find_circles(graph())
    assert not circles, "\n".join(circles)


def test_the_layering_test_sees_the_mapped_subpackages():
    found = modules()
    assert "drake_biped.analysis.cost_of_transport" in found and "drake_biped.experiments.reproduce" in found
    # and would catch an upward import: the episode runner uses the pure C_mt, never the other way round
    g = graph()
    assert "drake_biped.analysis.cost_of_transport" in g["drake_biped.episode"]
