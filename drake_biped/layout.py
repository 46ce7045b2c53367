"""Vector layouts declared once: named fields with their sizes, offsets generated from them.

A LeafSystem's discrete state is a flat vector; its layout is declared here as a table of fields, and code
outside the update reads it through named views (`layout.view(vector).cpg_phase`, `layout.rows(log,
"positive_work_j")`) instead of offset arithmetic. The update itself uses plain integer offsets taken from
the same table (`layout.offset("cpg_phase")`), since every Python call there costs real time.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Field", "VectorLayout"]


@dataclass(frozen=True)
class Field:
    """One field: its name, its number of slots, what it holds, its unit ("1" for a pure number, "" for a flag
    or a count) and its bounds (None: unbounded or not declared)."""

    name: str
    size: int
    doc: str
    unit: str = ""
    bounds: tuple[float | None, float | None] | None = None


class VectorLayout:
    """Consecutive fields of a flat vector; offsets follow from the sizes."""

    def __init__(self, name: str, fields: tuple[Field, ...]):
        self.name = name
        self.fields = tuple(fields)
        self._offsets: dict[str, int] = {}
        offset = 0
        for f in self.fields:
            if f.name in self._offsets or f.size < 1:
                raise ValueError(f"{name}: field {f.name!r} given twice or with size {f.size}")
            self._offsets[f.name] = offset
            offset += f.size
        self.size = offset
        self._by_name = {f.name: f for f in self.fields}

    def __len__(self) -> int:
        return self.size

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.fields)

    def offset(self, name: str) -> int:
        """The first slot of field `name`."""
        try:
            return self._offsets[name]
        except KeyError:
            raise KeyError(f"{self.name} has no field {name!r}; fields: {list(self._offsets)}") from None

    def slice(self, name: str) -> slice:
        start = self.offset(name)
        return slice(start, start + self._by_name[name].size)

    def view(self, vector: Any) -> LayoutView:
        """Named, read-only access to one vector of this layout (scalar fields as floats, others as arrays)."""
        values = np.asarray(vector, dtype=float)
        if values.shape != (self.size,):
            raise ValueError(f"{self.name}: expected a vector of {self.size}, got shape {values.shape}")
        return LayoutView(self, values)

    def rows(self, data: np.ndarray, name: str) -> np.ndarray:
        """Field `name` over the columns of a log (`VectorLog.data()`, shape (size, samples)): a 1-D array
        of samples for a scalar field, (samples, size) for a vector field."""
        block = np.asarray(data)[self.slice(name)]
        return block[0].copy() if self._by_name[name].size == 1 else block.T.copy()

    def markdown(self) -> str:
        """The layout as a Markdown table: slot, name, unit, bounds, meaning."""
        def bounds(f: Field) -> str:
            if f.bounds is None or f.bounds == (None, None):
                return ""
            lo, hi = f.bounds
            return f"[{'-inf' if lo is None else f'{lo:g}'}, {'inf' if hi is None else f'{hi:g}'}]"

        rows = ["| slot | name | unit | bounds | meaning |", "|---|---|---|---|---|"]
        for f in self.fields:
            slot = str(self.offset(f.name)) if f.size == 1 else f"{self.offset(f.name)}-{self.offset(f.name) + f.size - 1}"
            rows.append(f"| {slot} | `{f.name}` | {f.unit or '-'} | {bounds(f)} | {f.doc.replace('|', '/')} |")
        return "\n".join(rows) + "\n"

    def describe(self) -> str:
        """The layout as a table: offset, size, name, meaning."""
        return "\n".join(f"{self.offset(f.name):3d} {f.size:2d} {f.name:28s} {f.doc}" for f in self.fields)


class LayoutView:
    """Attribute access to the fields of one vector (see VectorLayout.view)."""

    __slots__ = ("_layout", "_values")

    def __init__(self, layout: VectorLayout, values: np.ndarray):
        self._layout = layout
        self._values = values

    def __getattr__(self, name: str):
        layout = object.__getattribute__(self, "_layout")
        values = object.__getattribute__(self, "_values")
        try:
            field = layout._by_name[name]
        except KeyError:
            raise AttributeError(f"{layout.name} has no field {name!r}") from None
        start = layout._offsets[name]
        if field.size == 1:
            return float(values[start])
        return values[start:start + field.size].copy()

    def to_dict(self) -> dict[str, Any]:
        return {name: getattr(self, name) for name in self._layout.names}

    def __repr__(self) -> str:
        return f"{self._layout.name}({', '.join(f'{k}={v!r}' for k, v in self.to_dict().items())})"
