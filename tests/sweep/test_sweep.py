"""Sweeps: executors agree, a killed sweep resumes to the identical dataset, files are checked."""

import importlib
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from stickslip.files import FileFormatError
from stickslip.sweep import SweepError, load_sweep, regions, sweep
from stickslip.sweep.spec import TIMING_COLUMNS

GRID = {"N": [30.0, 50.0, 70.0], "Omega": [0.5, 5.0]}
OPTS = dict(t_end=10.0, t_from=5.0, sample_rate=200.0)


def _assert_same(a, b):
    """Every variable identical (bit for bit, NaNs equal) except machine timings."""
    assert set(a.data_vars) == set(b.data_vars)
    for name in a.data_vars:
        if name not in TIMING_COLUMNS:
            assert a[name].equals(b[name]), name
    for name in a.coords:
        assert a[name].equals(b[name]), name


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    return sweep(GRID, out=tmp_path_factory.mktemp("s") / "serial.nc", executor="serial", **OPTS)


def test_dataset_layout(serial):
    ds = serial.to_xarray()
    assert tuple(ds["attractor"].dims) == ("N", "Omega")
    assert ds["peaks"].dims == ("N", "Omega", "peak")
    assert ds["N"].attrs["units"] == "N" and ds["Omega"].attrs["units"] == "rad/s"
    assert ds["frequency"].attrs["units"] == "Hz"
    assert ds.attrs["format"] == "stickslip-sweep-2" and ds.attrs["complete"] == 1
    assert ds.attrs["param_mu_k"] == 0.2
    assert np.all(ds["done"] == 1) and np.all(ds["t_reached"] == OPTS["t_end"])
    assert set(serial.outcomes().ravel()) <= {"equilibrium", "periodic", "quasiperiodic", "chaotic", "unsettled"}
    # stick-slip at Ω = 0.5 rad/s for every N (Fig. 12(a))
    assert np.all(ds["stick_fraction"].sel(Omega=0.5) > 0)


def test_processes_match_serial(serial, tmp_path):
    res = sweep(GRID, out=tmp_path / "p.nc", executor="processes", workers=2, batch_size=2, **OPTS)
    _assert_same(serial.dataset, res.dataset)


def test_dask_local_cluster_matches_serial(serial, tmp_path):
    pytest.importorskip("distributed")
    res = sweep(GRID, out=tmp_path / "d.nc", executor="dask", workers=2, **OPTS)
    assert res.timings["cluster_start_s"] > 0  # a real LocalCluster was started
    _assert_same(serial.dataset, res.dataset)


def test_local_cluster_workers_start_without_malloc_trim_threshold():
    # dask's nanny sets MALLOC_TRIM_THRESHOLD_, which makes glibc map and unmap every sample
    # buffer per point (20 % slower points); our LocalCluster's workers start without it
    pytest.importorskip("distributed")
    from distributed import Client

    from stickslip.parallel import local_cluster

    with local_cluster(1) as cluster, Client(cluster) as client:
        env = client.run(lambda: {k: os.environ.get(k) for k in ("MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS")})
    (worker_env,) = env.values()
    assert worker_env["MALLOC_TRIM_THRESHOLD_"] is None
    assert worker_env["OMP_NUM_THREADS"] == "1"  # the rest of the nanny's environment is kept


#: The child writes no snapshot of its output (the first point's compile, over a minute from a cold
#: cache on a loaded machine, would otherwise pass the snapshot interval): killed, it leaves the
#: journal only.
_CHILD = textwrap.dedent("""
    import sys
    from stickslip.sweep import sweep
    sweep({grid!r}, out=sys.argv[1], executor="serial", batch_size=1, snapshot_interval=1e9, **{opts!r})
""")


def test_killed_sweep_resumes_to_identical_dataset(serial, tmp_path):
    out = tmp_path / "k.nc"
    rows = Path(str(out) + ".journal") / "rows.f64"
    grid = {"N": GRID["N"], "Omega": GRID["Omega"]}
    proc = subprocess.Popen([sys.executable, "-c", _CHILD.format(grid=grid, opts=OPTS), str(out)])
    deadline = time.time() + 120
    width = 8 * (serial.spec.row_width + 2)
    # kill for real (SIGKILL) once some but not all points are journaled
    while time.time() < deadline:
        if rows.exists() and rows.stat().st_size >= 2 * width:
            os.kill(proc.pid, signal.SIGKILL)
            break
        if proc.poll() is not None:
            break
        time.sleep(0.005)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the child finished before it could be killed"
    done_before = rows.stat().st_size // width
    assert 2 <= done_before < 6 and not out.exists()
    res = sweep(grid, out=out, executor="serial", **OPTS)
    assert res.timings["points_resumed"] == done_before
    assert res.timings["points_computed"] == 6 - done_before
    _assert_same(serial.dataset, res.dataset)
    assert not rows.exists()  # journal removed once the NetCDF is complete
    # a second call finds the complete file and recomputes nothing
    again = sweep(grid, out=out, executor="serial", **OPTS)
    assert again.timings["points_computed"] == 0


