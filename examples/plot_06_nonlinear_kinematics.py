"""
A Python model with nonlinear kinematics
========================================

An arm hinged at height H above a belt moving at V, its tip pressed on the belt with a constant
force N. The tip is at x = H tan θ, so the slip velocity is v = (H / cos²θ) θ̇ − V: the contact's
tangent depends on the state. Such a model supplies a *frame function* that fills G(q) and w,
registered for a ``NamedTuple`` class of its kinematics data with
``stickslip.model.kinematics.register_kinematics``. The class and its frame must live in an
importable module (the compiled kernels are cached by its import path); this one is
``stickslip.studies.models``.
"""

# %%
# The frame function and the model, as written in ``stickslip.studies.models``:
import inspect

import matplotlib.pyplot as plt
import numpy as np

import stickslip
from stickslip.studies import models as worked

print(inspect.getsource(worked.belt_arm_frame))
arm = worked.belt_arm()
print(arm.description, "-", arm.parameters)

# %%
# The arm starts stuck to the belt; it sticks until the friction force needed to keep it there
# reaches μs N, then slips back.
traj = stickslip.simulate(arm, 60.0, ic={"theta": 0.0, "dtheta": 0.1})
res = stickslip.stability(arm)
print(f"steady sliding at θ = {res.equilibrium[0]:.4f} rad, stable: {res.stable}")

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
ax1.plot(traj.t, traj.states[:, 0])
ax1.fill_between(traj.t, 0, 1, where=traj.stick[:, 0], color="tab:orange", alpha=0.25,
                 transform=ax1.get_xaxis_transform(), label="stick")
ax1.set_xlabel("t [s]")
ax1.set_ylabel("θ [rad]")
ax1.legend()
ax2.plot(traj.states[:, 0], traj.states[:, 1], lw=0.8)
theta = np.linspace(traj.states[:, 0].min(), traj.states[:, 0].max(), 50)
ax2.plot(theta, arm.kinematics.V * np.cos(theta) ** 2 / arm.kinematics.H, "--", label="tip moves with the belt")
ax2.set_xlabel("θ [rad]")
ax2.set_ylabel("θ' [rad/s]")
ax2.legend()
