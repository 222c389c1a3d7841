"""Registries of the pluggable crank-bearing and pin models.

A model is one class (see :mod:`rvfem.solve.models` for the protocol and the built-in models). The case
reader, the command line and the report all take the list of valid names from here, so that a new
model is one class registered with :func:`register_bearing_model` / :func:`register_pin_model`
(from any module, a test module included) plus its case keys.

The built-in names are known without importing the (heavier) model module; their classes are
imported on first use.
"""

from __future__ import annotations

import importlib

__all__ = [
    "register_bearing_model",
    "register_pin_model",
    "bearing_model_names",
    "pin_model_names",
    "bearing_model",
    "pin_model",
]

_BUILTIN_BEARINGS = {"rollers": "RollerBearing", "rigid_bore": "RigidBoreBearing"}
_BUILTIN_PINS = {"rigid": "RigidPins", "hertz": "HertzPins", "palmgren": "PalmgrenPins", "linear": "LinearPins"}
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


def _resolve(name: str, registered: dict, builtin: dict, kind: str) -> type:
    if name not in registered and name in builtin:
        # the built-in models' module, loaded by name on first use like a plugin: the case layer
        # names the models without importing the solver
        models = importlib.import_module("rvfem.solve.models")
        registered.setdefault(name, getattr(models, builtin[name]))
    try:
        return registered[name]
    except KeyError:
        known = ", ".join(dict.fromkeys([*builtin, *registered]))
        raise KeyError(f"unknown {kind} model {name!r}; known: {known}") from None


def bearing_model(name: str) -> type:
    """The class of bearing model ``name``."""
    return _resolve(name, _BEARINGS, _BUILTIN_BEARINGS, "bearing")


def pin_model(name: str) -> type:
    """The class of pin model ``name``."""
    return _resolve(name, _PINS, _BUILTIN_PINS, "pin")
