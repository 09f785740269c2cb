"""
Popp–Stelter: two masses, two contacts
======================================

The Popp–Stelter oscillator: two masses coupled by a spring, each on the same moving belt with a
velocity-weakening friction law. Each contact sticks and slips on its own; on the stick-slip orbit
the two masses stick at different times.
"""

# %%
import matplotlib.pyplot as plt

import stickslip
from stickslip.plot.models import plot_popp_stelter

traj = stickslip.simulate("popp-stelter", 80.0, ic={"x1": 0.1}, sample_rate=200.0)
steady = traj.steady
print("stick fraction of each contact:", [round(f, 3) for f in steady.contact_stick_fractions])
print("dominant frequency:", round(steady.dominant_frequency_hz, 4))

# %%
# Each mass's displacement with the stick phases of its contact, and the phase portraits.
fig = plt.figure(figsize=(11, 4.5), layout="constrained")
plot_popp_stelter(traj, fig=fig)
