"""Gmsh meshing of the disc: area, physical groups, closed boundaries, quality, cache, preview.

Coarse meshes keep this file fast; one test meshes the default fan-hole case at its own sizes to
check the node budget the load cycle relies on.
"""

from __future__ import annotations

import dataclasses
import math
import os
import subprocess
import sys
from pathlib import Path

import gmsh
import numpy as np
import pytest
from conftest import CASES_DIR, ROOT
from scipy.integrate import quad

from rvfem.case.definition import load_case
from rvfem.errors import MeshError
from rvfem.geometry import closest_points, disc_geometry
from rvfem.mesh import gmsh_session, mesh_case, mesh_key, mesh_path, read_msh
from rvfem.outputs.plots import mesh_preview

CASES = CASES_DIR

MIN_QUALITY = 0.6
"""Accepted smallest minSICN (1 = equilateral). Measured: 0.684 (coarse fan-hole mesh), 0.660
(the default fan-hole case)."""


def coarse(case, flank=0.6, bore=0.6, interior=3.0):
    return case.replace(mesh=dataclasses.replace(case.mesh, size_flank=flank, size_bore=bore,
                                                 size_interior=interior))


@pytest.fixture(scope="module")
def fan_case():
    return coarse(load_case(CASES / "rv40e_fanholes.toml"))


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("meshes")


@pytest.fixture(scope="module")
def fan_mesh(fan_case, cache):
    return mesh_case(fan_case, cache)


# ------------------------------------------------------------------------------------------------
# Independent exact area
# ------------------------------------------------------------------------------------------------


def classical_profile_area(Rp, e, r, zp, n=400_000):
    """Shoelace area of a dense polygon of the classical one-tooth-difference profile
    x = Rp cos φ − e cos Zpφ − r (cos φ − k cos Zpφ)/√S, y likewise (k = eZp/Rp)."""
    phi = 2 * np.pi * np.arange(n) / n
    k = e * zp / Rp
    S = np.sqrt(1 + k * k - 2 * k * np.cos((zp - 1) * phi))
    x = Rp * np.cos(phi) - e * np.cos(zp * phi) - r * (np.cos(phi) - k * np.cos(zp * phi)) / S
    y = Rp * np.sin(phi) - e * np.sin(zp * phi) - r * (np.sin(phi) - k * np.sin(zp * phi)) / S
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def filleted_sector_area(ri, ro, half_span, f):
    """Annular sector area minus the four corner pieces the fillets cut off. A corner piece lies
    between the radial side, the arc and the fillet circle (centre at radius ρ_c = r_o − f or
    r_i + f, at angle γ inside the side, sin γ = f/ρ_c); at radius ρ it spans the angle γ − ψ(ρ),
    cos ψ = (ρ² + ρ_c² − f²)/(2ρρ_c) (law of cosines), between the side's tangent point and the
    arc, integrated in polar coordinates."""
    def corner(rc, g, outer):
        # region between the arc (radius ro or ri), the radial side and the fillet circle:
        # integrate over ρ between the tangent point on the side and the arc
        t = rc * math.cos(g)
        lo, hi = (t, ro) if outer else (ri, t)

        def width(rho):          # angular width of the corner piece at radius ρ
            cpsi = (rho * rho + rc * rc - f * f) / (2 * rho * rc)
            return g - math.acos(max(-1.0, min(1.0, cpsi)))
        return quad(lambda p: width(p) * p, lo, hi, epsabs=1e-13, epsrel=1e-13)[0]

    go, gi = math.asin(f / (ro - f)), math.asin(f / (ri + f))
    sector = half_span * (ro * ro - ri * ri)
    return sector - 2 * corner(ro - f, go, True) - 2 * corner(ri + f, gi, False)


# ------------------------------------------------------------------------------------------------
# Tests
# ------------------------------------------------------------------------------------------------


