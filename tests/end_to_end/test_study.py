"""Design studies on Dask distributed: a real scheduler and two workers on localhost, the study
against the same variants run one by one in-process, failing variants, resume, Ctrl-C, the lock,
study-file and override errors, and the notebook executed from its own folder."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import ROOT, assert_figures_shown

from rvfem.app import cli
from rvfem.app.cli_study import COMPARE, STUDY
from rvfem.app.run import run_case
from rvfem.app.study import LOCK_NAME, load_study, read_study_csv, run_study
from rvfem.case.definition import load_case
from rvfem.errors import CaseError, OutputError
from rvfem.outputs.summary import RESULT_MARKER, mark_folder

BIN = Path(sys.executable).parent
BASE_CASE = ROOT / "cases" / "rv40e_fanholes.toml"

#: Coarse mesh and 30° steps: a variant in about 2 s; enough for the physics the tests check.
COARSE = {"mesh.size_flank": 1.2, "mesh.size_bore": 1.5, "mesh.size_interior": 6.0, "mesh.size_hole": 2.0,
          "analysis.angle_step_deg": 30.0}


def _study_text(kind: str, body: str, name: str = "test_study") -> str:
    overrides = "\n".join(f'"{k}" = {v!r}' for k, v in COARSE.items())
    return (f'name = "{name}"\nbase_case = "{BASE_CASE.as_posix()}"\nkind = "{kind}"\n\n'
            f"[overrides]\n{overrides}\n\n{body}\n")


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def _subcommands():
    names = {s.name for s in cli.SUBCOMMANDS}
    return cli.SUBCOMMANDS + tuple(c for c in (COMPARE, STUDY) if c.name not in names)


def _main(argv, monkeypatch) -> int:
    """``rvfem ARGV`` with the study subcommands registered."""
    build = cli.build_parser
    monkeypatch.setattr(cli, "build_parser", lambda subcommands=None: build(_subcommands()))
    return cli.main([str(a) for a in argv])


# A runner for subprocesses: `rvfem` with the study subcommands (until they are in cli.SUBCOMMANDS).
RUNNER = """
import sys
from rvfem.app import cli
from rvfem.app.cli_study import COMPARE, STUDY
names = {s.name for s in cli.SUBCOMMANDS}
subs = cli.SUBCOMMANDS + tuple(c for c in (COMPARE, STUDY) if c.name not in names)
build = cli.build_parser
cli.build_parser = lambda subcommands=None: build(subs)
sys.exit(cli.main(sys.argv[1:]))
"""


def _as_terminal_job() -> None:
    """In a child before it runs the command: SIGINT unblocked and at its default action, as in a
    job started from a terminal. A child inherits its parent's blocked signals and ignored ones,
    and a test process that ran clusters and child processes before may hold SIGINT so (seen with
    parallel test workers): the command would then never see the Ctrl-C these tests send."""
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    return env


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=10)


@pytest.fixture(scope="module")
def meshes(tmp_path_factory) -> Path:
    """Mesh cache shared by the cluster tests (the variants of one base case share meshes)."""
    return tmp_path_factory.mktemp("meshes")


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory):
    """A real Dask scheduler and two single-threaded workers, each its own process on 127.0.0.1."""
    from distributed import Client

    logs = tmp_path_factory.mktemp("dask-logs")
    address = f"tcp://127.0.0.1:{_free_port()}"
    procs = []
    try:
        procs.append(subprocess.Popen(
            [str(BIN / "dask"), "scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1],
             "--no-dashboard"], env=_env(), stdout=subprocess.DEVNULL, stderr=open(logs / "scheduler.log", "w")))
        for i in range(2):
            procs.append(subprocess.Popen(
                [str(BIN / "dask"), "worker", address, "--nworkers", "1", "--nthreads", "1", "--host", "127.0.0.1",
                 "--no-dashboard", "--name", f"test-worker-{i}", "--local-directory", str(logs / f"w{i}")],
                env={**_env(), "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"},
                stdout=subprocess.DEVNULL, stderr=open(logs / f"worker{i}.log", "w")))
        with Client(address, timeout=30, set_as_default=False) as client:
            client.wait_for_workers(2, timeout=60)
        yield address
    finally:
        for p in reversed(procs):
            _stop(p)


def _wait_for_no_partials(variants: Path, timeout_s: float = 30.0) -> None:
    """A variant cancelled while it runs on an external worker stops at its next crank angle and
    removes its temporary folder; wait for that (bounded)."""
    end = time.monotonic() + timeout_s
    while list(variants.glob(".*")):
        assert time.monotonic() < end, f"temporary folders left: {[p.name for p in variants.glob('.*')]}"
        time.sleep(0.1)


LIST_BODY = """
[[variant]]
id = "thin-ligament"
set = { "fan_holes.ligament" = 3.5 }

