"""
Hoffmann's mode coupling: eigenvalues against μ
===============================================

The ``hoffmann`` model (two degrees of freedom, a mass pressed on a belt by a spring) has no
velocity dependence in its friction law: its steady sliding loses stability because friction
couples two modes. As μ grows the two frequencies approach, merge at μ = 1 (undamped), and a pair
of eigenvalues with positive real part appears (flutter).
"""

# %%
import matplotlib.pyplot as plt
import numpy as np

import stickslip

hoffmann = stickslip.load_model("hoffmann")
mu = np.linspace(0.0, 1.6, 81)
eigenvalues = np.array([stickslip.stability(hoffmann.replace(**{"contact.0.friction.mu_k": m})).eigenvalues
                        for m in mu])
print(eigenvalues.shape, "(μ, eigenvalue)")

# %%
# Past the onset the oscillation grows until the contact lifts off; the run ends on a cycle with
# a flight phase in each period.
damped = hoffmann.replace(**{"contact.0.friction.mu_k": 1.3, "damping.x.x": 0.1, "damping.y.y": 0.1})
traj = stickslip.simulate(damped, 80.0, ic={"x": 0.01})

fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(13, 4), layout="constrained")
m = np.repeat(mu, eigenvalues.shape[1])
ax1.plot(m, np.abs(eigenvalues.imag).ravel(), ".", ms=3)
ax1.set_xlabel("μ")
ax1.set_ylabel("|Im λ|")
ax2.plot(m, eigenvalues.real.ravel(), ".", ms=3)
ax2.axvline(1.0, color="0.5", ls="--")
ax2.set_xlabel("μ")
ax2.set_ylabel("Re λ")
ax3.plot(traj.t, traj.states[:, 1], lw=0.8)
ax3.fill_between(traj.t, 0, 1, where=traj.open[:, 0], color="tab:green", alpha=0.2,
                 transform=ax3.get_xaxis_transform(), label="contact open")
ax3.set_xlabel("t")
ax3.set_ylabel("y")
ax3.legend(loc="upper left")
