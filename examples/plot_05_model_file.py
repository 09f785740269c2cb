"""
Your own model in a TOML file
=============================

A model file states M, C, K, the contacts and their friction laws, with named parameters that
expressions may use. This one is two masses in a row: the first sits on a belt moving at V and
is held by a spring to the frame, the second hangs on the first by a spring. Every tool takes the
file's path wherever it takes a model (``--model two-mass.toml`` on the command line).
"""

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

import stickslip

MODEL = """
name = "two-mass"
description = "a mass on a belt moving at V, a second mass hung on it by a spring"
dofs = ["x1", "x2"]
mass = [[1.0, 0.0], [0.0, "m2"]]
damping = [[0.05, 0.0], [0.0, 0.05]]
stiffness = [["k1 + kc", "-kc"], ["-kc", "kc"]]

[parameters]
V = 0.5        # belt speed
m2 = 0.5       # second mass
k1 = 1.0       # spring to the frame
kc = 2.0       # coupling spring

[[contact]]
tangent = [[1.0, 0.0]]    # slip velocity v = x1' − V
drive = ["V"]
normal_force = 1.0
[contact.friction]
law = "exponential"
mu_k = 0.5
delta_mu = 0.5
alpha = 2.0
"""

with tempfile.TemporaryDirectory() as tmp:
    path = Path(tmp) / "two-mass.toml"
    path.write_text(MODEL)
    model = stickslip.load_model(path)

print(model.state_names, {name: model.parameters[name] for name in ("V", "m2", "k1", "kc")})
print("steady sliding stable:", stickslip.stability(model).stable)

# %%
# A run from rest, and the same model with a faster belt (``replace`` takes parameter paths and
# named parameters, as ``--set`` does).
slow = stickslip.simulate(model, 60.0)
fast = stickslip.simulate(model.replace(V=1.5), 60.0)

fig, axes = plt.subplots(2, 1, figsize=(8, 5), layout="constrained", sharex=True)
for ax, traj, title in zip(axes, (slow, fast), ("V = 0.5", "V = 1.5")):
    for i, name in enumerate(model.dofs):
        ax.plot(traj.t, traj.states[:, i], label=name)
    ax.fill_between(traj.t, 0, 1, where=traj.stick[:, 0], color="tab:orange", alpha=0.2,
                    transform=ax.get_xaxis_transform(), label="stick")
    ax.set_title(title)
    ax.set_ylabel("displacement")
    ax.legend(loc="upper right", ncols=3)
axes[-1].set_xlabel("t")
