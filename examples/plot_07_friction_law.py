"""
A friction law of your own
==========================

A friction law is a ``NamedTuple`` of its parameters and a numba-compilable function
``mu(law, speed)`` of the slip speed, registered once with ``register_friction_law``; a contact
takes it as ``FrictionLaw.from_user(instance)``. The library's Stribeck law
(``stickslip.model.library.laws``) is written this way; here it drives a mass on a belt.
"""

# %%
import inspect

import matplotlib.pyplot as plt
import numpy as np

import stickslip
from stickslip import Contact, FrictionLaw, FrictionModel
from stickslip.model.library import laws

print(inspect.getsource(laws.Stribeck))
print(inspect.getsource(getattr(laws.stribeck, "py_func", laws.stribeck)))

# %%
# A mass on a belt moving at 0.3 with this law; stick holds while the friction force stays within μs N
# (here μs = μ(0)).
law = laws.Stribeck(mu_c=0.5, mu_s=1.0, v_s=0.5, mu_v=0.05)
belt = FrictionModel(name="stribeck-belt", dofs=("x",), mass=[[1.0]], damping=[[0.1]], stiffness=[[1.0]],
                     force=[0.0], contacts=(Contact(dim=1, friction=FrictionLaw.from_user(law), normal_force=1.0,
                                                    tangent=[[1.0]], drive=[0.3]),))
traj = stickslip.simulate(belt, 60.0)
steady = traj.steady
print(f"stick fraction {steady.stick_fraction:.3f}, x between {steady.minimum:.3f} and {steady.maximum:.3f}")

# %%
speed = np.linspace(0.0, 3.0, 200)
ratio = speed / law.v_s
mu = law.mu_c + (law.mu_s - law.mu_c) * np.exp(-ratio**2) + law.mu_v * speed

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
ax1.plot(speed, mu)
ax1.set_xlabel("slip speed |v|")
ax1.set_ylabel("μ")
ax1.set_title("Stribeck law")
ax2.plot(traj.states[:, 0], traj.states[:, 1], lw=0.8)
ax2.axhline(0.3, color="tab:orange", ls="--", label="belt speed (stick)")
ax2.set_xlabel("x")
ax2.set_ylabel("x'")
ax2.legend()