[[variant]]
id = "low-torque"
set = { "loads.torque_Nm" = 300.0 }

[[variant]]
set = { "crank_bearing.model" = "rigid_bore" }
"""


@pytest.fixture(scope="module")
def cluster_study(scheduler, meshes, tmp_path_factory):
    """A 4-variant study (the base and three variants, one a model choice) through ``rvfem study
    --scheduler``; the study folder and the time it took."""
    tmp = tmp_path_factory.mktemp("cluster-study")
    study_file = _write(tmp / "four.toml", _study_text("list", LIST_BODY, name="four"))
    out = tmp / "out"
    mp = pytest.MonkeyPatch()
    try:
        started = time.perf_counter()
        code = _main(["study", study_file, "-o", out, "--scheduler", scheduler, "--cache-dir", meshes], mp)
        elapsed = time.perf_counter() - started
    finally:
        mp.undo()
    assert code == 0
    return study_file, out, elapsed


def test_study_on_a_real_cluster_equals_the_variants_run_in_process(cluster_study, tmp_path):
    study_file, out, _ = cluster_study
    study = load_study(study_file)
    assert [v.id for v in study.variants] == ["base", "thin-ligament", "low-torque", "crank_bearing.model=rigid_bore"]
    rows = {r["id"]: r for r in read_study_csv(out / "study.csv")}
    assert set(rows) == {v.id for v in study.variants}
    for v in study.variants:
        row = rows[v.id]
        assert row["status"] == "ok" and row["computed"] == "yes", row
        # the same variant, run here one by one, with its own mesh cache
        summary = run_case(load_case(study.base_case, v.overrides), tmp_path / v.id, images=False,
                           cache_dir=tmp_path / "meshes").summary
        assert row["digest"] == summary["case"]["digest"]
        for i, b in enumerate(summary["bearings"], start=1):
            assert row[f"bearing{i}_max_N"] == b["flexible"]["max_load_N"]          # bit-identical
            assert row[f"bearing{i}_min_N"] == b["flexible"]["min_load_N"]
            assert row[f"bearing{i}_Fm_N"] == b["flexible"]["equivalent_load_N"]
            assert row[f"bearing{i}_L10h_h"] == b["flexible"]["L10h_h"]
            assert row[f"bearing{i}_handbook_max_N"] == b["rigid"]["max_load_N"]
            assert row[f"bearing{i}_life_ratio"] == b["life_ratio"]
        assert row["peak_von_mises_MPa"] == summary["peak_von_mises_MPa"]
        # the worker's result folder holds the same summary numbers
        stored = json.loads((out / "variants" / v.id / "summary.json").read_text())
        assert stored["bearings"] == summary["bearings"]
    # deltas against the base are the base's own numbers
    base = rows["base"]
    assert rows["low-torque"]["max_vs_base_percent"] == pytest.approx(
        100 * (rows["low-torque"]["max_load_N"] / base["max_load_N"] - 1), rel=1e-12)
    assert base["max_vs_base_percent"] == 0.0
    # physics: a thinner ligament raises the largest load; less torque lowers it about in proportion
    assert rows["thin-ligament"]["max_load_N"] > base["max_load_N"]
    assert rows["low-torque"]["max_load_N"] / base["max_load_N"] == pytest.approx(300 / 412, rel=0.05)
    assert (out / "report.html").is_file() and (out / "plots" / "variants.png").is_file()
    assert not (out / LOCK_NAME).exists()


def test_rerun_recomputes_nothing(cluster_study, monkeypatch, capsys):
    study_file, out, first_s = cluster_study
    before = {p.name: (p / "summary.json").stat().st_mtime_ns for p in (out / "variants").iterdir()}
    started = time.perf_counter()
    result = run_study(study_file, out, scheduler="tcp://127.0.0.1:1")  # never contacted: nothing to do
    assert (result.computed, result.reused, result.failed) == (0, 4, 0)
    assert time.perf_counter() - started < first_s
    after = {p.name: (p / "summary.json").stat().st_mtime_ns for p in (out / "variants").iterdir()}
    assert after == before
    assert all(r["computed"] == "no" and r["status"] == "ok" for r in read_study_csv(out / "study.csv"))
    # the compute time is the variants' recorded run times, those of the first run included;
    # the wall time is this (short) run's
    recorded = sum(json.loads((p / "summary.json").read_text())["timings_s"]["total"]
                   for p in (out / "variants").iterdir())
    assert result.compute_time_s == pytest.approx(recorded, rel=1e-12)
    assert result.compute_time_s > result.wall_time_s
    report = (out / "report.html").read_text()
    assert f"compute time of the variants {result.compute_time_s:.1f} s" in report
    assert f"wall time of this run {result.wall_time_s:.1f} s" in report


def test_a_failing_variant_is_recorded_and_the_study_goes_on(scheduler, cluster_study, meshes, tmp_path):
    _, done, _ = cluster_study
    out = tmp_path / "out"
    shutil.copytree(done / "variants" / "base", out / "variants" / "base")  # same base case: reused
    mark_folder(out, "study")                                               # a study folder of rvfem
    study_file = _write(tmp_path / "fail.toml", _study_text("list", """
