"""Shared test utilities: paths of the shipped cases, a small TOML line editor, the registries
saved and restored around a test that registers a plug-in, and the ``slow`` marker of the
end-to-end tests.

The tests mirror the package: ``tests/<layer>/test_*.py`` tests ``rvfem/<layer>`` (case, geometry,
mesh, fem, solve, evaluate, outputs, app), ``tests/end_to_end/`` runs the whole job, and the test
modules directly in ``tests/`` check the package as a whole or its top-level modules. This file
applies to every folder below it, and ``tests/`` is on ``sys.path`` (``pythonpath`` in
pyproject.toml), so a test module anywhere imports these helpers as ``from conftest import …``.
Test folders are not packages: every test module's file name is unique across the folders.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

BLAS_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
"""With parallel workers (``pytest -n N``, pytest-xdist sets ``PYTEST_XDIST_WORKER_COUNT`` before
this file is imported), each worker and the processes it starts get an equal share of the cores
for their BLAS threads unless the variables are set already: N workers of as many BLAS threads
as there are cores would oversubscribe the machine. Set before NumPy is imported."""

if int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1")) > 1:
    _share = max(1, (os.cpu_count() or 1) // int(os.environ["PYTEST_XDIST_WORKER_COUNT"]))
    for _name in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(_name, str(_share))

import numpy as np  # noqa: E402
import pytest  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CASES_DIR = ROOT / "cases"
TESTS_DIR = Path(__file__).resolve().parent
REGRESSIONS_DIR = TESTS_DIR / "regressions"
"""Case files an earlier rvfem refused (tests/solve/test_regressions.py runs each of them)."""


def documented_keys(after: str | None = None) -> set[str]:
    """Key paths of a key table of docs/outputs.md: the first ``| key | type | meaning |`` table
    (after the heading ``after``, if given). A row's backquoted names are full paths; an indented
    row (``&nbsp;``) lists keys of each object named in the row above it."""
    text = (ROOT / "docs" / "outputs.md").read_text(encoding="utf-8")
    if after is not None:
        text = text[text.index(after):]
    table = text[text.index("| key | type | meaning |"):]
    table = table[: table.index("\n\n")]
    keys: set[str] = set()
    parents: list[str] = []
    for row in table.splitlines()[2:]:
        if not row.startswith("|"):       # the end of a generated table
            break
        first = row.split("|")[1].strip()
        names = re.findall(r"`([^`]+)`", first)
        if first.startswith("&nbsp;"):
            keys.update(p + n for p in parents for n in names)
        else:
            keys.update(names)
            parents = names
    return keys


def written_keys(obj, opaque=frozenset(), prefix: str = "") -> set[str]:
    """Key paths of a JSON object; an array of objects is ``name[]`` and its entries' keys
    ``name[].key``; the objects named in ``opaque`` (keys that are names) count as one key."""
    keys = {prefix} if prefix else set()
    if prefix in opaque:
        return keys
    if isinstance(obj, dict):
        for k, v in obj.items():
            name = f"{prefix}.{k}" if prefix else k
            if isinstance(v, list) and v and isinstance(v[0], dict):
                keys.add(name + "[]")
                for entry in v:
                    keys |= written_keys(entry, opaque, name + "[]")
            else:
                keys |= written_keys(v, opaque, name)
    return keys


def coarse_case(name: str, **changes):
    """A shipped case on a coarse mesh (0.6 mm at the flanks and bores, 4 mm inside) with the given
    tables updated (``coarse_case("rv40e_solid", crank_bearing={"stiffness_law": "linear", ...})``):
    fast enough for the science-core tests."""
    from rvfem.case.definition import case_from_dict, case_to_dict, load_case

    data = case_to_dict(load_case(CASES_DIR / f"{name}.toml"))
    data["mesh"].update(size_flank=0.6, size_bore=0.6, size_interior=4.0)
    for table, values in changes.items():
        data[table].update(values)
    return case_from_dict(data, source=f"{name} (coarse)")


class CaseText:
    """Edits a case file's text line by line (keys addressed by table), for validation tests."""

    def __init__(self, text: str):
        self.lines = text.splitlines()

    @classmethod
    def shipped(cls, name: str = "rv40e") -> "CaseText":
        return cls((CASES_DIR / f"{name}.toml").read_text(encoding="utf-8"))

    def _table_span(self, table: str) -> tuple[int, int]:
        header = re.compile(r"^\s*\[\[?([^\]]+)\]\]?")
        start = 0 if table == "" else None
        for i, line in enumerate(self.lines):
            m = header.match(line)
            if m:
                if start is not None:
                    return start, i
                if m.group(1).strip() == table:
                    start = i + 1
        if start is None:
            raise KeyError(f"no table [{table}] in the case text")
        return start, len(self.lines)

    def _find(self, table: str, key: str) -> int:
        lo, hi = self._table_span(table)
        pattern = re.compile(rf"^\s*{re.escape(key)}\s*=")
        for i in range(lo, hi):
            if pattern.match(self.lines[i]):
                return i
        raise KeyError(f"no key {key!r} in [{table}]")

    def set(self, table: str, key: str, value: str) -> "CaseText":
        """Set ``key`` in ``[table]`` to the TOML literal ``value`` (adding the key if absent)."""
        try:
            self.lines[self._find(table, key)] = f"{key} = {value}"
        except KeyError:
            lo, _ = self._table_span(table)
            self.lines.insert(lo, f"{key} = {value}")
        return self

    def drop(self, table: str, key: str) -> "CaseText":
        del self.lines[self._find(table, key)]
        return self

    def drop_table(self, table: str) -> "CaseText":
        lo, hi = self._table_span(table)
        del self.lines[lo - 1:hi]
        return self

    def append(self, text: str) -> "CaseText":
        self.lines.extend(text.strip("\n").splitlines())
        return self

    def prepend(self, text: str) -> "CaseText":
        self.lines[0:0] = text.strip("\n").splitlines()
        return self

    def write(self, directory: Path, name: str = "case.toml") -> Path:
        path = directory / name
        path.write_text("\n".join(self.lines) + "\n", encoding="utf-8")
        return path