def test_mesh_area_equals_exact_area(fan_case, fan_mesh):
    geom = disc_geometry(fan_case)
    fan = fan_case.fan_holes
    half = math.radians(60.0) - math.asin((18.0 + fan.ligament) / 36.0)   # span from the ligament
    hole = filleted_sector_area(fan.inner_radius, fan.outer_radius, half, fan.fillet_radius)
    exact = (classical_profile_area(64.0, 1.3, 3.0, 40) - math.pi * 12.0**2 - 3 * math.pi * 18.0**2
             - 3 * hole)
    assert fan_mesh.area == pytest.approx(exact, rel=4e-4)    # measured 1.5e-4 (straight edges)
    assert geom.area == pytest.approx(exact, rel=6e-7)        # measured 2.2e-7 (profile samples)


def test_arrays_layout_and_orientation(fan_mesh):
    p, t = fan_mesh.points, fan_mesh.triangles
    assert p.dtype == np.float64 and p.flags.c_contiguous and p.shape[1] == 2
    assert np.issubdtype(t.dtype, np.integer) and t.flags.c_contiguous and t.shape[1] == 3
    assert fan_mesh.n_nodes == len(p) and fan_mesh.n_elements == len(t)
    q = p[t]
    area2 = (q[:, 1, 0] - q[:, 0, 0]) * (q[:, 2, 1] - q[:, 0, 1]) - (q[:, 1, 1] - q[:, 0, 1]) * (q[:, 2, 0] - q[:, 0, 0])
    assert np.all(area2 > 0)                                  # counter-clockwise
    assert np.array_equal(np.unique(t), np.arange(len(p)))   # every node used, indices contiguous


def test_physical_groups_present_and_closed(fan_mesh):
    expected = {"profile", "central_hole", "bore_0", "bore_1", "bore_2", "hole_0", "hole_1", "hole_2"}
    assert set(fan_mesh.boundaries) == expected
    # the mesh's own boundary (edges with one triangle) is exactly the union of the named curves
    t = fan_mesh.triangles
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(e, axis=0, return_counts=True)
    free = {tuple(x) for x in uniq[count == 1]}
    named = set()
    for name, edges in fan_mesh.boundaries.items():
        assert edges.shape[1] == 2 and len(edges) > 10
        assert np.array_equal(edges[1:, 0], edges[:-1, 1]), name          # ordered along the curve
        assert edges[-1, 1] == edges[0, 0], name                          # closed
        assert len(np.unique(edges[:, 0])) == len(edges), name            # one loop, no revisits
        named |= {tuple(sorted(x)) for x in edges.tolist()}
        # disc on the left: profile counter-clockwise, holes clockwise
        xy = fan_mesh.points[edges[:, 0]]
        signed = 0.5 * np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1])
        assert (signed > 0) == (name == "profile"), name
    assert named == free


def test_boundary_nodes_lie_on_their_features(fan_case, fan_mesh):
    centres = [(36 * math.cos(math.radians(a)), 36 * math.sin(math.radians(a))) for a in (90, 210, 330)]
    for i, c in enumerate(centres):
        xy = fan_mesh.points[fan_mesh.boundary_nodes(f"bore_{i}")]
        np.testing.assert_allclose(np.hypot(xy[:, 0] - c[0], xy[:, 1] - c[1]), 18.0, rtol=0,
                                   atol=5e-14)              # measured 2.1e-14 mm (rotated sector copies)
    xy = fan_mesh.points[fan_mesh.boundary_nodes("central_hole")]
    np.testing.assert_allclose(np.hypot(xy[:, 0], xy[:, 1]), 12.0, rtol=0, atol=5e-15)   # measured 1.8e-15 mm
    # profile nodes: on the spline through the analytical profile (< 0.1 µm off), radius between
    # root and tip
    xy = fan_mesh.points[fan_mesh.boundary_nodes("profile")]
    rad = np.hypot(xy[:, 0], xy[:, 1])
    assert rad.min() >= 59.7 - 1e-13 and rad.max() <= 62.3 + 3e-14   # measured +2.2e-8, +1.4e-14 mm
    geom = disc_geometry(fan_case)
    _, _, P, _ = closest_points(geom.profile, xy)       # Newton-refined distance to the profile
    assert np.max(np.linalg.norm(xy - P, axis=1)) < 3e-6   # measured 1.2e-6 mm (spline vs profile)
    # fan-hole nodes: inside the annulus [17, 49]
    for name in ("hole_0", "hole_1", "hole_2"):
        xy = fan_mesh.points[fan_mesh.boundary_nodes(name)]
        rad = np.hypot(xy[:, 0], xy[:, 1])
        assert rad.min() >= 17.0 - 1e-14 and rad.max() <= 49.0 + 3e-14   # measured −3.6e-15, +1.4e-14 mm