[[variant]]
id = "too-thin"
set = { "fan_holes.ligament" = 1.0 }

[[variant]]
id = "also-thin"
set = { "fan_holes.ligament" = 1.5 }
"""))
    result = run_study(study_file, out, scheduler=scheduler, cache_dir=meshes)
    rows = {r["id"]: r for r in result.rows}
    assert rows["base"]["status"] == "ok" and not rows["base"]["computed"]
    for vid, thickness in (("too-thin", "1.000"), ("also-thin", "1.500")):
        assert rows[vid]["status"] == "failed"
        assert rows[vid]["error"].startswith("GeometryError: ") and f"only {thickness} mm thick" in rows[vid]["error"]
        assert rows[vid]["max_load_N"] is None
        assert not (out / "variants" / vid).exists()
    assert result.failed == 2
    csv_rows = {r["id"]: r for r in read_study_csv(out / "study.csv")}
    assert csv_rows["too-thin"]["status"] == "failed" and "GeometryError" in csv_rows["too-thin"]["error"]


def test_ctrl_c_cancels_and_leaves_no_partial_variant(scheduler, meshes, tmp_path):
    study_file = _write(tmp_path / "grid.toml", _study_text("grid", """
[[parameter]]
key = "loads.torque_Nm"
values = [250.0, 300.0, 350.0, 450.0, 500.0, 550.0]
"""))
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-c", RUNNER, "study", str(study_file), "-o", str(out),
                             "--scheduler", scheduler, "--cache-dir", str(meshes)],
                            env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_as_terminal_job)
    try:
        end = time.monotonic() + 90
        while not list((out / "variants").glob("*/summary.json")):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < end, "no variant finished in time"
            time.sleep(0.1)
        proc.send_signal(signal.SIGINT)
        _, stderr = proc.communicate(timeout=60)
    finally:
        _stop(proc)
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr
    _wait_for_no_partials(out / "variants")
    folders = list((out / "variants").iterdir())
    assert len(folders) < 7
    for folder in folders:
        assert not folder.name.startswith("."), f"temporary folder left: {folder.name}"
        summary = json.loads((folder / "summary.json").read_text())   # complete, or not there at all
        assert summary["case"]["digest"]
    rows = read_study_csv(out / "study.csv")
    assert {r["status"] for r in rows} <= {"ok", "cancelled"} and "cancelled" in {r["status"] for r in rows}
    assert not (out / LOCK_NAME).exists()


def test_a_second_study_into_the_same_folder_is_refused(tmp_path):
    study_file = _write(tmp_path / "s.toml", _study_text("list", LIST_BODY))
    out = tmp_path / "out"
    out.mkdir()
    mark_folder(out, "study")                  # a study folder in use holds the marker and the lock
    lock = out / LOCK_NAME
    lock.write_text(json.dumps({"pid": os.getpid(), "host": socket.gethostname(), "started": "now"}))
    with pytest.raises(OutputError, match=r"in use by another study \(lock file .*\.study\.lock"):
        run_study(study_file, out)
    assert lock.exists()
    # a lock left by a process that no longer runs is taken over (here: nothing to compute is not
    # reachable without a cluster, so only the lock logic is checked)
    from rvfem.app.study_run import _acquire_lock

    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    lock.write_text(json.dumps({"pid": dead.pid, "host": socket.gethostname(), "started": "then"}))
    assert _acquire_lock(out) == lock
    assert json.loads(lock.read_text())["pid"] == os.getpid()


@pytest.mark.parametrize("body, message", [
    ('[[parameter]]\nkey = "fan_holes.ligamnt"\nvalues = [3.5]',
     r"parameter\[1\] \(key fan_holes\.ligamnt\)|'fan_holes\.ligamnt' is not a known key \(did you mean 'fan_holes\.ligament'\?\)"),
    ('[[parameter]]\nkey = "fan_holes.ligament"\nvalues = [-1.0]', r"fan_holes\.ligament"),
    ('[[parameter]]\nkey = "crank_bearing.model"\nvalues = ["rollers", "ball"]', r"crank_bearing\.model"),
    ('[[parameter]]\nkey = "fan_holes.ligament"\nlow = 3.5\nhigh = 5.5', r"'parameter\[1\]\.low' is not a known key; known keys: key, values, label"),
    ('[[parameter]]\nkey = "fan_holes.ligament"', r"'parameter\[1\]\.values' is missing \(required: array of values\)"),
    ('[[parameter]]\nkey = "fan_holes.ligament"\nvalues = [3.5, 3.5]', r"parameter\[1\]\.values: a value appears twice"),
    ('[[variant]]\nset = { "fan_holes.ligament" = 4.0 }', r"variant: only a study of kind 'list'"),
    ('[[parametre]]\nkey = "x"', r"'parametre' is not a known key \(did you mean 'parameter'\?\); known keys: name, "),
])
def test_study_file_errors_name_the_key(tmp_path, body, message):
    path = _write(tmp_path / "bad.toml", _study_text("grid", body))
    with pytest.raises(CaseError, match=message) as info:
        load_study(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)


def test_study_file_errors_on_the_top_level(tmp_path):
    path = _write(tmp_path / "bad.toml", 'base_case = "nowhere.toml"\nkind = "grid"\n')
    with pytest.raises(CaseError, match=r"base_case: no case file 'nowhere.toml'"):
        load_study(path)
    path = _write(tmp_path / "bad.toml", f'base_case = "{BASE_CASE.as_posix()}"\nkind = "tornado"\n')
    with pytest.raises(CaseError, match=r"'kind' must be one of 'grid', 'sensitivity', 'list', got 'tornado'"):
        load_study(path)
    path = _write(tmp_path / "bad.toml", f'base_case = "{BASE_CASE.as_posix()}"\n')
    with pytest.raises(CaseError, match=r"'kind' is missing \(required: one of grid, sensitivity, list\)"):
        load_study(path)



@pytest.mark.parametrize("top, body, message", [
    ('kind = "gird"', "", r"'kind' must be one of 'grid', 'sensitivity', 'list', got 'gird' \(did you mean 'grid'\?\)"),
    ('kind = "grid"\ndescription = 3', "", r"'description' must be a string, got 3"),
    ('kind = "grid"\nname = "a b"', "", r"name: expected a non-empty name of letters, digits and \._=,\+-, got 'a b'"),
    ('kind = "grid"', "parameter = [3]", r"'parameter\[1\]' must be a table, got int"),
    ('kind = "grid"', '[[parameter]]\nkey = "fan_holes.ligament"\nvalues = [3.5]\nlabel = 3',
     r"'parameter\[1\]\.label' must be a string, got 3"),
    ('kind = "sensitivity"', '[[parameter]]\nkey = "fan_holes.ligament"\nlow = 3.5',
     r"'parameter\[1\]\.high' is missing \(required: high value\)"),
    ('kind = "list"', '[[variant]]\nid = "a"', r"'variant\[1\]\.set' is missing \(required: table of dotted case keys\)"),
    ('kind = "list"', '[[variant]]\nset = { "fan_holes.ligament" = 4.0 }\nname = "x"',
     r"'variant\[1\]\.name' is not a known key; known keys: id, set"),
])
def test_study_file_tables_are_read_by_the_schema(tmp_path, top, body, message):
    """The study file's tables go through rvfem.case.schema.read_table: types, choices (with a "did you
    mean"), unknown keys with the known ones, missing keys with their meaning."""
    path = _write(tmp_path / "bad.toml", f'base_case = "{BASE_CASE.as_posix()}"\n{top}\n{body}\n')
    with pytest.raises(CaseError, match=message) as info:
        load_study(path)
    assert "\n" not in str(info.value) and str(info.value).startswith(f"{path}: ")

