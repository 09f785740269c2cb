"""Helpers for the stability tests: growth rates measured in simulations."""

import numpy as np

import stickslip
from stickslip.model import resolve_variant, two_plates
from stickslip.stability import stability


def measured_growth_rate(params, t_end, amplitude, *, model="full", sample_rate=50.0, t_from=0.5):
    """Growth rate [1/s] of the leading mode measured in a simulation started on it.

    The run starts at the equilibrium plus ``amplitude`` × Re(v) (v the leading eigenvector,
    scaled to unit max entry). The modal coordinate c(t) = (V⁻¹)_j (s(t) − s_e) of a linear
    system is exactly (amplitude/2)·e^{λ t}, so the slope of log|c| is Re λ without any
    envelope fitting; other modes do not leak in while the motion stays linear.

    Returns (measured rate, predicted max real part, trajectory).
    """
    res = stability(two_plates(params, model))
    free = resolve_variant(model).free_indices
    idx = np.concatenate([free, 6 + free])
    lam, V = np.linalg.eig(res.jacobian)
    j = int(np.argmax(lam.real + 1e-12 * np.sign(lam.imag)))  # the member with Im >= 0
    v = V[:, j] / V[np.argmax(np.abs(V[:, j])), j]
    pert = np.zeros(12)
    pert[idx] = amplitude * v.real
    traj = stickslip.simulate(two_plates(params, model), t_end, ic="equilibrium", perturbation=pert,
                              rtol=1e-11, atol=1e-15, sample_rate=sample_rate)
    assert traj.status == "success"
    assert not np.any(traj.mode), "the run must stay in slip for a linear growth measurement"
    s_e = np.concatenate([res.equilibrium, np.zeros(6)])
    d = traj.states[:, idx] - s_e[idx]
    c = d @ np.linalg.inv(V)[j]
    keep = traj.t >= t_from
    slope = np.polyfit(traj.t[keep], np.log(np.abs(c[keep])), 1)[0]
    return slope, res.max_real_part, traj