def test_min_quality_above_threshold(fan_mesh):
    assert fan_mesh.quality_measure == "minSICN"
    assert fan_mesh.min_quality > MIN_QUALITY


@pytest.mark.slow
def test_cache_hit_and_miss(fan_case, fan_mesh, cache):
    path = mesh_path(fan_case, cache)
    assert fan_mesh.path == path and path.is_file()
    mtime = path.stat().st_mtime_ns
    again = mesh_case(fan_case, cache)
    assert again.from_cache and again.path == path and path.stat().st_mtime_ns == mtime
    assert np.array_equal(again.points, fan_mesh.points)
    assert np.array_equal(again.triangles, fan_mesh.triangles)
    for name, edges in fan_mesh.boundaries.items():
        assert np.array_equal(again.boundaries[name], edges)
    assert again.min_quality == fan_mesh.min_quality          # binary .msh: read back exactly
    # loads, material, thickness, min_wall do not shape the mesh: same file, still a hit
    other = fan_case.replace(loads=dataclasses.replace(fan_case.loads, torque_Nm=99.0),
                             material=dataclasses.replace(fan_case.material, youngs_modulus=1e5),
                             cycloid=dataclasses.replace(fan_case.cycloid, thickness=12.0),
                             mesh=dataclasses.replace(fan_case.mesh, min_wall=1.0))
    assert mesh_key(other) == mesh_key(fan_case)
    assert mesh_case(other, cache).from_cache
    # a shaping input changes the key; the first call misses
    moved = fan_case.replace(fan_holes=dataclasses.replace(fan_case.fan_holes, inner_radius=17.5))
    assert mesh_path(moved, cache) != path
    assert mesh_key(coarse(fan_case, flank=0.7)) != mesh_key(fan_case)
    assert mesh_key(with_mod(fan_case, 0.001)) != mesh_key(fan_case)
    miss = mesh_case(moved, cache)
    assert not miss.from_cache and miss.path != path
    # use_cache=False re-meshes in place
    assert not mesh_case(fan_case, cache, use_cache=False).from_cache


def with_mod(case, equidistant):
    m = dataclasses.replace(case.cycloid.modification, equidistant=equidistant)
    return case.replace(cycloid=dataclasses.replace(case.cycloid, modification=m))


def test_preview_png_is_not_blank(fan_mesh, tmp_path):
    import matplotlib.image as mpimg

    out = mesh_preview(fan_mesh, tmp_path / "preview.png")
    img = mpimg.imread(out)
    assert img.ndim == 3 and img.shape[0] > 400 and img.shape[1] > 800
    rgb = img[..., :3]
    ink = np.mean(np.any(rgb < 0.9, axis=-1))
    assert ink > 0.05                      # lines drawn over a good part of the picture
    assert np.std(rgb) > 0.05


def test_area_agrees_with_scikit_fem(fan_mesh):
    """The arrays feed scikit-fem as they are (C-contiguous, every node used), and its quadrature
    gives the same area as the mesh's own sum of triangle areas."""
    from skfem import Basis, ElementTriP1, MeshTri

    m = MeshTri(fan_mesh.points.T.copy(), fan_mesh.triangles.T.copy())
    assert float(np.sum(Basis(m, ElementTriP1()).dx)) == pytest.approx(fan_mesh.area, rel=1e-15)   # measured 0