def test_set_errors_name_the_key(tmp_path, monkeypatch, capsys):
    path = _write(tmp_path / "s.toml", _study_text("list", LIST_BODY))
    code = _main(["study", path, "-o", tmp_path / "out", "--set", "fan_holes.ligamnt=4.0"], monkeypatch)
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert "fan_holes.ligamnt" in err and "did you mean 'fan_holes.ligament'" in err
    assert not (tmp_path / "out").exists()  # validated before anything runs
    code = _main(["study", path, "--set", "crank_bearing.model=ball", "--check"], monkeypatch)
    err = capsys.readouterr().err.strip()
    assert code == 2 and "crank_bearing.model" in err and len(err.splitlines()) == 1
    code = _main(["study", path, "--set", "no equals sign"], monkeypatch)
    err = capsys.readouterr().err.strip()
    assert code == 2 and "expected KEY=VALUE" in err


def test_shipped_combined_roller_study_is_a_grid_of_combined_rollers_around_the_rigs():
    # every variant a combined roller (the study's overrides), the rig's a = 1.23 mm, b = 6 µm at the
    # rated torque its base, and the grid's base point computed once
    study = load_study(ROOT / "studies" / "rv40e_fanholes_combined_roller.toml")
    assert study.kind == "grid" and [p.key for p in study.parameters] == [
        "crank_bearing.profile.modification_length", "crank_bearing.profile.modification_drop", "loads.torque_Nm"]
    sizes = [len(p.values) for p in study.parameters]
    assert len(study.variants) == 1 + sizes[0] * sizes[1] * sizes[2]
    assert len({v.digest for v in study.variants}) == len(study.variants) - 1     # the base is in the grid
    base = load_case(study.base_case, overrides=study.base.overrides)
    prof = base.crank_bearing.profile
    assert (prof.kind, prof.modification_length, prof.modification_drop, base.loads.torque_Nm) == (
        "combined", 1.23, 0.006, 412.0)
    last = load_case(study.base_case, overrides=study.variants[-1].overrides)
    assert last.crank_bearing.profile.kind == "combined" and last.loads.torque_Nm == 1250.0


