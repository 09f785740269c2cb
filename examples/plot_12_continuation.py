"""
Continuation of a stick-slip orbit, with its special points
===========================================================

:func:`stickslip.continue_orbit` follows a periodic orbit as one parameter changes
(pseudo-arclength continuation), with its period, Floquet multipliers and stick phases, and
locates the special points where it changes stability or ends: folds, period doublings, Hopf
points, changes in the number of stick phases, grazing. Here the plates' reduced model (Model 4,
rotation only) at N = 50 N: the stick-slip orbit found at Ω = 3 rad/s is followed up in Ω until
its stick phase vanishes.
"""

# %%
import matplotlib.pyplot as plt

import stickslip
from stickslip.model.library import two_plates
from stickslip.orbits.continuation import start_run
from stickslip.plot.continuation import plot_branch

band = 1e-5  # a narrower low-speed band of the 2-D slip direction than the default
model = two_plates(stickslip.Parameters(N=50.0, Omega=3.0), "rotation")  # Model 4
start = stickslip.periodic_orbit(model, start_run(model, "far", t_end=30.0, slip_band=band), slip_band=band)
branch = stickslip.continue_orbit(start=start, param="Omega", step=0.05, max_step=1.0, max_points=200,
                                  bounds=(3.0, 20.0), amplitude=False)
print(f"{len(branch)} orbits, Ω from {branch.values[0]:.3f} to {branch.values[-1]:.4f} rad/s; stop: {branch.stop_reason}")
for point in branch.special:
    print(point.kind, f"at Ω = {point.value:.5f} rad/s")

# %%
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
plot_branch(branch, ax1)
for point in branch.special:
    ax1.axvline(point.value, color="tab:red", ls=":", label=point.kind)
ax1.legend()
ax2.plot(branch.values, branch.stick_time, "k.-")
ax2.set_xlabel("Ω [rad/s]")
ax2.set_ylabel("stick time per period [s]")
