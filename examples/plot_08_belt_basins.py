"""
Basins of the belt, and a parameter study
=========================================

The ``belt`` model (a mass on a moving belt, bSTAB's friction case) has two attractors at its
default belt speed: steady sliding and a stick-slip cycle. :func:`stickslip.basin_stability`
runs every initial state with exact stick, names the attractor it reaches and returns the
fractions with their standard errors. On a regular grid the labels make a basin image; with
``param`` and ``values`` the fractions follow a parameter.
"""

# %%
import matplotlib.pyplot as plt

import stickslip
from stickslip.basins import box, grid
from stickslip.plot.basins import plot_basins, plot_parameter_study

belt = stickslip.load_model("belt")
image = stickslip.basin_stability(belt, grid(belt, {"x": (-2, 2), "dx": (0, 2)}, 24), t_end=200.0,
                                  executor="serial")
print(image.fractions, image.standard_errors)

# %%
# The fractions against the belt speed (random states in the same box).
study = stickslip.basin_stability(belt, box(belt, {"x": (-2, 2), "dx": (0, 2)}, n=100, seed=0), t_end=200.0,
                                  param="contact.0.drive", values=[1.2, 1.5, 1.8], executor="serial")
print(study.fractions)

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5), layout="constrained")
plot_basins(image, ax1)
plot_parameter_study(study, ax2)
