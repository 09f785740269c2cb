"""The command line builds and writes NetCDF without importing dask.array, and xarray still
tells dask arrays apart once dask.array is imported (:mod:`stickslip.cli._xarray_dask`)."""

import json
import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent("""
    import json, sys
    import stickslip.cli  # installs the deferred answer before xarray is imported
    import numpy as np
    import xarray as xr
    from xarray.namedarray.pycompat import array_type, mod_version
    out = sys.argv[1]
    xr.Dataset({"a": ("t", np.arange(4.0))}, coords={"t": np.arange(4.0)}).to_netcdf(out, engine="h5netcdf")
    before = {"dask.array": "dask.array" in sys.modules, "type": len(array_type("dask")),
              "roundtrip": xr.open_dataset(out, engine="h5netcdf").load()["a"].values.tolist()}
    import dask
    import dask.array as da
    masked = da.from_array(np.ma.masked_array(np.arange(3.0), mask=[0, 1, 0]), chunks=2)
    after = {"type": [t.__module__ + "." + t.__name__ for t in array_type("dask")],
             "version": str(mod_version("dask")) == dask.__version__,
             "chunks": xr.DataArray(da.zeros(6, chunks=3)).chunks,
             "masked": np.isnan(xr.DataArray(masked).compute().values).tolist()}
    print(json.dumps({"before": before, "after": after}))
""")


def test_no_dask_array_until_imported_then_dask_arrays_as_before(tmp_path):
    run = subprocess.run([sys.executable, "-c", SCRIPT, str(tmp_path / "a.nc")], capture_output=True, text=True,
                         check=True, timeout=120)
    seen = json.loads(run.stdout.strip().splitlines()[-1])
    assert seen["before"] == {"dask.array": False, "type": 0, "roundtrip": [0.0, 1.0, 2.0, 3.0]}
    assert seen["after"] == {"type": ["dask.array.core.Array"], "version": True, "chunks": [[3, 3]],
                             "masked": [False, True, False]}
