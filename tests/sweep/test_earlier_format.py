"""Sweeps written before the one vocabulary of outcomes (format stickslip-sweep-1, with a steady-state
``kind`` column): finished files are read in today's terms, unfinished journals refused in one line."""

import numpy as np
import pytest

from stickslip import OUTCOMES, SweepError
from stickslip.journal import RowJournal
from stickslip.sweep import load_sweep, sweep
from stickslip.sweep.spec import SweepSpec


def _format_1_file(path, kind, attractor=None):
    """A sweep file as stickslip 0.1.0 wrote it: ``kind`` (−1 failed, 0 equilibrium, 1 periodic
    slip, 2 periodic stick-slip, 3 non-periodic) and ``attractor`` (−1 failed, else the verdict)."""
    import xarray as xr

    n = len(kind)
    data = {"done": (("N",), np.ones(n, np.int8)), "stick_fraction": (("N",), np.full(n, 0.2)),
            "kind": (("N",), np.asarray(kind, float), {"flag_values": "-1 0 1 2 3",
                                                       "flag_meanings": "failed equilibrium periodic-slip "
                                                                        "periodic-stick-slip non-periodic"})}
    if attractor is not None:
        data["attractor"] = (("N",), np.asarray(attractor, float), {"flag_values": "-1 0 1 2 3 4 5"})
    ds = xr.Dataset(data, coords={"N": np.arange(10.0, 10.0 * (n + 1), 10.0)},
                    attrs={"format": "stickslip-sweep-1", "digest": "0123456789abcdef", "complete": 1})
    ds.to_netcdf(path, engine="h5netcdf")


def test_a_format_1_sweep_reads_with_its_outcomes_in_todays_codes(tmp_path):
    _format_1_file(tmp_path / "old.nc", kind=[0, 2, 3, -1, -1], attractor=[0, 1, 3, 4, -1])
    ds = load_sweep(tmp_path / "old.nc")
    assert "kind" not in ds.variables
    names = [OUTCOMES[int(c)] for c in ds["attractor"].values]
    assert names == ["equilibrium", "periodic", "chaotic", "unbounded", "failed"]
    assert ds["attractor"].attrs["flag_meanings"].split() == list(OUTCOMES)
    assert ds.attrs["format"] == "stickslip-sweep-1"  # what the file is; the file itself is not changed


def test_a_format_1_sweep_without_verdicts_takes_them_from_its_kinds(tmp_path):
    _format_1_file(tmp_path / "older.nc", kind=[0, 1, 2, 3, -1])
    names = [OUTCOMES[int(c)] for c in load_sweep(tmp_path / "older.nc")["attractor"].values]
    assert names == ["equilibrium", "periodic", "periodic", "unsettled", "failed"]


def test_the_journal_of_an_unfinished_format_1_sweep_is_refused_in_one_line(tmp_path):
    out = tmp_path / "s.nc"
    spec = SweepSpec.build({"N": [30.0, 50.0]}, t_end=2.0)
    old = RowJournal(out, width=spec.row_width + 1, size=spec.size, kind="sweep", digest=spec.digest,
                     settings={}, noun="sweep", differs="grid or options differ", error=SweepError)
    old.append([0], np.zeros((1, spec.row_width + 1)))  # a finished point with the retired kind column
    old.close()
    with pytest.raises(SweepError) as err:
        sweep(spec, out=out, executor="serial")
    text = str(err.value)
    assert "\n" not in text and f"holds rows of {spec.row_width + 1} numbers" in text and "--overwrite" in text
    assert (out.parent / "s.nc.journal" / "rows.f64").stat().st_size > 0  # kept, to finish with the old version
