"""Registries of the pluggable crank-bearing and pin models.

A model is one class (see :mod:`rvfem.solve.models` for the protocol and the built-in models). The case
reader, the command line and the report all take the list of valid names from here, so that a new
model is one class registered with :func:`register_bearing_model` / :func:`register_pin_model`
(from any module, a test module included) plus its case keys.

Two halves, one per layer:

* the **names** and what each model needs of its case table (:class:`ModelName`) are part of the
  case format, so they are declared here, once, in :data:`BUILTIN_MODELS`: the case reader knows
  every built-in name whatever was imported first (a notebook calling
  :func:`rvfem.case.definition.load_case` accepts exactly the names ``rvfem run`` accepts);
* the **classes** live in the solver (:mod:`rvfem.solve.models`), which attaches them by
  registering them when it is imported; the lookups :func:`rvfem.solve.models.bearing_model` and
  :func:`rvfem.solve.models.pin_model` live in that module, so a lookup always sees them.

Chosen over a list of modules that register, imported by the lookup through :mod:`importlib`:
that would make the case layer load the solver (numpy, scipy and the contact code) to validate a
case — an upward dependency the import contracts cannot see, and a slower ``rvfem check``. The two
halves are tied: a class of rvfem's own package registering a name not declared here is refused
when its module is imported, and the tests check that every declared name has its class.
A model registered from outside the package (a notebook, a test module) declares its required keys
itself, in a class attribute ``requires``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = [
    "ModelName",
    "BUILTIN_MODELS",
    "register_bearing_model",
    "register_pin_model",
    "bearing_model_names",
    "pin_model_names",
    "registered_models",
    "builtin_model_names",
    "model_requires",
]


@dataclass(frozen=True)
class ModelName:
    """A built-in model as the case format knows it.

    Attributes
    ----------
    name : str
        Its value of ``crank_bearing.model`` or ``pins.model``.
    requires : tuple of str
        Keys of its case table (``[crank_bearing]`` or ``[pins]``) that have no default and must be
        given with it.
    """

    name: str
    requires: tuple[str, ...] = ()


BUILTIN_MODELS: dict[str, tuple[ModelName, ...]] = {
    "bearing": (ModelName("rollers"), ModelName("rigid_bore")),
    "pin": (ModelName("rigid"), ModelName("hertz"), ModelName("palmgren"),
            ModelName("linear", requires=("linear_stiffness_N_per_mm",))),
}
"""The built-in models of each kind (``"bearing"``, ``"pin"``), the one place their names are declared;
their classes are in :mod:`rvfem.solve.models`."""

_BEARINGS: dict[str, type[Any]] = {}
_PINS: dict[str, type[Any]] = {}
_KINDS = {"bearing": _BEARINGS, "pin": _PINS}


def _register(kind: str, cls: type[Any]) -> type[Any]:
    if cls.__module__.split(".")[0] == "rvfem" and cls.name not in builtin_model_names(kind):
        raise ValueError(f"{cls.__qualname__}: the {kind} model {cls.name!r} is rvfem's own but not declared in "
                         "rvfem.case.registry.BUILTIN_MODELS; declare its name (and the keys it requires) there")
    _KINDS[kind][cls.name] = cls
    return cls


def register_bearing_model(cls: type) -> type:
    """Class decorator: make ``cls`` available as ``crank_bearing.model = cls.name``.

    Raises
    ------
    ValueError
        ``cls`` belongs to rvfem's package but its name is not declared in :data:`BUILTIN_MODELS`.
    """
    return _register("bearing", cls)


def register_pin_model(cls: type) -> type:
    """Class decorator: make ``cls`` available as ``pins.model = cls.name``.

    Raises
    ------
    ValueError
        ``cls`` belongs to rvfem's package but its name is not declared in :data:`BUILTIN_MODELS`.
    """
    return _register("pin", cls)


def bearing_model_names() -> tuple[str, ...]:
    """Valid values of ``crank_bearing.model``: the built-in ones, then any registered since."""
    return tuple(dict.fromkeys([*builtin_model_names("bearing"), *_BEARINGS]))


def pin_model_names(*, case_file: bool = True) -> tuple[str, ...]:
    """Valid values of ``pins.model`` (the built-in ones, then any registered since; ``case_file``
    is kept for callers of earlier versions, where it hid the linear model from case files)."""
    return tuple(dict.fromkeys([*builtin_model_names("pin"), *_PINS]))


def registered_models(kind: str) -> dict[str, type]:
    """The registered model classes of a kind (``"bearing"`` or ``"pin"``) by name: the built-in
    ones once :mod:`rvfem.solve.models` has been imported (it registers them), and any registered
    since. Look a model up with :func:`rvfem.solve.models.bearing_model` /
    :func:`rvfem.solve.models.pin_model`, which always see the built-in classes."""
    return _KINDS[kind]


def builtin_model_names(kind: str) -> tuple[str, ...]:
    """The names of the built-in models of a kind, known without importing the solver."""
    return tuple(m.name for m in BUILTIN_MODELS[kind])


def model_requires(kind: str, name: str) -> tuple[str, ...]:
    """The keys of its case table that the model ``name`` of ``kind`` needs given (no default):
    :attr:`ModelName.requires` of a built-in model, the class attribute ``requires`` of one
    registered from outside the package (none if it has no such attribute or is unknown)."""
    for model in BUILTIN_MODELS[kind]:
        if model.name == name:
            return model.requires
    return tuple(getattr(_KINDS[kind].get(name), "requires", ()))