def test_gmsh_session_finalizes_on_error_and_is_silent(capfd, tmp_path):
    with pytest.raises(RuntimeError):
        with gmsh_session():
            assert gmsh.isInitialized()
            raise RuntimeError("boom")
    assert not gmsh.isInitialized()
    with pytest.raises(MeshError, match="cannot nest"):
        with gmsh_session():
            with gmsh_session():
                pass
    assert not gmsh.isInitialized()
    with pytest.raises(MeshError, match="no such mesh file"):
        read_msh(tmp_path / "missing.msh")
    capfd.readouterr()
    case = coarse(load_case(CASES / "rv40e_solid.toml"), 0.8, 0.8, 4.0)
    mesh_case(case, tmp_path)
    out, err = capfd.readouterr()
    assert out == "" and err == ""


@pytest.mark.skipif(not Path("/proc/self/status").is_file(), reason="reads the signal masks from /proc")
def test_gmsh_session_leaves_sigpipe_ignored():
    """Gmsh's initialisation sets SIGPIPE back to ending the process; the session puts Python's
    choice (ignored: a write to a closed pipe raises BrokenPipeError) back, also from a thread."""
    import signal
    import threading

    def ignored() -> bool:
        line = next(t for t in Path("/proc/self/status").read_text().splitlines() if t.startswith("SigIgn:"))
        return bool(int(line.split()[1], 16) & (1 << (signal.SIGPIPE - 1)))

    assert ignored()
    with gmsh_session():
        assert ignored()
    assert ignored()
    seen = []

    def in_a_thread():
        with gmsh_session():
            pass
        seen.append(ignored())

    thread = threading.Thread(target=in_a_thread)
    thread.start()
    thread.join()
    assert seen == [True]


@pytest.mark.slow
def test_default_fanholes_case_size_and_quality(tmp_path):
    """The project's default case at its own sizes: 10-21k nodes (the load cycle budget; the hole
    fillets' own size, mesh.size_fillet, added 1065 vertices to 19 074 to bring the structural peak
    within 3 % of converged), good quality, and the fine size really is applied along the flanks and
    the bores."""
    case = load_case(CASES / "rv40e_fanholes.toml")
    m = mesh_case(case, tmp_path)
    assert 10_000 <= m.n_nodes <= 21_000
    assert m.min_quality > MIN_QUALITY
    for name, h in (("profile", case.mesh.size_flank), ("bore_0", case.mesh.size_bore)):
        e = m.boundaries[name]
        length = np.linalg.norm(m.points[e[:, 1]] - m.points[e[:, 0]], axis=1)
        assert np.median(length) == pytest.approx(h, rel=0.06)   # measured −2.4 % (profile), −0.1 % (bore)
        assert length.max() < 1.05 * h                            # measured 0.976 h, 0.999 h


@pytest.mark.slow
def test_cli_mesh_subcommand(tmp_path, capsys):
    from rvfem.app.cli import main

    text = (CASES / "rv40e_fanholes.toml").read_text()
    text = text.replace("size_flank = 0.35", "size_flank = 0.8").replace("size_bore = 0.4", "size_bore = 0.8")
    case_file = tmp_path / "coarse.toml"
    case_file.write_text(text)
    cache = tmp_path / "cache"
    assert main(["mesh", str(case_file), "--cache-dir", str(cache)]) == 0
    out = capsys.readouterr().out
    mesh = mesh_case(load_case(case_file), cache)
    assert mesh.from_cache
    assert f"{mesh.n_nodes} nodes, {mesh.n_elements} linear triangles" in out
    assert f"(minSICN) {mesh.min_quality:.3f}" in out and "generated" in out
    png = mesh.path.with_suffix(".png")
    assert png.is_file() and str(png) in out
    assert main(["mesh", str(case_file), "--cache-dir", str(cache)]) == 0
    assert "cached" in capsys.readouterr().out
    # a geometry error is one line on stderr and exit code 2, and nothing is meshed
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("bore_radius = 18.0", "bore_radius = 22.0"))
    assert main(["mesh", str(bad), "--cache-dir", str(tmp_path / "none")]) == 2
    err = capsys.readouterr().err
    assert "rvfem mesh: error:" in err and "mesh.min_wall" in err
    assert not (tmp_path / "none").exists()


