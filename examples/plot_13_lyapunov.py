"""
A Lyapunov spectrum across stick-slip events
============================================

:func:`stickslip.lyapunov_spectrum` integrates the variational equations along a run (with
saltation matrices at the transitions) and re-orthonormalises them (QR): all exponents of the
attractor. On the Popp–Stelter stick-slip orbit one exponent is 0 (along the orbit), the others
negative; the stick phases, which collapse a mass's velocity, make some very negative.
"""

# %%
import matplotlib.pyplot as plt

import stickslip
from stickslip.plot.orbits import plot_lyapunov_spectrum

spectrum = stickslip.lyapunov_spectrum("popp-stelter", {"x1": 0.5, "x2": -0.5}, t_transient=100.0, t_average=100.0)
print("exponents [1/s]:", spectrum.exponents)

# %%
# The running estimate of each exponent against the averaging time.
fig, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
plot_lyapunov_spectrum(spectrum, ax=ax)
