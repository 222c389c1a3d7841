"""The registries are complete whatever was imported first: the model names the case reader accepts,
the writers of a result folder and the roller-profile kinds, each declared in one place and tied to
what implements it."""

from __future__ import annotations

import ast
import json
import subprocess
import sys

import numpy as np
import pytest

from conftest import CASES_DIR, ROOT
from rvfem.case import registry
from rvfem.case.definition import ROLLER_PROFILE_KINDS, RollerProfile, load_case
from rvfem.case.schema import file_fields
from rvfem.evaluate import roller_slices
from rvfem.outputs import registry as writer_registry
from rvfem.solve import models  # noqa: F401  (registers the built-in model classes)


def _fresh(code: str) -> str:
    """Run ``code`` in a fresh interpreter (nothing of rvfem imported before) and return its stdout."""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout


# Models


def test_load_case_alone_accepts_every_model_name_the_solver_has_a_class_for():
    # the names `rvfem run` accepts are those the solver can look a class up for
    names = {kind: sorted(registry.registered_models(kind)) for kind in ("bearing", "pin")}
    assert set(names["bearing"]) >= {"rollers", "rigid_bore"}
    assert set(names["pin"]) >= {"rigid", "hertz", "palmgren", "linear"}
    overrides = {}
    for kind, table in (("bearing", "crank_bearing"), ("pin", "pins")):
        for name in names[kind]:
            # the keys a model needs given are stiffnesses in N/mm (1e5 N/mm lies within their bounds)
            overrides[f"{table}.model={name}"] = [f"{table}.model={name}"] + [
                f"{table}.{key}=1e5" for key in registry.model_requires(kind, name)]
    code = f"""
import json, sys
from rvfem.case.definition import load_case
models = {{}}
for key, given in {overrides!r}.items():
    case = load_case({str(CASES_DIR / 'rv40e.toml')!r}, given)
    models[key] = [case.crank_bearing.model, case.pins.model]
print(json.dumps({{"models": models, "solver imported": "rvfem.solve.models" in sys.modules}}))
"""
    out = json.loads(_fresh(code))
    assert not out["solver imported"]        # the case layer validated alone
    assert len(out["models"]) == len(names["bearing"]) + len(names["pin"])
    for key, (bearing, pin) in out["models"].items():
        assert key.split("=")[1] == (bearing if key.startswith("crank_bearing.") else pin)


def test_every_model_of_the_package_is_declared_and_every_declared_name_has_its_class():
    for kind in ("bearing", "pin"):
        own = {name for name, cls in registry.registered_models(kind).items() if cls.__module__.startswith("rvfem.")}
        assert own == set(registry.builtin_model_names(kind))


def test_a_model_of_the_package_with_an_undeclared_name_is_refused_when_registered(registries):
    stray = type("StrayPins", (), {"name": "stray", "__module__": "rvfem.solve.stray"})
    with pytest.raises(ValueError, match="'stray' is rvfem's own but not declared in rvfem.case.registry.BUILTIN_MODELS"):
        registry.register_pin_model(stray)
    outside = type("OutsidePins", (), {"name": "outside", "__module__": "my_notebook", "requires": ("radius",)})
    registry.register_pin_model(outside)         # a model from outside the package declares itself
    assert "outside" in registry.pin_model_names()
    assert registry.model_requires("pin", "outside") == ("radius",)


def test_the_front_door_alone_accepts_every_model_name_rvfem_run_accepts():
    """``import rvfem; rvfem.load_case(...)`` in a fresh interpreter (nothing imported but the
    front door's case reader) against the names the command line has once it is loaded: the
    solver's classes and the case reader's choices of ``rvfem run``'s own interpreter."""
    code = """
import json
import rvfem.app.cli                      # what `rvfem run` loads before it reads a case
from rvfem.case import registry
from rvfem.case.schema import file_fields
from rvfem.case.tables import CrankBearing, Pins
choices = {kind: sorted(spec.param.allowed()) for kind, cls in (("bearing", CrankBearing), ("pin", Pins))
           for spec in file_fields(cls) if spec.name == "model"}
classes = {kind: sorted(registry.registered_models(kind)) for kind in ("bearing", "pin")}
requires = {kind: {n: list(registry.model_requires(kind, n)) for n in classes[kind]} for kind in classes}
print(json.dumps({"choices": choices, "classes": classes, "requires": requires}))
"""
    run = json.loads(_fresh(code))
    assert run["choices"] == run["classes"]                 # rvfem run accepts exactly the names it can solve
    overrides = [[f"{table}.model={name}"] + [f"{table}.{key}=1e5" for key in run["requires"][kind][name]]
                 for kind, table in (("bearing", "crank_bearing"), ("pin", "pins")) for name in run["classes"][kind]]
    code = f"""
import json, sys
import rvfem
read = [[c.crank_bearing.model, c.pins.model] for c in
        (rvfem.load_case({str(CASES_DIR / 'rv40e.toml')!r}, given) for given in {overrides!r})]
print(json.dumps({{"read": read, "solver imported": any(m.startswith("rvfem.solve") for m in sys.modules)}}))
"""
    out = json.loads(_fresh(code))
    assert not out["solver imported"]
    names = run["classes"]["bearing"] + run["classes"]["pin"]
    assert [b if i < len(run["classes"]["bearing"]) else p for i, (b, p) in enumerate(out["read"])] == names


# Tables of stage components