@pytest.mark.slow
def test_two_processes_building_the_same_mesh_share_one_complete_file(tmp_path):
    """Two processes start meshing the same case into the same cache at the same moment (both
    miss the cache): both succeed, one complete .msh is left, no temporary file, and it reads back
    as the mesh both of them built."""
    script = (
        "import sys, time, pathlib\n"
        "from rvfem.case.definition import load_case\n"
        "from rvfem.mesh import mesh_case\n"
        "import dataclasses\n"
        "case = load_case(sys.argv[1])\n"
        "case = case.replace(mesh=dataclasses.replace(case.mesh, size_flank=0.8, size_bore=0.8, size_interior=4.0))\n"
        "go = pathlib.Path(sys.argv[3])\n"
        "while not go.exists():\n"
        "    time.sleep(0.01)\n"
        "m = mesh_case(case, sys.argv[2])\n"
        "print(m.n_nodes, m.from_cache)\n"
    )
    root = ROOT
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))
    cache, go = tmp_path / "cache", tmp_path / "go"
    args = [sys.executable, "-c", script, str(CASES / "rv40e_solid.toml"), str(cache), str(go)]
    procs = [subprocess.Popen(args, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for _ in range(2)]
    go.touch()
    outs = [p.communicate(timeout=300) for p in procs]
    assert [p.returncode for p in procs] == [0, 0], [err for _, err in outs]
    files = sorted(x.name for x in cache.iterdir())
    assert len(files) == 1 and files[0].endswith(".msh") and not files[0].startswith("."), files
    n_nodes = {int(out.split()[0]) for out, _ in outs}
    mesh = read_msh(cache / files[0])
    assert n_nodes == {mesh.n_nodes}


@dataclasses.dataclass(frozen=True)
class Slot:
    """A new hole shape written only against the Feature protocol: a slot (stadium) along x, two
    straight sides and two half circles. Nothing in rvfem knows this class."""

    name: str
    centre: tuple[float, float]
    length: float          # distance between the two arc centres, mm
    radius: float          # half the width, mm

    def validate(self) -> None:
        assert self.length > 0 and self.radius > 0

    def outline(self):
        from rvfem.geometry import Arc, LineSegment

        (cx, cy), h, r = self.centre, 0.5 * self.length, self.radius
        return (LineSegment((cx - h, cy - r), (cx + h, cy - r)),
                Arc((cx + h, cy), r, -math.pi / 2, math.pi),
                LineSegment((cx + h, cy + r), (cx - h, cy + r)),
                Arc((cx - h, cy), r, math.pi / 2, math.pi))

    def signed_distance(self, p):
        (cx, cy), h = self.centre, 0.5 * self.length
        x = np.clip(p[:, 0], cx - h, cx + h)
        return np.hypot(p[:, 0] - x, p[:, 1] - cy) - self.radius

    def sample(self, spacing=0.02):
        return np.concatenate([q.sample(spacing)[:-1] for q in self.outline()])

    @property
    def area(self):
        return 2 * self.radius * self.length + math.pi * self.radius**2

    @property
    def sampling_length(self):
        return 2 * self.length + 2 * math.pi * self.radius


def test_a_new_feature_class_is_meshed_through_the_protocol(tmp_path):
    """The Feature protocol is all the mesher needs: a disc with a slot-shaped hole meshes, the
    slot's boundary is named after it, its nodes lie on the slot, and the area is the disc's."""
    from rvfem.mesh import mesh_geometry

    case = coarse(load_case(CASES / "rv40e_solid.toml"), 0.8, 0.8, 4.0)
    slot = Slot("hole_slot", (0.0, -30.0), 6.0, 2.0)
    geom = dataclasses.replace(disc_geometry(case), holes=(slot,))
    mesh = mesh_geometry(geom, tmp_path / "slot.msh")
    assert "hole_slot" in mesh.boundaries
    xy = mesh.points[mesh.boundary_nodes("hole_slot")]
    assert np.abs(slot.signed_distance(xy)).max() < 3e-15        # measured 8.9e-16 mm
    assert mesh.area == pytest.approx(geom.area, rel=1e-3)       # measured 4.1e-4 (straight edges)
