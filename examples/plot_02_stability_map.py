"""
Stability of steady sliding over (N, Ω)
=======================================

A Fig. 3-style map of the two plates: the largest real part of the eigenvalues of steady sliding
over the normal load N and the drive speed Ω, for three values of Δμ, with the boundary
Ω_c(N) located by root finding along Ω. The grid here is coarse (the paper's figure uses a
100 × 100 grid; ``stickslip stability-map`` makes it).
"""

# %%
import matplotlib.pyplot as plt
import numpy as np

import stickslip
from stickslip.plot.stability import plot_stability_map

smap = stickslip.stability_map(stickslip.Parameters(), N=np.linspace(5, 200, 14), Omega=np.linspace(0.25, 20, 14),
                               family=("delta_mu", [0.1, 0.2, 0.3]))
print(smap.max_real_part.shape, "(family, N, Ω)")

# %%
# One point of the map in detail: :func:`stickslip.stability` returns the eigenvalues, the
# frequencies and the linearised matrices.
res = stickslip.stability(stickslip.Parameters(N=50.0, Omega=5.0))
print(f"max Re λ = {res.max_real_part:.4f} 1/s, stable: {res.stable}")

# %%
fig, axes = plt.subplots(1, 3, figsize=(12, 4), layout="constrained", sharey=True)
for i, ax in enumerate(axes):
    plot_stability_map(smap, ax, member=i)
