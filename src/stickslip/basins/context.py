"""What the early-stopping classifier needs to know about one model (one parameter value).

Computed once per parameter value in the process that runs the study, and sent with every
batch of states (plain arrays; a model travels as its description and is rebuilt where it
runs, :func:`model_of`):

* the **sampling**: a characteristic period T_c of the model (the slowest oscillation of its
  linearisation about steady sliding, else of its undamped natural frequencies), sampled
  :data:`SAMPLES_PER_PERIOD` times, integrated in chunks of :data:`CHUNK_PERIODS` T_c, with a
  window of the last :data:`WINDOW_PERIODS` T_c kept for the section crossings and the verdict;
* **steady sliding** s_e = (q_e, 0) and whether it is linearly stable
  (:func:`stickslip.stability.analysis.model_stability`: the dense path, for models above 64 dofs too);
* for a stable one, the linear flow over one chunk, Φ = exp(A Δ), and a quadratic Lyapunov
  function V(δ) = δᵀ P δ of the linearisation A (Aᵀ P + P A = −Q, Q the diagonal of the
  stiffness and mass, an energy weighting), in which the linear flow contracts monotonically.
  The classifier takes the equilibrium as reached when a chunk of the run agrees with the
  linear flow to a small fraction of the contraction that flow predicts (:mod:`.early`).
"""

from __future__ import annotations

import dataclasses
import json
import math
from functools import lru_cache

import numpy as np

from ..errors import StickSlipError
from ..model.library import describe_system, system_from_description
from ..stability.analysis import model_stability
from ..stability.equilibrium import rigid_constraint

__all__ = ["Context", "make_context", "model_of", "model_key", "SAMPLES_PER_PERIOD", "CHUNK_PERIODS",
           "WINDOW_PERIODS", "register_model"]

#: Samples per characteristic period T_c: the section crossings (maxima of the observed
#: coordinate) are located on the cubic Hermite interpolant of (x, ẋ), whose error at a peak is
#: ~(2π/64)⁴/384 ≈ 2.4e-7 of the amplitude, 40 times below the period rule's 1e-5.
SAMPLES_PER_PERIOD = 64

#: Chunk length in T_c: the classifier tests after each chunk; the linear test compares the
#: chunk's end with the linear flow from its start.
CHUNK_PERIODS = 4

#: Window kept for the section crossings and the final verdict, in T_c: the period rule needs
#: nine periods (ten maxima), so a cycle of up to 3 maxima per T_c is claimed within it.
WINDOW_PERIODS = 32

#: Models defined in Python (not rebuildable from their description) by key, for processes
#: forked from the one that registered them.
_PYTHON_MODELS: dict = {}


@dataclasses.dataclass(frozen=True)
class Context:
    """One model's data for the early-stopping classifier (plain arrays, picklable).

    Attributes
    ----------
    key : str
        The model's description (JSON), from which :func:`model_of` rebuilds it.
    period : float
        Characteristic period T_c [s].
    dt : float
        Sample interval T_c / SAMPLES_PER_PERIOD [s].
    chunk : int
        Samples per chunk.
    window : int
        Samples kept in the window.
    equilibrium : ndarray (2n,) or None
        Steady sliding s_e = (q_e, 0), None when there is none.
    stable : bool
        Whether steady sliding is linearly stable (the linear test runs only then).
    max_real_part : float
        Largest real part of its eigenvalues [1/s] (NaN without steady sliding).
    free : ndarray (2k,) int
        Indices of the free states (free dofs, then their rates), the order of A, P and Φ.
    lyapunov : ndarray (2k, 2k)
        P of the Lyapunov function (zeros when not stable).
    flow : ndarray (2k, 2k)
        Φ = exp(A · chunk · dt) (zeros when not stable).
    rest : float
        √V below which a deviation from s_e counts as at rest (1e-6 of √V(s_e)).
    open_contacts : tuple of int
        The unilateral contacts that steady sliding leaves open (ascending; empty where all are
        closed or there is no steady sliding).
    """

    key: str
    period: float
    dt: float
    chunk: int
    window: int
    equilibrium: np.ndarray | None
    stable: bool
    max_real_part: float
    free: np.ndarray
    lyapunov: np.ndarray
    flow: np.ndarray
    rest: float
    open_contacts: tuple = ()


def model_key(model) -> str:
    """The description of ``model`` as a JSON key (:func:`stickslip.model.library.describe_system`)."""
    return json.dumps(describe_system(model), sort_keys=True)


def register_model(model) -> str:
    """Make ``model`` available by its key in this process and the processes forked from it
    (a model defined in Python cannot be rebuilt from its description)."""
    key = model_key(model)
    _PYTHON_MODELS[key] = model
    return key


