"""The benchmark's Parquet dataset: one folder, one file per finished chunk.

Layout of ``DIR``::

    DIR/_bench.json                  the run's settings (checked on --resume)
    DIR/part-<chunk id>.parquet      the rows of one chunk of queries, all methods
    DIR/.part-<chunk id>...tmp-<pid> a chunk being written (ignored by readers)

A chunk file is written to a temporary name and moved into place with :func:`os.replace`
(after ``fsync``), so a killed run leaves whole files only: the dataset never holds a
half-written row. Readers (pyarrow, pandas, DuckDB, ...) read the folder as one dataset;
names starting with ``.`` or ``_`` are not data. Every file has the fixed schema
:func:`schema` (:data:`COLUMNS`), one row per (query, method), keyed by ``(query_id, method)``.
"""

from __future__ import annotations

import json
import os
import socket
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from trajopt.errors import BenchmarkError

_STR, _INT, _FLT, _BOOL = "string", "int64", "float64", "bool"
#: Column name -> type, in file order.
COLUMNS: dict[str, str] = {
    # the query
    "map": _STR,
    "source": _STR,
    "query_id": _STR,
    "query_index": _INT,
    "bucket": _INT,
    "start_ix": _INT,
    "start_iy": _INT,
    "goal_ix": _INT,
    "goal_iy": _INT,
    "optimal_length_cells": _FLT,
    "radius_m": _FLT,
    "resolution_m": _FLT,
    # the method and its outcome
    "method": _STR,
    "ok": _BOOL,
    "valid": _BOOL,
    "failure": _STR,
    "note": _STR,
    # trajopt.metrics.PathMetrics
    "mse_m2": _FLT,
    "start_error_x_m": _FLT,
    "start_error_y_m": _FLT,
    "end_error_x_m": _FLT,
    "end_error_y_m": _FLT,
    "hausdorff_m": _FLT,
    "min_clearance_m": _FLT,
    "collision": _BOOL,
    "length_m": _FLT,
    "length_ratio": _FLT,
    "max_curvature_1pm": _FLT,
    "rms_curvature_1pm": _FLT,
    "int_sq_curvature_1pm": _FLT,
    "max_heading_jump_rad": _FLT,
    "sample_spacing_m": _FLT,
    "n_samples": _INT,
    # what compare adds: the fits' MSE, the timed metrics
    "fit_mse_m2": _FLT,
    "duration_s": _FLT,
    "ratio_v": _FLT,
    "ratio_a": _FLT,
    "ratio_jerk": _FLT,
    "ratio_omega": _FLT,
    "ratio_a_lat": _FLT,
    "fallback_used": _BOOL,
    "corridor": _STR,
    # the car methods (trajopt.analysis.bench._car; NaN / -1 on the other rows)
    "start_heading_rad": _FLT,
    "goal_heading_rad": _FLT,
    "turning_radius_m": _FLT,
    "cusps": _INT,
    "reverse_length_m": _FLT,
    "kappa_over_kmax": _FLT,
    "curvature_violations": _INT,
    "heading_motion_error_rad": _FLT,
    "end_heading_error_rad": _FLT,
    "cusp_speed_max_mps": _FLT,
    "rests": _INT,
    # compute times (s) and where the row was computed
    "runtime_s": _FLT,
    "reference_search_s": _FLT,
    "score_s": _FLT,
    "stage_inflate_s": _FLT,
    "stage_search_s": _FLT,
    "stage_corridor_s": _FLT,
    "stage_smooth_s": _FLT,
    "stage_timing_s": _FLT,
    "stage_fallback_s": _FLT,
    "stage_total_s": _FLT,
    "hybrid_search_s": _FLT,
    "hybrid_heuristic_s": _FLT,
    "first_solution_s": _FLT,
    "worker": _STR,
}
#: Columns that vary from run to run (wall times, the worker): every other column of a
#: row is a function of the query and the method.
TIMING_COLUMNS: tuple[str, ...] = tuple(
    c for c in COLUMNS if c.endswith("_s") and c != "duration_s"
) + ("worker",)
_CONFIG = "_bench.json"
_DEFAULTS = {_STR: "", _INT: -1, _FLT: float("nan"), _BOOL: False}


def schema() -> Any:
    """Return the dataset's :class:`pyarrow.Schema` (:data:`COLUMNS`)."""
    import pyarrow as pa

    types = {_STR: pa.string(), _INT: pa.int64(), _FLT: pa.float64(), _BOOL: pa.bool_()}
    return pa.schema([(c, types[t]) for c, t in COLUMNS.items()])


def _normalize(row: Mapping[str, Any], worker: str) -> dict[str, Any]:
    out = {}
    for col, typ in COLUMNS.items():
        v = row.get(col, _DEFAULTS[typ])
        if v is None:
            v = _DEFAULTS[typ]
        if typ == _FLT:
            v = float(v)
        elif typ == _INT:
            v = int(v)
        elif typ == _BOOL:
            v = bool(v)
        else:
            v = str(v)
        out[col] = v
    if not out["worker"]:
        out["worker"] = worker
    return out