@pytest.fixture
def case_text() -> CaseText:
    """An editable copy of the shipped RV-40E case."""
    return CaseText.shipped("rv40e")


END_TO_END_DIR = TESTS_DIR / "end_to_end"
"""The test modules that run the whole job (result folders, images, notebooks, Dask studies, the
fuzzed command line) rather than one stage of the science core: every test in them counts as
``slow``."""


WIDER_SCOPES = ("class", "module", "package")
"""Fixture scopes whose value a module's tests share (a whole run of the job, a mesh, a solved
cycle): with parallel workers (pytest-xdist, ``make test``) such a test runs on the worker that
computed the value for its module, so that it is computed once per test run."""


def shared_fixture_group(item) -> str | None:
    """The ``xdist_group`` of a test: its module's path when it uses a fixture of a scope in
    :data:`WIDER_SCOPES` (directly or through another fixture), None otherwise (the test may run
    on any worker). Session fixtures are per worker and not counted: they must be cheap or cached
    across processes (see :func:`shared_mesh_cache`)."""
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return None
    for name in item.fixturenames:
        if any(d.scope in WIDER_SCOPES for d in info.name2fixturedefs.get(name, ())):
            return item.path.relative_to(ROOT).as_posix()
    return None


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """Mark the tests under :data:`END_TO_END_DIR` ``slow`` (tests elsewhere carry the marker
    themselves), so that ``pytest -m "not slow"`` runs the science core only; and put the tests
    that share a module's fixtures in one ``xdist_group`` (:func:`shared_fixture_group`), which
    ``--dist loadgroup`` (``make test``) runs on one worker."""
    for item in items:
        if END_TO_END_DIR in item.path.resolve().parents:
            item.add_marker(pytest.mark.slow)
        group = shared_fixture_group(item)
        if group is not None:
            item.add_marker(pytest.mark.xdist_group(group))


