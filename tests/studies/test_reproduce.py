"""`stickslip reproduce`: recipes on a micro resolution write PNGs, report.md and a table row per figure."""

import json
import math

import pytest
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.studies.reproduce import RECIPES, _regimes, _spearman, recipe_names, reproduce

#: Recipes of Sects. 4.1–4.2.3 up to Fig. 12(a) (the micro report below); the region maps and
#: bifurcation diagrams of Figs. 8, 9, 12(b)–16 have their own fixtures so no test runs > ~10 s.
FIRST = ["fig3", "fig4", "table2", "fig7", "fig10", "fig11", "fig12a"]
REGION_FIGS = ["fig8", "fig9", "fig16"]
BIFURCATION_FIGS = ["fig12b", "fig13", "fig14", "fig15"]


@pytest.fixture(scope="module")
def micro_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce")
    return out, reproduce(out, "micro", only=FIRST)


@pytest.fixture(scope="module")
def region_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce_regions")
    return out, reproduce(out, "micro", only=REGION_FIGS)


@pytest.fixture(scope="module")
def bifurcation_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce_bifurcation")
    return out, reproduce(out, "micro", only=BIFURCATION_FIGS)


def _summary_rows(text):
    summary = text.split("## Summary: paper says / we measure / agrees?")[1]
    rows = [line for line in summary.splitlines() if line.startswith("| ") and not line.startswith("| item")]
    return [[c.strip() for c in r.strip("|").split(" | ")] for r in rows]


def test_report_and_figures_written(micro_report):
    out, report = micro_report
    assert report == out / "report.md" and report.is_file()
    results = json.loads((out / "results.json").read_text())
    entries = {e["name"]: e for e in results["recipes"]}
    assert set(entries) == set(FIRST)
    for recipe in [r for r in RECIPES if r.name in FIRST]:
        e = entries[recipe.name]
        assert e["status"] == "done", e.get("traceback")
        assert e["figures"], recipe.name
        for fig in e["figures"]:
            assert (out / fig).is_file() and (out / fig).stat().st_size > 1000
            assert f"]({fig})" in report.read_text()


def test_table_has_measured_row_per_figure(micro_report):
    out, report = micro_report
    text = report.read_text()
    summary = text.split("## Summary: paper says / we measure / agrees?")[1]
    rows = [line for line in summary.splitlines() if line.startswith("| ") and not line.startswith("| item")]
    items = [r.split(" | ")[0][2:] for r in rows]
    for prefix in ("Fig. 3", "Fig. 3(a)", "Fig. 3(b)", "Fig. 4", "Table 2", "Fig. 5", "Fig. 6", "Fig. 7", "Fig. 10",
                   "Fig. 11", "Fig. 12(a)"):
        assert any(i.startswith(prefix) for i in items), prefix
    for r in rows:
        cells = [c.strip() for c in r.strip("|").split(" | ")]
        assert len(cells) == 5, r
        assert cells[2] and cells[2] != "–"                     # a measured value from this run
        assert cells[3] in ("yes", "no", "not compared")
    assert "## Not yet reproduced" not in text                  # every figure of Sects. 4.1–4.2 has a recipe


def test_every_paper_figure_has_a_recipe():
    assert recipe_names() == ["fig3", "fig4", "table2", "fig7", "fig8", "fig9", "fig10", "fig11", "fig12a", "fig12b",
                              "fig13", "fig14", "fig15", "fig16"]


@pytest.mark.parametrize("fixture, names, items", [
    ("region_report", REGION_FIGS, ("Fig. 8, regions", "Fig. 8, trend", "Fig. 8 vs Fig. 7", "Fig. 9, Model 4",
                                    "Fig. 9, translation", "Fig. 16(a), (b)", "Fig. 16(c)")),
    # ~50 s (four bifurcation diagrams settled point by point): with the slow studies
    pytest.param("bifurcation_report", BIFURCATION_FIGS, ("Fig. 12(b), period", "Fig. 12(b), kind", "Fig. 13(a)",
                                                          "Fig. 13(b)", "Fig. 14(a)(b), Model 2",
                                                          "Fig. 14(c)(d), Model 3", "Fig. 14(e)(f), Model 4",
                                                          "Fig. 15"), marks=pytest.mark.slow),
])
def test_new_figures_rows_and_pngs(request, fixture, names, items):
    out, report = request.getfixturevalue(fixture)
    text = report.read_text()
    entries = {e["name"]: e for e in json.loads((out / "results.json").read_text())["recipes"]}
    assert set(entries) == set(names)
    for name in names:
        assert entries[name]["status"] == "done", entries[name].get("traceback")
        for fig in entries[name]["figures"]:
            assert (out / fig).stat().st_size > 1000 and f"]({fig})" in text
    rows = {cells[0]: cells for cells in _summary_rows(text)}
    for item in items:
        cells = rows[item]
        assert len(cells) == 5 and cells[2] and cells[4]           # measured value and an explicit criterion
        assert cells[3] in ("yes", "no", "not compared")


