"""Registries of the pluggable crank-bearing and pin models.

A model is one class (see :mod:`rvfem.solve.models` for the protocol and the built-in models). The case
reader, the command line and the report all take the list of valid names from here, so that a new
model is one class registered with :func:`register_bearing_model` / :func:`register_pin_model`
(from any module, a test module included) plus its case keys.

The built-in names are known without importing the (heavier) model module, which registers their
classes when it is imported; :func:`rvfem.solve.models.bearing_model` and
:func:`rvfem.solve.models.pin_model` look a class up by name.
"""

from __future__ import annotations

__all__ = [
    "register_bearing_model",
    "register_pin_model",
    "bearing_model_names",
    "pin_model_names",
    "registered_models",
    "builtin_model_names",
]

_BUILTIN_BEARINGS = ("rollers", "rigid_bore")
_BUILTIN_PINS = ("rigid", "hertz", "palmgren", "linear")
_BEARINGS: dict[str, type] = {}
_PINS: dict[str, type] = {}


def register_bearing_model(cls: type) -> type:
    """Class decorator: make ``cls`` available as ``crank_bearing.model = cls.name``."""
    _BEARINGS[cls.name] = cls
    return cls


def register_pin_model(cls: type) -> type:
    """Class decorator: make ``cls`` available as ``pins.model = cls.name``."""
    _PINS[cls.name] = cls
    return cls


def bearing_model_names() -> tuple[str, ...]:
    """Valid values of ``crank_bearing.model``."""
    return tuple(dict.fromkeys([*_BUILTIN_BEARINGS, *_BEARINGS]))


def pin_model_names(*, case_file: bool = True) -> tuple[str, ...]:
    """Valid values of ``pins.model`` (every registered pin model; ``case_file`` is kept for
    callers of earlier versions, where it hid the linear model from case files)."""
    return tuple(dict.fromkeys([*_BUILTIN_PINS, *_PINS]))


def registered_models(kind: str) -> dict[str, type]:
    """The registered model classes of a kind (``"bearing"`` or ``"pin"``) by name: the built-in
    ones once :mod:`rvfem.solve.models` has been imported (it registers them), and any registered
    since. The solver looks a model up with :func:`rvfem.solve.models.bearing_model` /
    :func:`rvfem.solve.models.pin_model`."""
    return {"bearing": _BEARINGS, "pin": _PINS}[kind]


def builtin_model_names(kind: str) -> tuple[str, ...]:
    """The names of the built-in models of a kind, known without importing the solver."""
    return tuple({"bearing": _BUILTIN_BEARINGS, "pin": _BUILTIN_PINS}[kind])