def test_a_component_table_is_refused_where_it_would_clash_or_cannot_be_read(registries):
    from dataclasses import dataclass

    from rvfem.case.definition import Pins, component_tables, register_component_table
    from rvfem.case.schema import param

    @dataclass(frozen=True)
    class Spring:
        stiffness: float = param(unit="N·mm/rad", low=0.0, low_open=True, doc="stiffness")

    @dataclass(frozen=True)
    class Undeclared:
        stiffness: float = 1.0

    with pytest.raises(ValueError, match="'pins' is a table of the case format already"):
        register_component_table("pins", Spring, owner="x")
    with pytest.raises(ValueError, match="'fan_holes' is a table of the case format already"):
        register_component_table("fan_holes", Spring, owner="x")
    with pytest.raises(TypeError, match="is not declared with rvfem.case.schema.param"):
        register_component_table("spring", Undeclared, owner="x")
    with pytest.raises(ValueError, match="every key needs a default; stiffness has none"):
        register_component_table("spring", Spring, by_default=True, owner="x")
    register_component_table("spring", Spring, owner="x")
    with pytest.raises(ValueError, match="registered by the component 'x' already"):
        register_component_table("spring", Pins, owner="y")
    names = [t.name for t in component_tables()]       # after the built-in components' own tables
    assert names[-1] == "spring" and names.count("spring") == 1


def test_a_component_table_there_by_default_is_read_with_its_defaults(registries, tmp_path):
    from dataclasses import dataclass

    from rvfem.case.definition import case_to_dict, register_component_table
    from rvfem.case.schema import param

    @dataclass(frozen=True)
    class Seats:
        groove_radius: float = param(6.0, unit="mm", low=0.0, low_open=True, doc="groove radius")

    register_component_table("seats", Seats, by_default=True, owner="pin seats")
    case = load_case(CASES_DIR / "rv40e.toml")
    assert case.component_table("seats") == Seats()
    assert case_to_dict(case)["seats"] == {"groove_radius": 6.0}
    assert load_case(CASES_DIR / "rv40e.toml", ["seats.groove_radius=7.5"]).component_table("seats") == Seats(7.5)
    from rvfem.errors import CaseError
    with pytest.raises(CaseError, match="'seats.groove' is not a known key"):
        load_case(CASES_DIR / "rv40e.toml", ["seats.groove=7.5"])


def test_a_declared_required_key_missing_is_named():
    from rvfem.errors import CaseError
    with pytest.raises(CaseError, match=r"'pins.linear_stiffness_N_per_mm' is missing \(required when pins.model = 'linear'\)"):
        load_case(CASES_DIR / "rv40e.toml", ["pins.model=linear"])


# Writers


def _writers_in_source() -> dict[str, str]:
    """Every writer registered by a module under rvfem/outputs (a ``@register_writer("name", …)``
    decorator), found in the source: name → module."""
    found = {}
    for path in sorted((ROOT / "rvfem" / "outputs").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", None)) == "register_writer"
                    and node.args and isinstance(node.args[0], ast.Constant)):
                found[node.args[0].value] = f"rvfem.outputs.{path.stem}"
    return found


def test_every_module_defining_a_writer_is_in_the_writer_list():
    found = _writers_in_source()
    assert {"tables", "summary", "roller_pressure_csv"} <= set(found)
    unlisted = sorted(set(found.values()) - set(writer_registry.WRITER_MODULES))
    assert not unlisted, f"writer modules missing from rvfem.outputs.registry.WRITER_MODULES: {unlisted}"


def test_the_writers_are_complete_in_a_fresh_interpreter():
    names = json.loads(_fresh("import json; from rvfem.outputs.registry import writers; "
                              "print(json.dumps([w.name for w in writers()]))"))
    assert sorted(names) == sorted(_writers_in_source())


# Roller-profile kinds


def test_every_profile_kind_the_case_accepts_has_a_drop_function():
    accepted = next(spec.param.allowed() for spec in file_fields(RollerProfile) if spec.name == "kind")
    assert set(accepted) == set(ROLLER_PROFILE_KINDS) == set(roller_slices.PROFILE_DROPS)
    length, x = 10.0, np.linspace(-5.0, 5.0, 41)
    for kind in accepted:
        case = load_case(CASES_DIR / "rv40e.toml", [f"crank_bearing.profile.kind={kind}"])
        z = roller_slices.profile_drop(case.crank_bearing.profile, length, x, composite_modulus_MPa=113000.0,
                                       reduced_radius_mm=5.0)
        # a drop below the straight generatrix: none at the centre, symmetric, growing towards the ends
        assert z[20] == 0.0 and np.all(z >= 0.0), kind
        np.testing.assert_array_equal(z, z[::-1])
        assert np.all(np.diff(z[20:]) >= 0.0), kind
        assert (z[-1] > 0.0) == (kind != "straight"), kind


def test_a_profile_kind_without_its_drop_function_fails_at_import():
    done = subprocess.run([sys.executable, "-c", "import rvfem.case.definition as d; "
                           "d.ROLLER_PROFILE_KINDS['barrel'] = (); import rvfem.evaluate.roller_slices"],
                          capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert done.returncode != 0
    assert "ImportError" in done.stderr and "barrel" in done.stderr


def test_the_report_shows_each_kind_its_own_keys():
    from rvfem.outputs.report import _PROFILE_KEYS
    for kind, keys in ROLLER_PROFILE_KINDS.items():
        others = {k for other, ks in ROLLER_PROFILE_KINDS.items() if other != kind for k in ks}
        assert set(keys) <= set(_PROFILE_KEYS[kind]) and not others & set(_PROFILE_KEYS[kind])