def _registry_tables() -> tuple[dict, ...]:
    """The tables a plug-in registers itself in: the crank-bearing and pin models
    (:mod:`rvfem.case.registry`), the writers of a result folder (:mod:`rvfem.outputs.registry`), the
    stage components (:mod:`rvfem.solve.stage_parts`) and their case tables
    (:func:`rvfem.case.definition.register_component_table`), the result sections
    (:mod:`rvfem.results.registry`), the subcommands (:func:`rvfem.app.cli.register_subcommand`)
    and the roller-profile kinds (:func:`rvfem.evaluate.roller_slices.register_profile_kind`)."""
    from rvfem.app import cli
    from rvfem.case import registry as models
    from rvfem.case import whole_case
    from rvfem.case.tables import ROLLER_PROFILE_KINDS
    from rvfem.evaluate.roller_slices import PROFILE_DROPS
    from rvfem.outputs import registry as writers
    from rvfem.results import registry as sections
    from rvfem.solve import stage_parts

    return (models._BEARINGS, models._PINS, writers._WRITERS, stage_parts._REGISTERED, whole_case._COMPONENT_TABLES,
            sections._ADDED, cli._ADDED, ROLLER_PROFILE_KINDS, PROFILE_DROPS)


@contextmanager
def saved_registries() -> Iterator[None]:
    """The model, writer and stage-component registries as they were before the block, whatever it
    registered or removed (restored in place: every module holding a table sees it restored). For fixtures wider
    than a test; a test asks for the :func:`registries` fixture."""
    tables = _registry_tables()
    saved = [dict(table) for table in tables]
    try:
        yield
    finally:
        for table, before in zip(tables, saved):
            table.clear()
            table.update(before)


@pytest.fixture
def registries() -> Iterator[None]:
    """The model, writer and stage-component registries saved before the test and restored after it:
    a test that registers a plug-in (a bearing or pin model, a writer, a stage component and its case
    table) leaves no trace in the next one."""
    with saved_registries():
        yield


def structured_annulus(r_in=8.0, r_out=30.0, n_r=6, n_t=72):
    """Triangles of a structured annulus, its vertices and its two boundary loops."""
    r = np.linspace(r_in, r_out, n_r)
    t = np.linspace(0.0, 2 * np.pi, n_t, endpoint=False)
    rr, tt = np.meshgrid(r, t, indexing="ij")
    points = np.column_stack([(rr * np.cos(tt)).ravel(), (rr * np.sin(tt)).ravel()])
    idx = np.arange(n_r * n_t).reshape(n_r, n_t)
    a, b = idx[:-1, :], np.roll(idx[:-1, :], -1, axis=1)
    c, d = idx[1:, :], np.roll(idx[1:, :], -1, axis=1)
    triangles = np.vstack([np.column_stack([a.ravel(), b.ravel(), d.ravel()]),
                           np.column_stack([a.ravel(), d.ravel(), c.ravel()])])
    loop = lambda k: np.column_stack([idx[k], np.roll(idx[k], -1)])  # noqa: E731
    return points, triangles, {"central_hole": loop(0), "profile": loop(-1)}


_DRAWS_A_FIGURE = re.compile(r"\b(plt\.subplots|plt\.figure|comparison_figure|study_figures)\(")


def assert_figures_shown(nb) -> int:
    """Every code cell of an executed notebook that draws a figure (``plt.subplots``,
    ``plt.figure``, rvfem's figure functions) shows it: a PNG is among the cell's outputs, as
    Jupyter's inline backend puts it there. Returns the number of figures shown (at least one)."""
    shown = 0
    for i, cell in enumerate(nb.cells):
        if cell.cell_type != "code":
            continue
        pngs = sum("image/png" in out.get("data", {}) for out in cell.get("outputs", []))
        if _DRAWS_A_FIGURE.search(cell.source):
            assert pngs, f"cell {i} draws a figure but shows none:\n{cell.source[:300]}"
        shown += pngs
    assert shown, "the notebook shows no figure"
    return shown
