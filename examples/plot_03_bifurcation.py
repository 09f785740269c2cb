"""
A bifurcation diagram of the plates
===================================

A sweep over the normal load N at Ω = 0.5 rad/s (the paper's Fig. 12(a), coarse): one run per
grid point, of which only reductions are kept — here the peak values of φ in the steady window
(the second half of each run). ``executor="serial"`` runs in this process; ``"processes"`` (the
default) uses every core.
"""

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import stickslip
from stickslip.plot.sweep import plot_bifurcation

with tempfile.TemporaryDirectory() as tmp:
    res = stickslip.sweep({"N": np.linspace(10, 130, 21)}, stickslip.Parameters(Omega=0.5),
                          out=Path(tmp) / "bifurcation.nc", t_end=200.0, executor="serial")
    print(res.outcomes())

# %%
# The peaks show the diagram's structure: one branch at low N, two and more above ≈ 75 N. Over
# windows this short (the translational modes decay over ~200 s) the settle rule claims no period,
# so the points are drawn as non-periodic; a period is claimed only from longer runs
# (``t_end``, ``t_from``).
fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
plot_bifurcation(res, ax)