def test_torn_journal_record_is_recomputed(serial, tmp_path):
    out = tmp_path / "t.nc"
    sweep(GRID, out=out, executor="serial", keep_journal=True, **OPTS)
    rows = Path(str(out) + ".journal") / "rows.f64"
    width = 8 * (serial.spec.row_width + 2)
    with open(rows, "r+b") as fh:  # as if killed in the middle of writing the 4th record
        fh.truncate(3 * width + width // 2)
    out.unlink()
    res = sweep(GRID, out=out, executor="serial", **OPTS)
    assert res.timings["points_resumed"] == 3
    _assert_same(serial.dataset, res.dataset)


def test_foreign_and_mismatched_files_are_refused(serial, tmp_path):
    foreign = tmp_path / "foreign.nc"
    foreign.write_text("not a netcdf file")
    with pytest.raises(FileFormatError, match="not a stickslip NetCDF file"):
        load_sweep(foreign)
    with pytest.raises(SweepError, match="refusing to overwrite"):
        sweep(GRID, out=foreign, executor="serial", **OPTS)
    with pytest.raises(SweepError, match="different sweep"):
        sweep({"N": [30.0]}, out=serial.path, executor="serial", **OPTS)
    traj_file = tmp_path / "run.nc"
    import stickslip

    stickslip.simulate(None, 0.1).to_netcdf(traj_file)
    with pytest.raises(FileFormatError, match="is a stickslip trajectory file, not a stickslip sweep"):
        load_sweep(traj_file)


@pytest.mark.parametrize("grid, match", [
    ({"nonsense": [1.0]}, "cannot sweep"),
    ({"N": [-1.0]}, "N"),
    ({"ic": ["sideways"]}, "unknown"),
    ({"N": [1.0, 1.0]}, "repeats"),
])
def test_invalid_grids(grid, match, tmp_path):
    with pytest.raises(ValueError, match=match):
        sweep(grid, out=tmp_path / "x.nc", executor="serial", **OPTS)


def test_regions_of_known_cases(tmp_path):
    # Sect. 4.2.2 at N = 50 N: coexistence at 8.5 rad/s, equilibrium only at 12 rad/s
    rm = regions([50.0], [8.5, 12.0], out=tmp_path / "r.nc", t_end=60.0, executor="serial")
    assert rm.region[0, 0].tolist() == [2, 3]
    assert rm.dataset["stick_slip_omega_max"].values[0, 0] == 8.5
    from stickslip.sweep import load_region_map

    back = load_region_map(tmp_path / "r.nc")
    assert back.region.tolist() == rm.region.tolist()


@pytest.mark.slow
def test_region_one_at_omega_5():
    # the near IC departs the unstable equilibrium (growth rate 0.05 1/s) only after ~150 s
    rm = regions([50.0], [5.0], t_end=300.0, t_from=200.0, executor="serial")
    assert rm.region[0, 0, 0] == 1


# ----------------------------------------------------------------------------- bounded-memory assembly
@pytest.mark.parametrize("shape", [(7,), (3, 5), (2, 3, 4), (1, 6, 1, 5)])
def test_flat_hyperslabs_tile_any_range_in_c_order(shape):
    from stickslip.sweep.store import flat_hyperslabs

    size = int(np.prod(shape))
    expected = np.arange(size).reshape(shape)           # C order by definition
    for a in range(size):
        for b in range(a + 1, size + 1):
            got = np.full(shape, -1)
            slabs = flat_hyperslabs(shape, a, b)
            assert len(slabs) <= 2 * len(shape) - 1
            assert [lo for _, lo, _ in slabs][0] == a and slabs[-1][2] == b
            for index, lo, hi in slabs:
                block_shape = tuple(s.stop - s.start for s in index)
                got[index] = np.arange(lo, hi).reshape(block_shape)
            assert np.array_equal(got[got >= 0], expected.ravel()[a:b])


def test_assembly_in_slabs_places_out_of_order_rows(tmp_path, monkeypatch):
    store = importlib.import_module("stickslip.sweep.store")
    from stickslip.sweep.spec import SweepSpec

    monkeypatch.setattr(store, "SLAB_POINTS", 4)        # several slabs, ranges that split the grid rows
    monkeypatch.setattr(store, "READ_ROWS", 3)          # several journal blocks
    spec = SweepSpec.build({"N": [10.0, 20.0, 30.0], "Omega": [1.0, 2.0, 3.0, 4.0, 5.0]}, t_end=2.0, n_peaks=3)
    journal = store.Journal(tmp_path / "j.nc", spec)
    rng = np.random.default_rng(1)
    rows = rng.normal(size=(spec.size, spec.row_width))
    done = [i for i in range(spec.size) if i != 7]      # point 7 (N = 20, Ω = 3) never computed
    order = rng.permutation(done)
    for chunk in np.array_split(order, 5):
        journal.append(chunk, rows[chunk])
    store.assemble(journal, tmp_path / "j.nc")
    ds = load_sweep(tmp_path / "j.nc")
    names = [c[0] for c in spec.columns]
    attractor_col = 0
    peaks_col = sum(c[1] for c in spec.columns[: names.index("peaks")])
    for i in range(spec.size):
        n, w = divmod(i, 5)
        if i == 7:
            assert ds["done"].values[n, w] == 0 and np.isnan(ds["attractor"].values[n, w])
            assert np.all(np.isnan(ds["peaks"].values[n, w]))
        else:
            assert ds["done"].values[n, w] == 1
            assert ds["attractor"].values[n, w] == rows[i, attractor_col]
            assert np.array_equal(ds["peaks"].values[n, w], rows[i, peaks_col : peaks_col + 3])
    assert not (journal.dir / "ordered.f64").exists()   # scratch file removed


def test_large_sweeps_are_returned_lazily(tmp_path, monkeypatch):
    store = importlib.import_module("stickslip.sweep.store")

    monkeypatch.setattr(store, "LOAD_LIMIT_POINTS", 2)
    lazy = sweep({"N": [30.0, 50.0, 70.0]}, out=tmp_path / "lazy.nc", executor="serial", t_end=2.0)
    var = lazy.dataset["attractor"].variable
    assert not isinstance(var._data, np.ndarray)        # backed by the file, not read yet
    loaded = load_sweep(tmp_path / "lazy.nc")
    _assert_same(loaded, lazy.dataset)
