"""
Regions of bistability over (N, Ω)
==================================

The paper's Fig. 8, coarse: at each (N, Ω) the plates are started twice, near steady sliding and
far from it, and the two steady states are compared. Region I: both reach steady sliding;
Region II: steady sliding and a stick-slip cycle coexist; Region III: both reach the cycle.
"""

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import stickslip
from stickslip.plot.regions import plot_regions

with tempfile.TemporaryDirectory() as tmp:
    rmap = stickslip.regions(N=np.linspace(20, 120, 5), Omega=np.linspace(1, 13, 5), variants=["full"],
                             out=Path(tmp) / "regions.nc", t_end=60.0, t_from=40.0, executor="serial")
print(rmap.region)  # (model, N, Ω): 1 = I, 2 = II, 3 = III, 0 = other

# %%
fig, ax = plt.subplots(figsize=(6, 4.5), layout="constrained")
plot_regions(rmap, ax)