def test_sensitivity_study_variants_and_check(tmp_path, monkeypatch, capsys):
    shipped = load_study(ROOT / "studies" / "rv40e_fanholes_tornado.toml")
    assert shipped.kind == "sensitivity" and shipped.base.id == "base"
    assert len(shipped.variants) == 1 + sum(v != p.base_value for p in shipped.parameters for v in p.values)
    for p in shipped.parameters:  # low and high bracket the base value
        assert p.values[0] <= p.base_value <= p.values[1] and p.values[0] < p.values[1], p
    assert len({v.digest for v in shipped.variants}) == len(shipped.variants)
    grid = load_study(ROOT / "studies" / "rv40e_ligament_torque_grid.toml")
    sizes = [len(p.values) for p in grid.parameters]
    assert len(grid.variants) == 1 + sizes[0] * sizes[1]
    code = _main(["study", ROOT / "studies" / "rv40e_fanholes_tornado.toml", "--check"], monkeypatch)
    assert code == 0 and "fan_holes.fillet_radius=" in capsys.readouterr().out


def test_notebook_runs_from_its_own_folder(tmp_path, monkeypatch):
    """Executed as Jupyter does (kernel started in notebooks/), on a local cluster."""
    import nbformat
    from nbclient import NotebookClient

    monkeypatch.setenv("RVFEM_NOTEBOOK_RESULTS", str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", _env()["PYTHONPATH"])
    path = ROOT / "notebooks" / "design_study.ipynb"
    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, timeout=300, kernel_name="python3",
                   resources={"metadata": {"path": str(path.parent)}}).execute()
    assert assert_figures_shown(nb) >= 2   # its own response curves and the study's plot
    checks = json.loads((tmp_path / "design_study" / "run_info.json").read_text())
    rows = read_study_csv(tmp_path / "design_study" / "study.csv")
    assert all(r["status"] == "ok" for r in rows)
    by = {(r["fan_holes.ligament"], r["loads.torque_Nm"]): r["max_load_N"] for r in rows if r["role"] == "grid"}
    ligaments = sorted({k[0] for k in by})
    torques = sorted({k[1] for k in by})
    for t in torques:  # the largest load rises as the ligament shrinks
        loads = [by[(lig, t)] for lig in ligaments]
        assert loads == sorted(loads, reverse=True), loads
    for lig in ligaments:  # and scales about linearly with the torque
        ratio = by[(lig, torques[-1])] / by[(lig, torques[0])]
        assert ratio == pytest.approx(torques[-1] / torques[0], rel=0.05)
    assert checks["cwd"] == str(path.parent) and Path(checks["root"]) == ROOT


