"""`stickslip reproduce`: recipes on a micro resolution write PNGs, report.md and a table row per figure."""

import json

import pytest
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.studies.reproduce import RECIPES, recipe_names, reproduce


@pytest.fixture(scope="module")
def micro_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce")
    return out, reproduce(out, "micro")


def test_report_and_figures_written(micro_report):
    out, report = micro_report
    assert report == out / "report.md" and report.is_file()
    results = json.loads((out / "results.json").read_text())
    entries = {e["name"]: e for e in results["recipes"]}
    assert set(entries) == set(recipe_names())
    for recipe in RECIPES:
        e = entries[recipe.name]
        assert e["status"] == "done", e.get("traceback")
        assert e["figures"], recipe.name
        for fig in e["figures"]:
            assert (out / fig).is_file() and (out / fig).stat().st_size > 1000
            assert f"]({fig})" in report.read_text()


def test_table_has_measured_row_per_figure(micro_report):
    out, report = micro_report
    text = report.read_text()
    summary = text.split("## Summary: paper says / we measure / agrees?")[1].split("## Not yet reproduced")[0]
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
    assert "## Not yet reproduced" in text and "Fig. 8" in text


def test_measured_values_come_from_the_run(micro_report):
    out, _ = micro_report
    results = json.loads((out / "results.json").read_text())
    fig10 = next(e for e in results["recipes"] if e["name"] == "fig10")["measured"]
    assert set(fig10) == {"30", "120"}                          # the micro N list, not the paper's
    assert all(v["fft_frequency_hz"] > 0 for v in fig10.values())


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
