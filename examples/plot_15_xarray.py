"""
Reading results with xarray
===========================

Every result writes a self-describing NetCDF file: the samples with their units, every
parameter, the method, the tolerances and the package version in the attributes.
``traj.to_xarray()`` gives the same dataset in memory, :func:`stickslip.load_trajectory` reads a
file back as a :class:`~stickslip.Trajectory`, and any NetCDF reader (here ``xarray``) opens it.
"""

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import xarray as xr

import stickslip

traj = stickslip.simulate("belt", 40.0, ic={"x": 1.0, "dx": 1.0})
with tempfile.TemporaryDirectory() as tmp:
    path = Path(tmp) / "run.nc"
    traj.to_netcdf(path)
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        ds = ds.load()
    again = stickslip.load_trajectory(path)
print(ds)
print({key: ds.attrs[key] for key in ("stickslip_version", "method") if key in ds.attrs})
print("read back:", again.t.shape, again.state_names)

# %%
# Variables carry their units; selections and plots work on names.
name = next(iter(ds.data_vars))
print(name, ds[name].attrs)
late = ds.sel(time=slice(20.0, 40.0))
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
late[name].plot.line(ax=ax, x="time")
