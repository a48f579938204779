"""The registry of comparison methods.

Names, callables (or lazy ``"module:attr"`` targets) and whether :func:`trajopt.compare` runs
them by default.
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from trajopt.analysis.comparison._records import MethodFn
from trajopt.errors import InvalidInputError


@dataclass(frozen=True, slots=True)
class MethodSpec:
    """A registered method.

    Its callable or ``"module:attr"`` target, and whether it runs by default.
    """

    target: MethodFn | str
    default: bool

    def resolve(self) -> MethodFn:
        """Return the callable (a ``"module:attr"`` target is imported now)."""
        if callable(self.target):
            return self.target
        module, _, attr = self.target.partition(":")
        fn = getattr(importlib.import_module(module), attr)
        if not callable(fn):
            raise InvalidInputError(f"method target {self.target!r} is not callable")
        return fn


#: Name -> method, in registration order (the default run order).
_METHODS: dict[str, MethodSpec] = {}


def register_method(
    name: str,
    fn: MethodFn | str | None = None,
    *,
    default: bool = True,
    replace: bool = False,
) -> Any:
    """Register a comparison method (usable as a decorator when ``fn`` is omitted).

    Parameters
    ----------
    name : str
        Row name in the table (non-empty, unique unless ``replace``).
    fn : callable or str, optional
        ``fn(ctx) -> curve | points | MethodResult``, or ``"module:attr"`` imported lazily
        at the first run (keeps ``import trajopt.analysis.comparison`` light and free of cycles).
    default : bool
        Run it when :func:`compare` gets ``methods=None``.
    replace : bool
        Allow overwriting an existing registration.

    Returns
    -------
    The function (or the decorator when ``fn`` is None).
    """
    if not isinstance(name, str) or not name:
        raise InvalidInputError(f"method name must be a non-empty string, got {name!r}")

    def _add(target: MethodFn | str) -> MethodFn | str:
        if not (callable(target) or (isinstance(target, str) and ":" in target)):
            raise InvalidInputError(
                f"method {name!r} must be a callable or a 'module:attr' string, got {target!r}"
            )
        if name in _METHODS and not replace:
            raise InvalidInputError(
                f"method {name!r} is already registered (pass replace=True to overwrite)"
            )
        _METHODS[name] = MethodSpec(target, bool(default))
        return target

    if fn is None:
        return _add
    return _add(fn)


def unregister_method(name: str) -> None:
    """Remove a registered method (:class:`InvalidInputError` when unknown)."""
    if name not in _METHODS:
        raise InvalidInputError(f"method {name!r} is not registered; known: {list(_METHODS)}")
    del _METHODS[name]


def registered_methods(*, default_only: bool = False) -> tuple[str, ...]:
    """Names of the registered methods in registration order."""
    return tuple(n for n, s in _METHODS.items() if s.default or not default_only)


def resolve_method(name: str) -> MethodFn:
    """Return the callable of a registered method (imported now if registered as "module:attr").

    Raises
    ------
    InvalidInputError
        ``name`` is not registered.
    """
    return resolve_methods([name])[0][1]


def resolve_methods(
    methods: Sequence[str] | Mapping[str, MethodFn | str] | None,
) -> list[tuple[str, MethodFn]]:
    """``(name, callable)`` pairs to run for ``compare(..., methods=methods)``."""
    if methods is None:
        return [(n, _METHODS[n].resolve()) for n in registered_methods(default_only=True)]
    if isinstance(methods, Mapping):
        out = []
        for name, fn in methods.items():
            spec = MethodSpec(fn, True)
            if not (callable(fn) or (isinstance(fn, str) and ":" in fn)):
                raise InvalidInputError(
                    f"methods[{name!r}] must be a callable or 'module:attr', got {fn!r}"
                )
            out.append((str(name), spec.resolve()))
        return out
    if isinstance(methods, str):
        methods = [methods]
    out = []
    for name in methods:
        if name not in _METHODS:
            raise InvalidInputError(f"method {name!r} is not registered; known: {list(_METHODS)}")
        out.append((name, _METHODS[name].resolve()))
    return out