def test_region_figures_share_one_grid_and_count_every_cell(region_report):
    out, _ = region_report
    # Fig. 8 computed Model 1; Fig. 9 only Models 2-4; Fig. 16 reused both (no third map)
    assert sorted(p.name for p in out.glob("regions_*.nc")) == ["regions_full.nc", "regions_x_y_rotation.nc"]
    measured = {e["name"]: e["measured"] for e in json.loads((out / "results.json").read_text())["recipes"]}
    assert sum(measured["fig8"]["counts"].values()) == 2 * 2       # micro grid 2 N × 2 Ω
    assert set(measured["fig9"]["stick_slip_cells"]) == {"full", "x", "y", "rotation"}


def test_regimes_collapse_verdicts_along_the_control_parameter():
    labels = ["periodic", "periodic", "equilibrium", "chaotic", "failed", "quasiperiodic", "unsettled", "periodic"]
    assert _regimes([1, 2, 3, 4, 5, 6, 7, 8], labels) == [("P", 1.0, 2.0), ("NP", 4.0, 6.0), ("U", 7.0, 7.0),
                                                          ("P", 8.0, 8.0)]
    assert _regimes([1, 2, 3], ["equilibrium", "failed", "unbounded"]) == []


def test_spearman_on_ranks():
    assert _spearman([1, 2, 3, 4], [10, 20, 25, 100]) == pytest.approx(1.0)
    assert _spearman([1, 2, 3, 4], [4, 3, 2, 1]) == pytest.approx(-1.0)
    assert math.isnan(_spearman([1, 2], [1, 2]))


def test_measured_values_come_from_the_run(micro_report):
    out, _ = micro_report
    results = json.loads((out / "results.json").read_text())
    fig10 = next(e for e in results["recipes"] if e["name"] == "fig10")["measured"]
    assert set(fig10) == {"30", "120"}                          # the micro N list, not the paper's
    assert all(v["dominant_frequency_hz"] > 0 for v in fig10.values())
    for v in fig10.values():                                    # each run extended up to the micro cap
        assert 4.0 <= v["t_end_s"] <= 6.0 and (v["settle_time_s"] is None) == (not v["settled"])


def test_failed_recipe_is_reported_and_others_go_on(tmp_path, monkeypatch):
    import stickslip.studies.reproduce as rp

    def boom(out, res, cache):
        raise RuntimeError("synthetic failure")

    monkeypatch.setattr(rp, "RECIPES", [rp.Recipe("broken", "Broken figure", "nothing", boom), rp.RECIPES[1]])
    report = rp.reproduce(tmp_path, "micro")
    text = report.read_text()
    assert "**Failed**" in text and "synthetic failure" in text
    assert (tmp_path / "fig4.png").is_file()


def test_unknown_only_and_resolution_rejected(tmp_path):
    with pytest.raises(ValueError, match="unknown figure"):
        reproduce(tmp_path, "micro", only=["fig99"])
    with pytest.raises(ValueError, match="unknown resolution"):
        reproduce(tmp_path, "huge")
    result = CliRunner().invoke(app, ["reproduce", "--only", "fig99", "--out", str(tmp_path / "x")])
    assert result.exit_code == 2
    assert "unknown figure 'fig99'" in result.output
    assert not (tmp_path / "x").exists()


def test_cli_only_writes_report(tmp_path, monkeypatch):
    import stickslip.studies.reproduce as rp

    monkeypatch.setitem(rp.RESOLUTIONS, "quick", rp.RESOLUTIONS["micro"])
    result = CliRunner().invoke(app, ["reproduce", "--quick", "--only", "fig4", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "report.md").is_file() and (tmp_path / "fig4.png").is_file()
