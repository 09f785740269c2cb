"""
Stick, slip, separation and reattachment on a belt
==================================================

The ``slider-belt`` library model is a slider pressed onto a moving belt by a preload, with a
tangential dof x and a normal dof y coupled by an inclined spring. Its contact is unilateral and
compliant: the normal force is λ = max(0, P − kc y), and the contact opens where λ reaches 0 and
closes where y comes back down. Friction falls with the sliding speed, so the slip from rest grows
until the slider lifts off the belt; the motion then settles on a cycle with one stick, one slip,
one flight and one reattachment in each period (the numbers are non-dimensional).
"""

# %%
import matplotlib.pyplot as plt

import stickslip

model = stickslip.load_model("slider-belt")
traj = stickslip.simulate(model, 60.0)
first = traj.t[traj.open[:, 0]][0]
print(traj.status, "-", f"first separation at t ≈ {first:.2f}")

# %%
# The summary of the last half of the run: the fraction of it with the contact open, and with
# it sticking. By t = 60 the cycle has not quite settled by the signal's rule (``periodic`` is
# False), but its dominant period is already the cycle's, 3.35, and its open fraction 0.47
# (a longer run settles at 200 on the period 3.3485 with open fraction 0.4729).
steady = traj.steady
print(f"over t = {steady.t_from:g} … {steady.t_to:g}: open fraction {steady.open_fraction:.4f}, "
      f"stick fraction {steady.stick_fraction:.4f}, dominant period {1.0 / steady.dominant_frequency_hz:.4f}, "
      f"periodic {steady.periodic}")

# %%
# x and y, the belt contact's normal force and its gap: the open phases shaded, the stick phases
# marked on x. While the contact is open the normal force is 0 and the gap positive; it closes
# where the gap comes back to 0.
is_open, sticks = traj.open[:, 0], traj.stick[:, 0]
fig, (ax1, ax2, ax3) = plt.subplots(3, 1, figsize=(10, 7.5), sharex=True, layout="constrained")
ax1.plot(traj.t, traj.states[:, 0], lw=0.8, label="x")
ax1.plot(traj.t[sticks], traj.states[sticks, 0], ".", ms=1.5, color="tab:red", label="stick")
ax1.set_ylabel("x")
ax2.plot(traj.t, traj.states[:, 1], lw=0.8, color="tab:orange", label="y")
ax2.plot(traj.t, traj.gap[:, 0], lw=0.8, color="0.4", ls="--", label="gap g")
ax2.set_ylabel("y, g")
ax3.plot(traj.t, traj.normal_force[:, 0], lw=0.8, color="tab:purple", label="normal force λ")
ax3.set_ylabel("λ")
ax3.set_xlabel("t")
for ax in (ax1, ax2, ax3):
    ax.fill_between(traj.t, 0, 1, where=is_open, color="tab:green", alpha=0.2, lw=0,
                    transform=ax.get_xaxis_transform(), label="contact open")
    ax.legend(loc="upper left", fontsize="small", ncols=4)
