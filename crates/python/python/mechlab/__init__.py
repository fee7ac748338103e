"""mechlab from Python: the models of ``models/`` (Lagrangians derived at
build time) and their analyses, NumPy arrays in and out.

    >>> import mechlab
    >>> m = mechlab.model("kapitza")
    >>> m.parameters                      # defaults, by name
    >>> m.derivations                     # text and LaTeX (rendered in Jupyter)
    >>> y = m.integrate([0.5, 0.0], t, params={"A": 2.0})
    >>> s = m.stability()                 # thresholds a*, exact windows
    >>> s.equilibria[0].a_star

Every analysis returns a :class:`Result`: its summary (the fields a scene
writes to ``summary.json``) with attribute access, and its per-point data
as NumPy arrays. Errors carry the library's messages: a bad value is a
``ValueError``, an analysis that does not apply is :class:`Refused` (a
``ValueError``), an orbit the integrator cannot follow is
:class:`IntegrationError`. Long calls release the GIL; Ctrl-C stops a chaos
map between blocks of rows, the other analyses when they return.
"""

from __future__ import annotations

import functools
from typing import Any

from . import _native
from ._native import Derivation, Derivations, IntegrationError, Refused

__all__ = ["models", "model", "schema", "Model", "Result", "Derivation", "Derivations",
           "Refused", "IntegrationError"]


class Result(dict):
    """An analysis's result: a dict whose keys are also attributes (nested
    dicts and lists of dicts too)."""

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(f"this result has no field '{name}' (fields: {', '.join(self)})") from None

    def __dir__(self):
        return list(self) + list(super().__dir__())


def _wrap(value: Any) -> Any:
    if isinstance(value, dict):
        return Result({k: _wrap(v) for k, v in value.items()})
    if isinstance(value, list):
        return [_wrap(v) for v in value]
    return value


class Model:
    """A generated model: its name, coordinates, parameters (defaults and
    ranges), derivations, and the analyses by name."""

    def __init__(self, native: _native.Model):
        self._native = native

    def __getattr__(self, name: str) -> Any:
        attr = getattr(self._native, name)
        if callable(attr):
            @functools.wraps(attr)
            def call(*args, **kwargs):
                return _wrap(attr(*args, **kwargs))
            return call
        return attr

    def __dir__(self):
        return sorted(set(dir(self._native)) | set(super().__dir__()))

    def __repr__(self) -> str:
        return repr(self._native)

    def _repr_markdown_(self) -> str:
        rows = "\n".join(
            f"| `{n}` | {v} | {self._native.ranges[n]} | {self._native.descriptions[n]} |"
            for n, v in self._native.parameters.items())
        return (f"**{self.name}** ({self.kind}; coordinates {', '.join(self.coordinates)})\n\n"
                f"| parameter | default | range | |\n|---|---|---|---|\n{rows}")


def models() -> list[str]:
    """The names of the models (the files models/<name>.toml)."""
    return _native.models()


def model(name: str) -> Model:
    """The model ``name``; a ``ValueError`` lists the known ones."""
    return Model(_native.model(name))


def schema() -> list[Result]:
    """Every declared analysis's settings: for each, its name, what it
    computes, and each setting's name, type, default, range and help (the
    keyword arguments its method takes)."""
    return _wrap(_native.schema())
