"""The movers file: predicted moving obstacles read from and written to JSON or YAML.

The command line (``trajopt plan --movers FILE``) and scripts that keep their predictions on
disk read them with :func:`load_movers`; :func:`save_movers` writes the same format. The file
is a mapping with one key, ``movers``, holding a list (a bare list is read too); each entry
is one :class:`~trajopt.moving.MovingObstacle`, in either of its two forms:

* waypoints (:meth:`MovingObstacle.from_waypoints`): ``times`` (s, the trajectory's clock),
  ``positions`` (m, one ``[x, y]`` per time), optional ``headings`` (rad, one per time);
* constant velocity (:meth:`MovingObstacle.constant_velocity`): ``position`` (m, at
  ``t = 0``), ``velocity`` (m/s), ``horizon`` (s), optional ``heading`` (rad);

and in both: ``radius`` (m; a disc's radius or a polygon's rounding), optional ``growth``
(m/s), ``vertices`` (a convex polygon in the mover's frame, m, one ``[x, y]`` per vertex)
and ``name`` (default ``mover <index>``). For example (YAML)::

    movers:
      - name: walker
        radius: 0.25
        times: [0.0, 4.0, 9.0]
        positions: [[1.0, 2.0], [3.0, 2.0], [3.0, 5.0]]
      - name: cart
        radius: 0.05
        position: [6.0, 1.0]
        velocity: [-0.4, 0.0]
        horizon: 10.0
        vertices: [[-0.5, -0.3], [0.5, -0.3], [0.5, 0.3], [-0.5, 0.3]]

Written by hand: the format is this library's own (a mover's fields), read with the standard
library's ``json`` and PyYAML.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import yaml

from trajopt.errors import InvalidInputError
from trajopt.moving._obstacle import MovingObstacle

__all__ = ["load_movers", "movers_from_data", "movers_to_data", "save_movers"]

_COMMON = {"name", "radius", "growth", "vertices"}
_WAYPOINTS = {"times", "positions", "headings"}
_VELOCITY = {"position", "velocity", "horizon", "heading"}
_SUFFIXES = (".json", ".yaml", ".yml")


def movers_from_data(data: object, source: str = "movers") -> list[MovingObstacle]:
    """Build the movers of a parsed movers file (a mapping with ``movers``, or a list).

    Parameters
    ----------
    data : dict or list
        The parsed file: ``{"movers": [entry, ...]}`` or ``[entry, ...]``; each entry a
        mapping of the fields in this module's description.
    source : str
        Named in errors (the file's path).

    Returns
    -------
    list of MovingObstacle
        In the file's order.

    Raises
    ------
    InvalidInputError
        The layout is not a list of mappings; an entry mixes the two forms, lacks a required
        field or has an unknown one; or a field breaks a rule of :class:`MovingObstacle`
        (the message names the entry, the field and the value).
    """
    if isinstance(data, dict):
        extra = sorted(set(data) - {"movers"})
        if extra:
            raise InvalidInputError(
                f"{source}: unknown top-level keys {extra}; the file holds one key, 'movers'"
            )
        data = data.get("movers")
    if not isinstance(data, list):
        raise InvalidInputError(
            f"{source}: 'movers' must be a list of movers, got {type(data).__name__}"
        )
    return [_entry(i, item, source) for i, item in enumerate(data)]


def _entry(i: int, item: object, source: str) -> MovingObstacle:
    """Build the mover of entry ``i`` (its form told by its keys)."""
    where = f"{source}: mover {i}"
    if not isinstance(item, dict):
        raise InvalidInputError(f"{where} must be a mapping of fields, got {item!r}")
    keys = set(item)
    unknown = sorted(keys - _COMMON - _WAYPOINTS - _VELOCITY)
    if unknown:
        raise InvalidInputError(
            f"{where}: unknown fields {unknown}; allowed: {sorted(_COMMON | _WAYPOINTS)} "
            f"(waypoints) or {sorted(_COMMON | _VELOCITY)} (constant velocity)"
        )
    waypoints, velocity = keys & _WAYPOINTS, keys & _VELOCITY
    if waypoints and velocity:
        raise InvalidInputError(
            f"{where} mixes waypoint fields {sorted(waypoints)} with constant-velocity "
            f"fields {sorted(velocity)}; give one form"
        )
    required = {"times", "positions"} if not velocity else {"position", "velocity", "horizon"}
    missing = sorted((required | {"radius"}) - keys)
    if missing:
        raise InvalidInputError(f"{where} lacks the fields {missing}")
    common = {
        "radius": item["radius"],
        "growth": item.get("growth", 0.0),
        "vertices": item.get("vertices"),
        "name": item.get("name", f"mover {i}"),
    }
    _number(where, "radius", common["radius"])
    _number(where, "growth", common["growth"])
    try:
        if velocity:
            _number(where, "horizon", item["horizon"])
            if item.get("heading") is not None:
                _number(where, "heading", item["heading"])
            return MovingObstacle.constant_velocity(
                item["position"],
                item["velocity"],
                horizon=float(item["horizon"]),
                heading=None if item.get("heading") is None else float(item["heading"]),
                **common,
            )
        return MovingObstacle.from_waypoints(
            item["times"], item["positions"], headings=item.get("headings"), **common
        )
    except (TypeError, ValueError) as exc:  # a field numpy cannot read as numbers
        raise InvalidInputError(
            f"{where} ({common['name']!r}): fields must be numeric: {exc}"
        ) from None


def _number(where: str, field: str, value: object) -> None:
    """Refuse a field that is not a real number (a string, a list, a bool)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InvalidInputError(f"{where}: field {field!r} must be a number, got {value!r}")


def load_movers(path: str | os.PathLike) -> list[MovingObstacle]:
    """Read predicted movers from a JSON or YAML movers file.

    Parameters
    ----------
    path : str or path-like
        A ``.json``, ``.yaml`` or ``.yml`` file in the format of this module's description.

    Returns
    -------
    list of MovingObstacle

    Raises
    ------
    InvalidInputError
        The file is missing, has another suffix, does not parse, or holds an invalid mover
        (see :func:`movers_from_data`).
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in _SUFFIXES:
        raise InvalidInputError(f"movers file must end in .json, .yaml or .yml, got {str(p)!r}")
    try:
        text = p.read_text()
    except OSError as exc:
        raise InvalidInputError(f"movers file {str(p)!r} cannot be read: {exc}") from None
    try:
        data = json.loads(text) if suffix == ".json" else yaml.safe_load(text)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise InvalidInputError(f"movers file {str(p)!r} does not parse: {exc}") from None
    return movers_from_data(data, source=str(p))


def movers_to_data(movers: Sequence[MovingObstacle]) -> dict[str, Any]:
    """Return the movers file's content for ``movers`` (waypoint form, plain lists, floats).

    Parameters
    ----------
    movers : sequence of MovingObstacle

    Returns
    -------
    dict
        ``{"movers": [...]}``; :func:`movers_from_data` of it rebuilds equal movers.
    """
    out = []
    for m in movers:
        if not isinstance(m, MovingObstacle):
            raise InvalidInputError(f"movers must be MovingObstacle, got {type(m).__name__}")
        entry: dict[str, Any] = {
            "name": m.name,
            "radius": float(m.radius),
            "growth": float(m.growth),
            "times": m.times.tolist(),
            "positions": m.positions.tolist(),
            "headings": m.headings.tolist(),
        }
        if m.vertices is not None:
            entry["vertices"] = m.vertices.tolist()
        out.append(entry)
    return {"movers": out}


def save_movers(path: str | os.PathLike, movers: Sequence[MovingObstacle]) -> Path:
    """Write ``movers`` to a JSON or YAML movers file (by its suffix); returns the path.

    Parameters
    ----------
    path : str or path-like
        A ``.json``, ``.yaml`` or ``.yml`` file; overwritten.
    movers : sequence of MovingObstacle
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in _SUFFIXES:
        raise InvalidInputError(f"movers file must end in .json, .yaml or .yml, got {str(p)!r}")
    data = movers_to_data(movers)
    text = json.dumps(data, indent=1) if suffix == ".json" else yaml.safe_dump(data)
    p.write_text(text)
    return p
