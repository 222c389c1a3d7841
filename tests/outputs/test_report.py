"""The outputs of a run: the writer registry (its order, a run writing exactly the registered files,
a writer added without touching the run) and ``report.html`` from its Jinja2 template (every
section rendered, every value escaped, the template shipped with the package).

The tests on a result folder share one coarse ``rvfem run`` of the default case (30° steps, no
images), with one writer registered by this module for the run."""

from __future__ import annotations

import copy
import json
import tomllib
from html.parser import HTMLParser
from importlib import resources
from pathlib import Path

import jinja2
import pytest
from conftest import CASES_DIR, ROOT, saved_registries

from rvfem.app import cli, screen
from rvfem.case.definition import case_from_dict, case_to_dict, load_case
from rvfem.outputs import registry, report, roller_outputs
from rvfem.outputs import summary as outputs

COARSE = ["--set", "mesh.size_flank=0.6", "--set", "mesh.size_bore=0.6", "--set", "mesh.size_interior=4.0",
          "--step", "30", "--no-images"]

BUILT_IN = ["tables", "roller_pressure_csv", "roller_damage_csv", "case_json", "vtk", "plots", "images", "report",
            "summary"]
"""The built-in writers in the order a run calls them."""

SECTIONS = [
    "Crank-bearing loads and lives: rigid handbook vs flexible disc", "Other results",
    "What the flexibility delta is made of", "What this delta depends on", "Hertz pressure of the most loaded roller",
    "The crank bearing in depth: pressure along the rollers, film and lives", "Mass, inertia and strength",
    "Plots", "Case parameters", "Assumptions", "Files and timings",
]
"""The headings (h2) of every report, in order."""

EXTRA = "registered_by_a_test.txt"


def _write_extra(analysis, folder, *, tick=None) -> list[Path]:
    """A writer defined here: one line with the case name."""
    path = Path(folder) / EXTRA
    path.write_text(analysis.case.name + "\n", encoding="utf-8")
    return [path]


# --------------------------------------------------------------------------------------------
# A coarse run of the default case, with one more writer registered
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory) -> Path:
    work = tmp_path_factory.mktemp("report")
    out = work / "run"
    with saved_registries():                  # the registry as it was, afterwards
        registry.register_writer("extra", order=25, stage="tables", options=("tick",), files=(EXTRA,))(_write_extra)
        code = cli.main(["run", str(CASES_DIR / "rv40e_fanholes.toml"), "-o", str(out),
                         "--cache-dir", str(work / "meshes"), *COARSE])
    assert code == 0
    return out