def part_files(out: str | os.PathLike[str]) -> list[Path]:
    """Return the finished chunk files of a dataset folder, sorted by name."""
    d = Path(out)
    return sorted(p for p in d.glob("part-*.parquet") if p.is_file()) if d.is_dir() else []


def write_chunk(
    out: str | os.PathLike[str], chunk_id: str, rows: Sequence[Mapping[str, Any]]
) -> Path:
    """Write one chunk's rows atomically to ``out/part-<chunk_id>.parquet``.

    Parameters
    ----------
    out : path
        The dataset folder (exists).
    chunk_id : str
        Names the file; rewriting the same chunk replaces its file (a retried chunk never
        duplicates rows).
    rows : sequence of mapping
        One mapping per (query, method); missing columns get their empty value (NaN, -1,
        ``""`` or ``False``).

    Returns
    -------
    Path
        The file written.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    d = Path(out)
    worker = f"{socket.gethostname()}:{os.getpid()}"
    table = pa.Table.from_pylist([_normalize(r, worker) for r in rows], schema=schema())
    final = d / f"part-{chunk_id}.parquet"
    tmp = d / f".part-{chunk_id}.parquet.tmp-{os.getpid()}"
    try:
        with open(tmp, "wb") as fh:
            pq.write_table(table, fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, final)
    finally:
        if tmp.exists():
            tmp.unlink()
    return final


def existing_keys(out: str | os.PathLike[str]) -> set[tuple[str, str]]:
    """Return the ``(query_id, method)`` pairs a dataset folder already holds."""
    files = part_files(out)
    if not files:
        return set()
    import pyarrow.parquet as pq

    keys: set[tuple[str, str]] = set()
    for f in files:
        t = pq.read_table(f, columns=["query_id", "method"])
        keys.update(
            zip(t.column("query_id").to_pylist(), t.column("method").to_pylist(), strict=True)
        )
    return keys


def read_dataset(path: str | os.PathLike[str], columns: Iterable[str] | None = None) -> Any:
    """Read a dataset folder (or one ``.parquet`` file) into a :class:`pandas.DataFrame`.

    Parameters
    ----------
    path : path
        The folder written by :func:`trajopt.bench.run` (or one of its part files).
    columns : iterable of str, optional
        Read only these columns (faster on large datasets).

    Raises
    ------
    BenchmarkError
        The path does not exist or holds no chunk file; an unknown column.
    """
    import pyarrow.parquet as pq

    p = Path(path)
    cols = None if columns is None else list(columns)
    for c in cols or ():
        if c not in COLUMNS:
            raise BenchmarkError(f"column {c!r} is not a dataset column; known: {list(COLUMNS)}")
    if p.is_file():
        files = [p]
    else:
        if not p.is_dir():
            raise BenchmarkError(f"dataset {str(p)!r} does not exist")
        files = part_files(p)
        if not files:
            raise BenchmarkError(f"dataset {str(p)!r} holds no part-*.parquet file")
    import pyarrow as pa

    tables = [pq.read_table(f, columns=cols, schema=schema()) for f in files]
    return pa.concat_tables(tables).to_pandas()


def prepare(out: str | os.PathLike[str], config: Mapping[str, Any], *, resume: bool) -> Path:
    """Create the dataset folder, or check that an existing one may be resumed.

    The folder must be new or empty unless ``resume``; when resuming, its ``_bench.json``
    must record the same robot radius per map as ``config`` (rows computed with another
    radius would be silently mixed otherwise). Leftover temporary files of a killed run
    are removed.

    Raises
    ------
    BenchmarkError
        The folder holds data and ``resume`` is False; the settings differ; ``out`` is a file.
    """
    d = Path(out)
    if d.exists() and not d.is_dir():
        raise BenchmarkError(f"--out {str(d)!r} is a file; it must be a dataset folder")
    d.mkdir(parents=True, exist_ok=True)
    cfg_path = d / _CONFIG
    has_data = bool(part_files(d)) or cfg_path.exists()
    if has_data and not resume:
        raise BenchmarkError(
            f"dataset folder {str(d)!r} already holds a run: pass resume=True (--resume) to "
            "continue it, or choose a new folder"
        )
    new = {"radius_m": dict(config.get("radius_m", {}))}
    if cfg_path.exists():
        old = json.loads(cfg_path.read_text())
        old_r = old.get("radius_m", {})
        for m, r in new["radius_m"].items():
            if m in old_r and float(old_r[m]) != float(r):
                raise BenchmarkError(
                    f"dataset {str(d)!r} was run with radius {old_r[m]} m on map {m!r}, this "
                    f"run asks for {r} m: a resumed run must use the same radius"
                )
        new["radius_m"] = {**old_r, **new["radius_m"]}
    tmp = d / f".{_CONFIG}.tmp-{os.getpid()}"
    tmp.write_text(json.dumps(new, indent=1, sort_keys=True))
    os.replace(tmp, cfg_path)
    for leftover in d.glob(".part-*.tmp-*"):
        leftover.unlink(missing_ok=True)
    return d