def test_an_unreachable_scheduler_is_one_line(tmp_path):
    from rvfem.app.study import ClusterError

    study_file = _write(tmp_path / "s.toml", _study_text("list", LIST_BODY))
    address = f"tcp://127.0.0.1:{_free_port()}"  # nothing listens there
    with pytest.raises(ClusterError, match=f"cannot connect to the Dask scheduler at {address}") as info:
        run_study(study_file, tmp_path / "a" / "out", scheduler=address, connect_timeout_s=1.0)
    assert "\n" not in str(info.value)
    # reached before anything is created: no study.csv, study.json, variants/ or created parent left
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_a_study_into_a_folder_rvfem_did_not_write_is_refused(tmp_path):
    study_file = _write(tmp_path / "s.toml", _study_text("list", LIST_BODY))
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match="rvfem did not write it"):
        run_study(study_file, out, scheduler="tcp://127.0.0.1:1", connect_timeout_s=1.0)
    assert [p.name for p in out.iterdir()] == ["notes.txt"]


def _fake_summary(max_n: float, fm_n: float, life_h: float) -> dict:
    bearing = {"flexible": {"max_load_N": max_n, "min_load_N": 0.1 * max_n, "equivalent_load_N": fm_n,
                            "L10h_h": life_h},
               "rigid": {"max_load_N": 1000.0, "min_load_N": 100.0, "equivalent_load_N": 800.0, "L10h_h": 5e4},
               "delta_max_percent": 100 * (max_n / 1000.0 - 1), "delta_equivalent_percent": 100 * (fm_n / 800.0 - 1),
               "life_ratio": life_h / 5e4}
    return {"bearings": [bearing, bearing], "max_bearing_load": {"bearing": 1}, "peak_von_mises_MPa": 50.0,
            "stress": {"away_from_contacts": {"peak_von_mises_MPa": 40.0}}}


