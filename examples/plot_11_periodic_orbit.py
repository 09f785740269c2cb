"""
A periodic orbit and its Floquet multipliers
============================================

:func:`stickslip.periodic_orbit` finds a periodic stick-slip orbit by Newton shooting on a
Poincaré section (by default a maximum of the observed coordinate). Its Floquet multipliers are
the eigenvalues of the monodromy matrix, built from the variational equations with a saltation
matrix at every stick↔slip transition. Here: the Popp–Stelter oscillator (two masses, two
contacts, four states), on the section of the second mass's maxima.
"""

# %%
import matplotlib.pyplot as plt

import stickslip
from stickslip.plot.orbits import plot_multipliers, plot_orbit

orbit = stickslip.periodic_orbit("popp-stelter", {"x1": 0.5, "x2": -0.5}, search_time=200.0, section="x2_max")
print(f"period {orbit.period:.6f}, {orbit.stick_phases} stick phases, stable: {orbit.stable}")
print("multipliers:", orbit.multipliers)

# %%
# One period of the orbit (a run from its state on the section) and its multipliers in the
# complex plane: one multiplier is 1 (the direction along the orbit); a stick phase collapses
# the stuck mass's velocity, which gives multipliers at 0.
traj = stickslip.simulate("popp-stelter", orbit.period, ic=orbit.state,
                          rtol=1e-10, atol=1e-12)
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5), layout="constrained")
plot_orbit(orbit, traj, ax1)
plot_multipliers(orbit, ax2)
