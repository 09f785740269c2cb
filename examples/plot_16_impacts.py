"""
Impacts on a rigid stop: bounces that come to rest
==================================================

The ``impact-oscillator`` library model is a mass on two springs above a rigid stop that moves
under it like a belt. The contact is rigid: closed, its normal force is a multiplier; where the
mass lands it receives an impulse with Newton's restitution (ġ⁺ = −e ġ⁻, e = 0.8) and a Coulomb
impulse along the stop. Dropped from rest at y0 = 0.5, the mass bounces ever lower: the flights
shorten geometrically and accumulate at a finite rest time, after which the mass stays on the
stop (the bounces that would follow within 1e-9 s close the contact at once).

The normal motion has a closed form (ω = 2π, d = 0.1 the depth of the normal spring's rest
position in the stop): the first landing at t1 = acos(d/(y0 + d))/ω with speed
u1 = ω √((y0 + d)² − d²); the k-th bounce leaves with e^k u1 and lands again after
(2/ω) atan(e^k u1/(ω d)), so the rest time is t1 + Σ (2/ω) atan(e^k u1/(ω d)).
"""

# %%
import matplotlib.pyplot as plt
import numpy as np

import stickslip

E, OMEGA, D, Y0 = 0.8, 2.0 * np.pi, 0.1, 0.5

model = stickslip.load_model("impact-oscillator")
traj = stickslip.simulate(model, 6.0, ic=np.array([0.0, Y0, 0.0, 0.0]), rtol=1e-10, atol=1e-12)
impacts = traj.impacts
print(traj.status, "-", len(impacts), "impacts, the fastest at", f"{-impacts.speed_before.min():.4f} m/s")

# %%
# Each impact's record: its instant, the normal speed just before and after, and the normal
# impulse P_N = m (1 + e) u. The last impact leaves with speed 0: the accumulation point, where
# the mass comes to rest on the stop.
for i in (0, 1, 2, len(impacts) - 1):
    print(f"impact {i:3d}: t = {impacts.time[i]:.9f} s, ġ- = {impacts.speed_before[i]: .3e} m/s, "
          f"ġ+ = {impacts.speed_after[i]: .3e} m/s, P_N = {impacts.impulse[i]:.3e} N s")

u1 = OMEGA * np.sqrt((Y0 + D) ** 2 - D ** 2)
t1 = np.arccos(D / (Y0 + D)) / OMEGA
k = np.arange(1, 400)
t_rest = t1 + np.sum(2.0 / OMEGA * np.arctan(E ** k * u1 / (OMEGA * D)))
print(f"rest time: run {impacts.time[-1]:.9f} s, closed form {t_rest:.9f} s "
      f"(difference {abs(impacts.time[-1] - t_rest):.1e} s)")

# %%
# Left: y(t) with the impacts marked. Right: the landing speeds against the impact number, on a
# log scale, with the closed form e^k u1 (and the impulses, (1 + e) times the landing speed): a
# straight line of slope ln e down to landings at ~5e-10 m/s; the bounces after those would all
# land within 1e-9 s, and the contact closes at once (the Zeno rule).
number = np.arange(len(impacts))
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.2), layout="constrained")
ax1.plot(traj.t, traj.states[:, 1], lw=0.8, label="y")
ax1.plot(impacts.time, np.zeros(len(impacts)), "|", color="tab:red", ms=10, label="impacts")
ax1.axvline(impacts.time[-1], color="0.5", ls="--", lw=0.8, label="at rest")
ax1.set_xlabel("t [s]")
ax1.set_ylabel("y [m]")
ax1.legend(loc="upper right")
ax2.semilogy(number, -impacts.speed_before, ".", ms=4, label="landing speed −ġ⁻ (run)")
ax2.semilogy(number, E ** number * u1, color="0.3", lw=0.8, label="closed form e^k u1")
ax2.semilogy(number[:-1], impacts.impulse[:-1], ".", ms=2, color="tab:green", label="impulse P_N [N s]")
ax2.set_xlabel("impact number k")
ax2.set_ylabel("speed [m/s], impulse [N s]")
ax2.legend(loc="upper right")