def test_rows_and_plots_of_a_sensitivity_study(tmp_path, monkeypatch):
    """Deltas against the handbook and the base from known numbers; the tornado and bar charts,
    written as a whole folder (rvfem.outputs.summary.result_folder): no stale plot, an interrupted run
    leaves the earlier plots."""
    from rvfem.app import study_outputs
    from rvfem.app.study_outputs import study_rows, write_plots

    path = _write(tmp_path / "s.toml", _study_text("sensitivity", """
[[parameter]]
key = "fan_holes.ligament"
low = 3.5
high = 5.5

[[parameter]]
key = "crank_bearing.model"
low = "rollers"
high = "rigid_bore"
"""))
    study = load_study(path)
    assert [v.id for v in study.variants] == ["base", "fan_holes.ligament=3.5", "fan_holes.ligament=5.5",
                                               "crank_bearing.model=rigid_bore"]  # 'rollers' is the base
    loads = {"base": 1100.0, "fan_holes.ligament=3.5": 1210.0, "fan_holes.ligament=5.5": 1045.0,
             "crank_bearing.model=rigid_bore": 990.0}
    records = {vid: {"id": vid, "status": "ok", "error": "", "computed": True, "wall_time_s": 1.0,
                     "summary": _fake_summary(f, 0.8 * f, 4e4 * (1100.0 / f) ** (10 / 3))} for vid, f in loads.items()}
    records["fan_holes.ligament=5.5"] = {"id": "fan_holes.ligament=5.5", "status": "failed", "computed": True,
                                         "error": "GeometryError: too thin", "summary": None, "wall_time_s": 0.1}
    rows = {r["id"]: r for r in study_rows(study, records)}
    thin = rows["fan_holes.ligament=3.5"]
    assert thin["max_vs_base_percent"] == pytest.approx(10.0, rel=1e-12)
    assert thin["max_vs_handbook_percent"] == pytest.approx(21.0, rel=1e-12)
    assert thin["life_ratio_vs_base"] == pytest.approx(1.1 ** (-10 / 3), rel=1e-12)
    assert thin["bearing2_Fm_vs_base_percent"] == pytest.approx(10.0, rel=1e-12)
    assert thin["fan_holes.ligament"] == 3.5 and thin["crank_bearing.model"] == "rollers"
    assert rows["fan_holes.ligament=5.5"]["max_load_N"] is None
    assert rows["fan_holes.ligament=5.5"]["error"] == "GeometryError: too thin"
    (tmp_path / "plots").mkdir()
    mark_folder(tmp_path / "plots", "study plots")   # the plots of an earlier run
    (tmp_path / "plots" / "response_old.png").write_bytes(b"stale")
    files = write_plots(study, list(rows.values()), tmp_path / "plots")
    assert set(files) == {"tornado", "variants"}
    assert all(p.stat().st_size > 5000 for p in files.values())
    assert sorted(p.name for p in (tmp_path / "plots").iterdir()) == [RESULT_MARKER, "tornado.png", "variants.png"]
    before = {p.name: p.read_bytes() for p in files.values()}

    def interrupted(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(study_outputs, "study_figures", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_plots(study, list(rows.values()), tmp_path / "plots")
    assert {p.name: p.read_bytes() for p in (tmp_path / "plots").iterdir() if p.name != RESULT_MARKER} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plots", "s.toml"]   # no temporary folder left


def test_plots_are_figures_and_leave_the_backend_alone(tmp_path):
    """A notebook's inline backend survives the study's and the comparison's plots: rvfem draws
    on Figure objects (no pyplot, no matplotlib.use) and returns them for display."""
    study_file = _write(tmp_path / "s.toml", _study_text("sensitivity", """
[[parameter]]
key = "fan_holes.ligament"
low = 3.5
high = 5.5
"""))
    script = f"""
import sys
import matplotlib
matplotlib.use("svg")     # stands for a notebook's inline backend
from matplotlib.figure import Figure
from rvfem.app.study import load_study, study_figures
from rvfem.app.study_outputs import write_plots
study = load_study({str(study_file)!r})
rows = []
for v in study.variants:
    rows.append({{"id": v.id, "role": v.role, "varied": ",".join(k for k, _ in v.settings), "status": "ok",
                 "fan_holes.ligament": dict(v.settings).get("fan_holes.ligament", 4.5),
                 "max_load_N": 1100.0 + len(rows), "equivalent_load_N": 880.0, "handbook_max_load_N": 1000.0,
                 "max_vs_base_percent": float(len(rows)), "life_ratio_vs_base": 1.0 - 0.01 * len(rows)}})
figures = study_figures(study, rows)
assert set(figures) == {{"tornado", "variants"}} and all(isinstance(f, Figure) for f in figures.values())
files = write_plots(study, rows, __import__("pathlib").Path({str(tmp_path / "plots")!r}))
assert sorted(p.name for p in files.values()) == ["tornado.png", "variants.png"]
assert matplotlib.get_backend() == "svg", matplotlib.get_backend()
assert "matplotlib.pyplot" not in sys.modules
print("ok")
"""
    out = subprocess.run([sys.executable, "-c", script], env=_env(), capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr
    assert all((tmp_path / "plots" / name).stat().st_size > 5000 for name in ("tornado.png", "variants.png"))


def test_long_variant_ids_stay_distinct_and_readable(tmp_path, capsys):
    """Ids longer than MAX_ID_LENGTH are shortened with a hash of the full text; the table and the
    variant list print ids whole, so two crank-support variants never look the same."""
    from rvfem.app.cli_study import _format_rows, _print_variants
    from rvfem.app.study import MAX_ID_LENGTH, short_id

    path = _write(tmp_path / "s.toml", _study_text("grid", """
[[parameter]]
key = "crank_support.support_stiffness_N_per_mm"
values = [250000.0, 1000000.0]

[[parameter]]
key = "fan_holes.fillet_radius"
values = [1.0, 3.0]
"""))
    study = load_study(path)
    ids = [v.id for v in study.variants]
    assert len(set(ids)) == len(ids)
    long = [i for i in ids if i != "base"]
    assert all(len(i) <= MAX_ID_LENGTH for i in ids)
    # the full text is over 64 characters: table prefix dropped, cut, a hash appended
    assert long[0].startswith("support_stiffness_N_per_mm=250000.0,fillet_radius=1.0")
    assert all(len(i.rsplit("--", 1)[1]) == 6 for i in long)
    assert load_study(path).variants[1].id == long[0]           # stable: a rerun resumes
    assert short_id("x" * 80, 40) != short_id("x" * 79 + "y", 40) and len(short_id("x" * 80, 40)) == 40
    # a one-parameter sensitivity keeps its full key=value ids, and the tables show them whole
    shipped = load_study(ROOT / "studies" / "rv40e_fanholes_tornado.toml")
    support = [v.id for v in shipped.variants if v.id.startswith("crank_support.")]
    assert support == ["crank_support.support_stiffness_N_per_mm=250000.0",
                       "crank_support.support_stiffness_N_per_mm=1000000.0"]
    _print_variants(shipped)
    rows = [{"id": vid, "status": "ok", "max_load_N": 1000.0, "max_vs_handbook_percent": 10.0,
             "max_vs_base_percent": 0.0, "equivalent_load_N": 800.0, "life_ratio": 0.7, "life_ratio_vs_base": 1.0,
             "peak_von_mises_MPa": 110.4, "peak_away_from_contacts_MPa": 90.6, "wall_time_s": 5.0,
             "computed": True, "error": ""} for vid in support]
    _format_rows(rows)
    out = capsys.readouterr().out
    for vid in support:
        assert f"  {vid}  " in out                # the variant list
        assert any(line.startswith(vid + " ") for line in out.splitlines())   # the results table
    # the table's stress is the headline (P2) peak of rvfem run, not the P1 cycle's
    assert "110.4" in out and "90.6" not in out and "s_vm: structural stress peak" in out


def test_compute_time_counts_every_case_once():
    from rvfem.app.study_run import _compute_time

    records = {"base": {"wall_time_s": 10.0}, "a": {"wall_time_s": 5.0},
               "same": {"wall_time_s": 10.0, "same_as": "base"}, "cancelled": {"wall_time_s": float("nan")},
               "failed": {"wall_time_s": 0.5}}
    assert _compute_time(records) == 15.5


def test_local_workers_keep_dask_log_messages_to_critical_ones():
    """A local cluster's workers write to the user's terminal: Dask's own messages there (a
    heartbeat cut short by a shutdown after Ctrl-C, with its traceback) are kept to critical
    ones; a variant's failure reaches the study as its record instead."""
    import logging

    from distributed import Client

    from rvfem.app.study_run import local_cluster

    cluster = local_cluster(1)
    try:
        with Client(cluster, set_as_default=False) as client:
            levels = client.run(lambda: tuple(logging.getLogger(n).getEffectiveLevel()
                                              for n in ("distributed.worker", "distributed.core", "tornado")))
    finally:
        cluster.close()
    assert list(levels.values()) == [(logging.CRITICAL,) * 3]


def test_a_local_worker_closed_under_a_running_variant_ends_at_once(monkeypatch):
    """Closing a local worker while a variant runs (Ctrl-C) ends its process at once, before its
    Python finalises with the variant's thread still inside a compiled library; an idle local
    worker, and any worker of a cluster the user started, closes as Dask closes it."""
    from types import SimpleNamespace

    from rvfem.app import study_run

    ended = []
    monkeypatch.setattr(study_run.os, "_exit", lambda code: ended.append(code))
    busy, idle = SimpleNamespace(active_threads={1: "variant"}), SimpleNamespace(active_threads={})
    study_run._SingleThreadedBlasSetup(local=True).teardown(busy)
    assert ended == [0]
    study_run._SingleThreadedBlasSetup(local=True).teardown(idle)
    study_run._SingleThreadedBlasSetup(local=False).teardown(busy)
    assert ended == [0]


def test_ctrl_c_on_a_local_cluster_prints_one_line(meshes, tmp_path):
    """Ctrl-C at a terminal signals the whole process group, the local cluster's workers too: the
    command still prints one line ("interrupted"), no worker traceback, no Dask warning."""
    study_file = _write(tmp_path / "grid.toml", _study_text("grid", """
[[parameter]]
key = "loads.torque_Nm"
values = [250.0, 300.0, 350.0, 450.0, 500.0]
"""))
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-c", RUNNER, "study", str(study_file), "-o", str(out),
                             "--workers", "2", "--cache-dir", str(meshes)],
                            env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True,   # its own process group, as a terminal's job
                            preexec_fn=_as_terminal_job)
    try:
        end = time.monotonic() + 240
        while not list((out / "variants").glob("*/summary.json")):
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() < end, "no variant finished in time"
            time.sleep(0.1)
        os.killpg(proc.pid, signal.SIGINT)       # what Ctrl-C does
        _, stderr = proc.communicate(timeout=120)
    finally:
        _stop(proc)
    assert proc.returncode == 130, stderr
    lines = stderr.splitlines()
    assert lines[-1] == "rvfem: interrupted", stderr
    assert all(line.startswith("rvfem") for line in lines), stderr      # the start line, progress lines
    assert "Traceback" not in stderr and "distributed" not in stderr and "KeyboardInterrupt" not in stderr
    assert not (out / LOCK_NAME).exists()
    assert not [p for p in (out / "variants").iterdir() if p.name.startswith(".")]