@lru_cache(maxsize=64)
def _rebuild(key: str):
    return system_from_description(json.loads(key))


def model_of(key: str):
    """The model of a :func:`model_key` (registered here, or rebuilt from the description).

    Raises
    ------
    StickSlipError
        For a model defined in Python in another process (its code is not in the description).
    """
    if key in _PYTHON_MODELS:
        return _PYTHON_MODELS[key]
    return _rebuild(key)


def _period(model, eigenvalues) -> float:
    """T_c: 2π over the smallest non-zero |Im λ| of steady sliding, else 1 / the smallest
    non-zero undamped natural frequency, else 1."""
    if eigenvalues is not None:  # none at all where closed rigid contacts fix every free dof
        im = np.abs(np.imag(eigenvalues))
        im = im[im > 1e-9 * max(1.0, float(np.max(np.abs(eigenvalues), initial=0.0)))]
        if im.size:
            return 2.0 * math.pi / float(im.min())
    f = model.natural_frequencies()
    f = f[np.isfinite(f) & (f > 0.0)]
    return 1.0 / float(f.min()) if f.size else 1.0


def _energy_weights(model, free_dofs) -> np.ndarray:
    """Diagonal weights (2k,) of the Lyapunov equation: |K_ii| for positions (M_ii ω² where K_ii
    is 0), M_ii for rates."""
    K = np.abs(model.stiffness.diagonal())[free_dofs]  # a dense array or a sparse matrix
    M = model.mass.diagonal()[free_dofs]
    wq = np.where(K > 0.0, K, M * (2.0 * math.pi / _period(model, None)) ** 2)
    return np.concatenate([wq, M])


def make_context(model, *, key: str | None = None) -> Context:
    """The :class:`Context` of ``model`` (steady sliding, its stability, the linear flow)."""
    from scipy.linalg import expm, solve_continuous_lyapunov


    n = model.n
    free_dofs = np.flatnonzero(model.free)
    free = np.concatenate([free_dofs, n + free_dofs]).astype(np.int64)
    k2 = free.size
    try:
        stab = model_stability(model)
    except (StickSlipError, ArithmeticError, np.linalg.LinAlgError):
        stab = None
    period = _period(model, None if stab is None else stab.eigenvalues)
    dt = period / SAMPLES_PER_PERIOD
    chunk = CHUNK_PERIODS * SAMPLES_PER_PERIOD
    P = np.zeros((k2, k2))
    flow = np.zeros((k2, k2))
    equilibrium = None
    stable = False
    max_re = math.nan
    rest = 0.0
    opened = ()
    if stab is not None:
        opened = tuple(model.contact_names.index(name) for name in stab.open_contacts)
        equilibrium = np.concatenate([stab.equilibrium, np.zeros(n)])
        max_re = float(stab.max_real_part)
        # a marginal centre (Re λ = 0 within the solver's accuracy: stickslip.stability.verdict) is
        # not stable for the linear test: its Lyapunov equation is singular, and a decay that
        # slow never settles within a run
        stable = bool(stab.stable)
        if stable:
            A = np.asarray(stab.jacobian, dtype=float)
            Q = np.diag(_energy_weights(model, free_dofs))
            # closed rigid contacts: the linear flow lives on W q = −g0, W q̇ = 0 (orthonormal
            # basis T); off it (a flight) the deviation counts with the weights Q and is not
            # linear motion (the flow's prediction drops it)
            T = np.kron(np.eye(2), rigid_constraint(model, exclude=opened)[1][free_dofs]) if model.rigid else np.eye(k2)
            A_c = T.T @ A @ T
            P = T @ solve_continuous_lyapunov(A_c.T, -(T.T @ Q @ T)) @ T.T
            off = np.eye(k2) - T @ T.T
            P = 0.5 * (P + P.T) + off @ Q @ off
            flow = T @ expm(A_c * chunk * dt) @ T.T
            se = equilibrium[free]
            if np.all(np.isfinite(P)) and np.linalg.eigvalsh(P)[0] > 0.0:
                rest = 1e-6 * math.sqrt(max(float(se @ P @ se), float(np.trace(P)) * 1e-12))
            else:  # the Lyapunov solve failed (ill-conditioned): no linear test
                stable, P, flow = False, np.zeros((k2, k2)), np.zeros((k2, k2))
    return Context(key or model_key(model), period, dt, chunk, WINDOW_PERIODS * SAMPLES_PER_PERIOD, equilibrium,
                   stable, max_re, free, P, flow, rest, opened)