@pytest.fixture(scope="module")
def summary(run_folder) -> dict:
    return json.loads((run_folder / "summary.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def case(run_folder):
    return case_from_dict(json.loads((run_folder / "case.json").read_text(encoding="utf-8")))


class _Page(HTMLParser):
    """The visible text of a page (style excluded), its h2 headings and whether its tags nest."""

    VOID = {"meta", "img", "br", "hr", "link", "input"}
    BLOCKS = {"title", "h1", "h2", "h3", "p", "ul", "li", "table", "tr", "th", "td", "div", "figure", "figcaption"}

    def __init__(self, page: str):
        super().__init__(convert_charrefs=True)
        self.text, self.headings, self.open, self.errors = [], [], [], []
        self._style = self._h2 = False
        self.feed(page)
        self.close()

    def handle_starttag(self, tag, attrs):
        if tag in self.BLOCKS:
            self.text.append(" ")
        if tag not in self.VOID:
            self.open.append(tag)
        self._style |= tag == "style"
        if tag == "h2":
            self._h2, self.headings = True, self.headings + [""]

    def handle_endtag(self, tag):
        if tag in self.BLOCKS:
            self.text.append(" ")
        if not self.open or self.open[-1] != tag:
            self.errors.append(f"</{tag}> closes <{self.open[-1] if self.open else None}>")
        else:
            self.open.pop()
        self._style &= tag != "style"
        self._h2 &= tag != "h2"

    def handle_data(self, data):
        if not self._style:
            self.text.append(data)
            if self._h2:
                self.headings[-1] += data

    @property
    def visible(self) -> str:
        return " ".join("".join(self.text).split())


def _render(summary: dict, case, root: Path) -> str:
    return report.render_report(report.report_context(summary, case, root))


# --------------------------------------------------------------------------------------------
# The registry
# --------------------------------------------------------------------------------------------


def test_the_writers_are_registered_in_the_order_a_run_calls_them():
    writers = outputs.writers()
    assert [w.name for w in writers] == BUILT_IN
    assert [w.order for w in writers] == sorted(w.order for w in writers)
    assert [w.name for w in outputs.writers(images=False)] == [n for n in BUILT_IN if n != "images"]
    # the registered functions are the public writers, with the options a run passes them
    public = {"tables": outputs.write_tables, "case_json": outputs.write_case_json, "vtk": outputs.write_vtk,
              "plots": outputs.write_plots, "images": outputs.write_images, "report": outputs.write_report,
              "summary": outputs.write_summary, "roller_pressure_csv": roller_outputs.write_roller_pressure_csv,
              "roller_damage_csv": roller_outputs.write_roller_damage_csv}
    for w in writers:
        assert w.write is public[w.name]
        assert set(w.options) <= set(registry.OPTIONS)
    # those that need the summary come last and name their files exactly; summary.json is the last
    last = [w for w in writers if w.needs_summary]
    assert writers[-len(last):] == tuple(last) and [w.files for w in last] == [("report.html",), ("summary.json",)]
    assert writers[-1].stage is None and all(w.stage for w in writers[:-1])


def test_register_writer_refuses_a_taken_name_or_order_and_unknown_options(registries):
    before = dict(registry._WRITERS)
    with pytest.raises(ValueError, match="order 10 is taken by the writer 'tables'"):
        registry.register_writer("other", order=10, stage="tables")(_write_extra)
    with pytest.raises(ValueError, match="is registered already"):
        registry.register_writer("tables", order=11, stage="tables")(_write_extra)
    with pytest.raises(ValueError, match="unknown options"):
        registry.register_writer("other", order=11, stage="tables", options=("colour",))
    assert registry._WRITERS == before


@pytest.mark.slow
def test_a_run_writes_exactly_the_registered_files(run_folder, summary):
    on_disk = sorted(p.relative_to(run_folder).as_posix() for p in run_folder.rglob("*")
                     if p.is_file() and p.name != outputs.RESULT_MARKER)   # the marker: who wrote the folder
    assert on_disk == summary["files"]
    writers = outputs.writers(images=False)
    assert "extra" not in {w.name for w in writers}              # the test's writer is gone again
    for rel in on_disk:
        owners = [w.name for w in writers if w.owns(rel)] or (["extra"] if rel == EXTRA else [])
        assert len(owners) == 1, f"{rel} is written by {owners or 'no registered writer'}"
    for w in writers:                                            # each writer of the run wrote its files
        assert any(w.owns(rel) for rel in on_disk), w.name
    assert (run_folder / EXTRA).read_text(encoding="utf-8") == summary["case"]["name"] + "\n"
    page = (run_folder / "report.html").read_text(encoding="utf-8")
    assert f"<code>{EXTRA}</code>" in page                      # the report lists the added file


# --------------------------------------------------------------------------------------------
# report.html
# --------------------------------------------------------------------------------------------


def test_the_template_ships_with_the_package():
    """The template is package data (found by an installed wheel as by a source checkout)."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert config["tool"]["setuptools"]["package-data"]["rvfem.outputs"] == ["templates/*.j2"]
    assert any(d.replace(" ", "").startswith("jinja2>=3.1") for d in config["project"]["dependencies"])
    template = resources.files("rvfem.outputs") / "templates" / report.TEMPLATE
    assert template.is_file()
    env = report.template_environment()
    assert isinstance(env.loader, jinja2.PackageLoader) and env.autoescape is True
    assert env.loader.get_source(env, report.TEMPLATE)[0] == template.read_text(encoding="utf-8")


def test_the_hole_tables_are_described_by_their_shapes():
    data = case_to_dict(load_case(CASES_DIR / "rv40e_fanholes.toml"))
    data["round_holes"] = {"count": 3, "radius": 3.0, "circle_radius": 55.0}
    case = case_from_dict(data)
    rows = report._case_rows(case)
    assert rows[-2:] == [["fan holes", "3, r = 17…49 mm, ligament 4.5 mm, fillet 2 mm"],
                         ["round holes", "3 × r = 3 mm on r = 55 mm"]]
    solid = report._case_rows(load_case(CASES_DIR / "rv40e_solid.toml"))
    assert [r[0] for r in solid][-1] == "mesh sizes"


@pytest.mark.slow
def test_the_report_of_a_run_renders_every_section(run_folder, summary, case):
    page = _Page((run_folder / "report.html").read_text(encoding="utf-8"))
    assert not page.errors and page.open == []                  # every tag closed where it opens
    assert page.headings == SECTIONS                             # no warnings, no images: not shown
    text = page.visible
    assert f"Crank-bearing loads with a flexible cycloid disc — {summary['case']['name']}" in text
    assert summary["case"]["description"] in text
    for b in summary["bearings"]:
        for model in ("rigid", "flexible"):
            assert f"{b[model]['max_load_N']:.0f}" in text and f"{b[model]['L10h_h']:.0f}" in text
        assert f"{b['delta_max_percent']:+.1f} %" in text and f"{b['life_ratio']:.3f}" in text
    sp = summary["stress"]["structural_peak"]
    assert f"{sp['von_mises_MPa']:.1f} MPa ± {sp['estimated_error_MPa']:.1f} MPa estimated" in text
    for r in summary["attribution"]:
        assert f"{r['step']}: {r['label']}" in text
    for f in summary["files"]:
        assert f in text
    raw = (run_folder / "report.html").read_text(encoding="utf-8")
    assert raw.count('<img src="data:image/png;base64,') == len(summary["plots"]) == 6 and "<" not in text
    overrides = ", ".join(f"{k} = {report.toml_text(v)}" for k, v in summary["case"]["overrides"].items())
    assert f"overrides: {overrides}" in text
    assert "fan holes 3, r = 17…49 mm, ligament 4.5 mm, fillet 2 mm" in text
    for sentence in report.assumptions(summary, case):
        plain = sentence if isinstance(sentence, str) else "".join(p if isinstance(p, str) else p["b"]
                                                                   for p in sentence)
        assert " ".join(plain.split()) in text


@pytest.mark.slow
def test_the_optional_sections_render_when_the_summary_has_them(run_folder, summary, case, tmp_path):
    """Warnings, the duty cycle and its FE check, stress images (key angles embedded, others
    linked), a case built in code: each appears when the summary holds it."""
    png = b"\x89PNG\r\n\x1a\n" + bytes(range(64))
    (tmp_path / "images").mkdir()
    s = copy.deepcopy(summary)
    s["warnings"] = [{"code": "load_ratio", "message": "P/C = 6.09 (bearing 1, flexible) > 0.5"}]
    life = {"rated_life_h": 1234.0, "equivalent_torque_Nm": 400.0, "equivalent_speed_rpm": 12.5,
            "service_life_h": 2345.0}
    s["duty_cycle"] = {"rigid": life, "flexible": dict(life, service_life_h=2000.0), "flexible_fe": {
        "torques_Nm": [200.0, 412.0], "linear_scaling_error_percent": [0.5, -0.25], "service_life_h": 1990.0,
        "life_difference_percent": -0.5, "seconds": 3.25}}
    key = report.key_field_angles(s, case)
    s["fields"] = [{"theta_deg": a, "vtu": f"vtk/{a}.vtu", "image": f"images/key_{i}.png"} for i, a in enumerate(key)]
    s["fields"].append({"theta_deg": 333.0, "vtu": "vtk/333.vtu", "image": "images/extra.png"})
    s["images"] = {"mesh": "images/mesh.png", "stress_peak_closeup": "images/closeup.png"}
    for rel in [f["image"] for f in s["fields"]] + list(s["images"].values()):
        (tmp_path / rel).write_bytes(png)
    s["case"].update(file=None, matches_file=False, defaults_used={})
    page = _Page(_render(s, case, tmp_path))
    assert not page.errors and page.open == []
    assert page.headings == ["Warnings: results outside their model's range"] + SECTIONS[:-4] + \
        ["Plots", "Stress images"] + SECTIONS[-3:]
    text = page.visible
    assert "load_ratio: P/C = 6.09 (bearing 1, flexible) > 0.5" in text
    assert "Duty cycle (Palmgren–Miner)" in text and "flexible 1234 400.0 12.50 2000" in text
    assert ("(200, 412 N·m): F_m differs from the linear scaling by +0.50 %, -0.25 %; Palmgren–Miner over the rows "
            "with those loads gives a service life of 1990 h (-0.5 % against the linear scaling; 3.2 s)") in text
    page_html = _render(s, case, tmp_path)
    assert page_html.count('<img src="data:image/png;base64,') == len(key) + 2     # key angles, close-up, mesh
    assert "<a href='images/extra.png'>333°</a>" in page_html
    assert "The case was built or modified in code; case.json holds every value used." in text
    assert "Where the case file is silent" not in text and "(sha256" not in text


@pytest.mark.slow
def test_every_value_is_escaped(run_folder, summary, case):
    """Markup in a case name, a description, an override or a warning is shown as text."""
    s = copy.deepcopy(summary)
    s["case"].update(name="<b>bold</b> & 'quoted'", description="<img src=x onerror=alert(1)>")
    s["case"]["overrides"] = {"<script>": "</td>"}
    s["warnings"] = [{"code": "<i>", "message": "a < b & c > d"}]
    page_html = _render(s, case, run_folder)
    assert "<b>bold</b>" not in page_html and "<img src=x" not in page_html and "<script>" not in page_html
    assert "&lt;b&gt;bold&lt;/b&gt; &amp; &#39;quoted&#39;" in page_html
    page = _Page(page_html)
    assert not page.errors and page.open == []
    text = page.visible
    assert "<b>bold</b> & 'quoted'" in text and "<img src=x onerror=alert(1)>" in text
    assert '<script> = "</td>"' in text and "<i>: a < b & c > d" in text


@pytest.mark.slow
def test_the_screen_text_has_every_part(summary):
    text = screen.summary_text(summary)
    lines = text.splitlines()
    assert lines[0].startswith(f"Case {summary['case']['name']} (") and "overrides: mesh.size_flank = 0.6" in lines[0]
    assert sum(line.split()[:1] == ["flexible"] for line in lines) == 3
    assert sum("life ratio" in line and "delta" in line for line in lines) == 3
    for part in ("  references: ", "  reducer stage: ", "  what the delta of bearing 1 is made of",
                 "  structural stress peak", "  pins in contact", "  Hertz, most loaded roller: ", "  wall time"):
        assert any(line.startswith(part) for line in lines), part
    assert not any(line.startswith("  duty cycle") or line.startswith("  warning") for line in lines)
    s = copy.deepcopy(summary)
    s["duty_cycle"] = {"rigid": None, "flexible": {"service_life_h": 2000.0, "equivalent_torque_Nm": 400.0,
                                                   "equivalent_speed_rpm": 12.5}}
    s["warnings"] = [{"code": "load_ratio", "message": "P/C above 0.5"}]
    lines = screen.summary_text(s).splitlines()
    assert ("  duty cycle: service life rigid not defined, flexible 2000 h (equivalent torque 400.0 N·m, speed "
            "12.50 rpm; loads scaled linearly with the torque)") in lines
    assert lines[-2:] == ["", "  warning: P/C above 0.5"]


def test_the_report_says_whether_the_bearing_has_clearance_or_preload():
    from rvfem.outputs.report import clearance_text

    assert clearance_text(0.01) == "radial clearance 10 µm"
    assert clearance_text(-0.005).startswith("preload 5 µm")
    assert clearance_text(0.0) == "no radial clearance and no preload"
