"""The comparison table: one row of metrics per method, as text, Markdown, CSV or pandas."""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from astar.files import atomic_write
from trajopt.errors import InvalidInputError

_FLOAT_FMT = "{:.4g}"


def _fmt(v: Any) -> str:
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (float, np.floating)):
        return "nan" if math.isnan(v) else _FLOAT_FMT.format(float(v))
    if v is None:
        return ""
    return str(v)


@dataclass(frozen=True, slots=True)
class ComparisonTable:
    """Rows of metrics, one per method.

    Attributes
    ----------
    rows : tuple of Mapping
        One read-only mapping per method: ``method``, ``valid``, every
        :class:`~trajopt.metrics.PathMetrics` field, ``runtime_s`` and ``note``.
    meta : Mapping
        The inputs: ``start``, ``goal`` (m), ``robot_radius`` (m), ``w_cells``,
        ``border_occupied``, ``sample_spacing_m``, ``options``.
    paths : Mapping
        Method name -> the path object it produced (curve or points), for plotting; not
        part of equality.
    """

    rows: tuple[Mapping[str, Any], ...]
    meta: Mapping[str, Any] = field(default_factory=dict)
    paths: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)

    def __post_init__(self) -> None:
        rows = tuple(MappingProxyType(dict(r)) for r in self.rows)
        object.__setattr__(self, "rows", rows)
        object.__setattr__(self, "meta", MappingProxyType(dict(self.meta)))
        object.__setattr__(self, "paths", MappingProxyType(dict(self.paths)))

    @property
    def columns(self) -> tuple[str, ...]:
        """Column names in order (union over rows, first-seen order)."""
        cols: dict[str, None] = {}
        for r in self.rows:
            cols.update(dict.fromkeys(r))
        return tuple(cols)

    @property
    def methods(self) -> tuple[str, ...]:
        """Method names in row order."""
        return tuple(str(r["method"]) for r in self.rows)

    def row(self, method: str) -> Mapping[str, Any]:
        """Return the row of ``method`` (:class:`InvalidInputError` when absent)."""
        for r in self.rows:
            if r["method"] == method:
                return r
        raise InvalidInputError(f"method must be one of {list(self.methods)}, got {method!r}")

    def __len__(self) -> int:
        return len(self.rows)

    def to_records(self) -> list[dict[str, Any]]:
        """Return a list of plain dicts, one per method (fresh copies)."""
        return [dict(r) for r in self.rows]

    def to_text(self, *, transpose: bool = True, columns: Sequence[str] | None = None) -> str:
        """Return an aligned plain-text table.

        Parameters
        ----------
        transpose : bool
            ``True`` (default, used by ``str()``): one line per metric, one column per
            method (readable for many metrics), notes listed below the table. ``False``:
            one line per method.
        columns : sequence of str, optional
            Columns to show (default all; ``note`` is always last).
        """
        cols = [c for c in (columns or self.columns) if c != "method"]
        if "note" in cols:
            cols = [c for c in cols if c != "note"] + ["note"]
        notes: list[str] = []
        if transpose:
            if "note" in cols:
                cols.remove("note")
                notes = [f"  {r['method']}: {r['note']}" for r in self.rows if r.get("note")]
            header = ["metric", *self.methods]
            body = [[c, *(_fmt(r.get(c)) for r in self.rows)] for c in cols]
        else:
            header = ["method", *cols]
            body = [[str(r["method"]), *(_fmt(r.get(c)) for c in cols)] for r in self.rows]
        table = [header, *body]
        widths = [max(len(line[i]) for line in table) for i in range(len(header))]
        lines = []
        for j, line in enumerate(table):
            cells = [
                line[i].ljust(widths[i]) if i == 0 else line[i].rjust(widths[i])
                for i in range(len(line))
            ]
            lines.append("  ".join(cells).rstrip())
            if j == 0:
                lines.append("  ".join("-" * w for w in widths))
        if notes:
            lines += ["notes:", *notes]
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.to_text()

    def to_markdown(self) -> str:
        """Return a GitHub-flavoured Markdown table, one row per method."""
        cols = list(self.columns)

        def esc(s: str) -> str:
            return s.replace("|", "\\|")

        out = ["| " + " | ".join(esc(c) for c in cols) + " |"]
        out.append("|" + "|".join("---" for _ in cols) + "|")
        for r in self.rows:
            out.append("| " + " | ".join(esc(_fmt(r.get(c))) for c in cols) + " |")
        return "\n".join(out)

    def to_csv(self, path: str | Path) -> Path:
        """Write the records as CSV (header = columns), atomically; returns the path written.

        The file is written beside ``path`` under a temporary name and moved into place
        (:func:`astar.files.atomic_write`): readers see the old file or the new one, and a
        failed write keeps the old file. The folder of ``path`` must exist.
        """
        cols = list(self.columns)

        def write(tmp: Path) -> None:
            with tmp.open("w", newline="", encoding="utf-8") as fh:
                writer = csv.DictWriter(fh, fieldnames=cols)
                writer.writeheader()
                for r in self.rows:
                    writer.writerow(dict(r))

        return atomic_write(Path(path), write)

    def to_dataframe(self) -> Any:
        """Return a :class:`pandas.DataFrame` indexed by method (pandas imported here)."""
        try:
            import pandas as pd
        except ImportError as exc:
            raise ImportError(
                "ComparisonTable.to_dataframe needs pandas, which is not installed "
                "(pip install pandas); use to_records() for plain dicts"
            ) from exc
        return pd.DataFrame.from_records(self.to_records()).set_index("method")
