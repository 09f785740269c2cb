"""
A sweep on a dask cluster
=========================

:func:`stickslip.sweep` sends its points in batches to an executor: one process, a pool of
processes, or dask. Given a scheduler's ``address`` it runs on that cluster; workers import
``stickslip`` and return rows to this process, which alone writes the journal and the NetCDF.
Here the cluster is a small local one in this process (on a real cluster: ``dask scheduler`` and
``dask worker ADDRESS --nthreads 1`` on each node). The model is the ``belt``; the swept parameter
is its belt speed, a parameter path of the model.
"""

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from distributed import LocalCluster

import stickslip
from stickslip.plot.sweep import plot_reduction

with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster, \
        tempfile.TemporaryDirectory() as tmp:
    res = stickslip.sweep({"contact.0.drive": np.linspace(0.2, 2.6, 25)}, "belt", t_end=150.0,
                          executor="dask", address=cluster.scheduler_address, out=Path(tmp) / "belt.nc")
    ds = res.to_xarray().load()
print(dict(ds.sizes), list(ds.data_vars)[:8], "...")
print(res.outcomes())

# %%
# The amplitude of the observed coordinate x and the fraction of time stuck, against the belt speed.
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
plot_reduction(res, "amplitude", ax1)
plot_reduction(res, "stick_fraction", ax2)
