"""
The two plates: one run with exact stick-slip
=============================================

The package's default model: two rigid circular plates in point frictional contact (six degrees
of freedom, 2-D velocity-weakening friction), with the paper's Table 1 parameters at a normal
load N = 50 N and a drive speed Ω = 5 rad/s. :func:`stickslip.simulate` integrates it with the
event-driven method: while the contact sticks, the friction force is the Lagrange multiplier that
keeps the slip velocity at zero, and every stick↔slip transition is a located event.
"""

# %%
# Run 20 s from rest and print the steady-state summary of the last half.
import matplotlib.pyplot as plt

import stickslip

params = stickslip.Parameters(N=50.0, Omega=5.0)
traj = stickslip.simulate(params, 20.0)
steady = traj.steady
print(f"{traj.status}: {len(traj.transitions)} transitions")
print(f"steady window {steady.t_from:g}-{steady.t_to:g} s: stick {steady.stick_fraction:.1%} of the time")
print(f"φ from {steady.minimum:.4f} to {steady.maximum:.4f} rad, dominant frequency {steady.dominant_frequency_hz:.3f} Hz")

# %%
# The result's own figure: φ and ψ with the stick phases shaded, the friction force against μs N, the φ–φ̇
# phase plot and the spectrum of φ.
fig = plt.figure(figsize=(10, 6.5), layout="constrained")
traj.plot(fig=fig)
