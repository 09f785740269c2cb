"""The uniform samples of the fixed-step methods (AEOM, NAEOM): each step writes the samples that
fall in it, from its cubic Hermite interpolant (``events.hermite_coefficients``), and a sample at
the step end (every sample when the sample period is a multiple of Δt) as the step end itself.

A sample holds the state (the plates' 12 states and the work of friction and of damping), the
mode flag (1 = stick, 0 = slip) and the friction force [N].
"""

from __future__ import annotations

import numpy as np

from ..model import physics as P
from ..model.jit import kernel
from . import events as E

__all__ = ["write_samples", "end_sample_only", "write_initial_samples", "store_sample", "END_SAMPLE_TOL"]

#: Samples within this fraction of a step from its end (either side) are written as the step end
#: itself (the interpolant there equals y1 up to round-off; sample times and step ends agree to
#: ~1e-16 t, i.e. ~1e-11 of a step of 1e-3 s at t = 100 s).
END_SAMPLE_TOL = 1e-9


@kernel
def store_sample(idx, y, mode, Fx, Fy, samples):
    """Write the state, the mode flag (1 = stick, 0 = slip) and the friction force of sample ``idx``
    into the :class:`~.bundles.Samples` ``samples``."""
    states = samples.states
    for i in range(y.shape[0]):
        states[idx, i] = y[i]
    samples.modes[idx] = 1 if mode == P.MODE_STICK else 0
    forces = samples.forces
    forces[idx, 0] = Fx
    forces[idx, 1] = Fy


@kernel
def write_samples(idx, t, h, step, dense, force1, mode, fixed_force, cst, md, samples, scratch):
    """Write the samples with t < ts ≤ t + h (to END_SAMPLE_TOL) from the Hermite interpolant of
    the step ``step`` (a :class:`~.fixed_step.FixedStep`: from y0 = ``step.y``, f0 = ``step.K[0]``
    to y1 = ``step.ynew``, f1 = ``step.fnew``; its coefficients into ``dense``).

    ``force1`` = (F1x, F1y) is the friction force at the step end y1 [N]. A sample at the step end
    (θ = 1 to :data:`END_SAMPLE_TOL` on either side; every sample when the sample period is a
    multiple of Δt) is y1 with that force, and needs neither the interpolant nor a force
    evaluation. The tolerance also covers the far side: sample times and grid points are
    rounded separately, and a sample one ulp after the step end would otherwise be interpolated
    at θ ≈ 0 of the next step, at the full cost of an interpolated sample.
    Inside the step the force written is (F1x, F1y) if ``fixed_force`` (NAEOM's per-step force
    in stick), else the contact force in the modes of ``cst`` at the sample
    (``physics.contact_forces``). Returns the next sample index.
    """
    F1x, F1y = force1
    times = samples.times
    n_samples = times.shape[0]
    y0 = step.y
    y1 = step.ynew
    Q = dense
    work = scratch.state
    t_to = t + h
    t_last = t_to + END_SAMPLE_TOL * h
    q_ready = False
    while idx < n_samples and times[idx] <= t_last:
        theta = (times[idx] - t) / h
        if theta >= 1.0 - END_SAMPLE_TOL:
            store_sample(idx, y1, mode, F1x, F1y, samples)
        else:
            if not q_ready:
                E.hermite_coefficients(y0, step.K[0], y1, step.fnew, h, Q)
                q_ready = True
            E.dense_state(y0, Q, h, theta, work)
            _store(idx, work, mode, F1x, F1y, fixed_force, cst, md, scratch, samples)
        idx += 1
    return idx


@kernel
def end_sample_only(idx, t, h, y1, mode, Fx, Fy, samples):
    """The samples of a step that has none or only one, at its end (the usual cases when the
    sample period is a multiple of Δt), without the call to :func:`write_samples`.

    Writes that one sample (y1 with the force (Fx, Fy) at y1 [N]) and returns (next index, True);
    returns (idx, False) and writes nothing when the step needs :func:`write_samples`.
    """
    times = samples.times
    n_samples = times.shape[0]
    t_last = t + h + END_SAMPLE_TOL * h
    if idx >= n_samples or times[idx] > t_last:
        return idx, True  # no sample in this step
    if (times[idx] - t) / h < 1.0 - END_SAMPLE_TOL:
        return idx, False  # a sample inside the step: interpolate
    if idx + 1 < n_samples and times[idx + 1] <= t_last:
        return idx, False
    store_sample(idx, y1, mode, Fx, Fy, samples)
    return idx + 1, True


@kernel
def _store(idx, y, mode, Fx, Fy, fixed_force, cst, md, scratch, samples):
    """Write sample ``idx``: the given force if ``fixed_force``, else the contact force in the modes
    of ``cst``."""
    if not fixed_force:
        F = scratch.F
        P.contact_forces(y, cst, md, F, scratch.N, scratch.v)
        Fx = F[0]
        Fy = F[1]
    store_sample(idx, y, mode, Fx, Fy, samples)


@kernel
def write_initial_samples(y, t0, mode, cst, md, samples, scratch):
    """Samples at t ≤ t0 (the initial state, its force from the state). Returns the next sample index."""
    idx = np.int64(0)  # not a literal: one compiled version of _store
    from_state = np.bool_(False)
    times = samples.times
    while idx < times.shape[0] and times[idx] <= t0:
        _store(idx, y, mode, 0.0, 0.0, from_state, cst, md, scratch, samples)
        idx += 1
    return idx
