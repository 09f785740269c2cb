"""What the model-library figures show (docs/models/*.md), computed; and the worked example of a
model with nonlinear contact kinematics (docs/models.md).

=======================  ======================================================================
``hoffmann_sweep``       eigenvalues of steady sliding of ``hoffmann`` over μ, the flutter onset
``belt_attractors``      ``belt`` from bSTAB's two template initial conditions (FP and LC)
``popp_stelter_orbit``   the stick-slip orbit of ``popp-stelter`` after its transient
``belt_arm``             worked example: an arm pressed on a belt, G(θ) = H / cos²θ
=======================  ======================================================================

``python -m stickslip.studies.models DIR`` computes all three and writes ``belt.png``,
``hoffmann.png`` and ``popp-stelter.png`` into DIR (the figures are drawn by
:mod:`stickslip.plot.models`).
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path
from typing import Any, Mapping, NamedTuple

import numpy as np

from ..errors import StickSlipError
from ..integrate.driver import simulate
from ..model import csmath as csm
from ..model.bundle import C_N0, contact_offsets
from ..model.friction import FrictionLaw
from ..model.kinematics import register_kinematics
from ..model.library import load_model
from ..model.system_model import Contact, FrictionModel
from ..plot.models import save_belt_figure, save_hoffmann_figure, save_popp_stelter_figure
from ..stability.analysis import stability

__all__ = ["BeltArm", "belt_arm_frame", "belt_arm", "HoffmannSweep", "hoffmann_sweep", "flutter_onset", "OnsetError",
           "BeltAttractors", "belt_attractors", "BSTAB_TEMPLATES", "popp_stelter_orbit", "main"]


# ----------------------------------------------------------------------------- worked example
class BeltArm(NamedTuple):
    """Kinematics data of the arm on a belt: hinge height H above the belt [m], belt speed V [m/s]."""

    H: float
    V: float


def belt_arm_frame(kin, s, c, m, G, w):
    """Contact frame of the arm's tip: x_tip = H tan θ, so v = (H / cos²θ) θ̇ − V; N = N0."""
    cos = csm.cos(s[0])
    G[0, 0] = kin.H / (cos * cos)
    G[1, 0] = 0.0
    w[0] = kin.V
    w[1] = 0.0
    return m[contact_offsets(1, c)[0] + C_N0] + csm.zero(s[0])


register_kinematics(BeltArm, belt_arm_frame, ndof=1, ncontacts=1, dim=1)


def belt_arm(J=1.0, c=0.02, k=1.0, H=1.0, V=0.1, N=1.0, mu_k=0.2, delta_mu=0.1) -> FrictionModel:
    """An arm hinged at height H above a belt moving at V, its tip pressed on the belt with N.

    J θ'' + c θ' + k θ = (H / cos²θ) F, F the friction force at the tip (Coulomb, μs = μk + Δμ).
    Every argument is a parameter that ``replace`` (and ``--set``) changes.
    """
    values = dict(J=J, c=c, k=k, H=H, V=V, N=N, mu_k=mu_k, delta_mu=delta_mu)

    def builder(p: Mapping[str, Any]) -> FrictionModel:
        return belt_arm(**p)

    return FrictionModel(
        name="belt-arm", dofs=("theta",), mass=[[J]], damping=[[c]], stiffness=[[k]], force=[0.0],
        contacts=(Contact(dim=1, friction=FrictionLaw("coulomb", mu_k, delta_mu), normal_force=N, name="tip"),),
        kinematics=BeltArm(H, V), parameters=values, builder=builder, units={"theta": "rad"},
        description="arm pressed on a moving belt (worked example of nonlinear kinematics)")


# ----------------------------------------------------------------------------- hoffmann
@dataclasses.dataclass(frozen=True)
class HoffmannSweep:
    """Eigenvalues of steady sliding of ``hoffmann`` over the friction coefficient.

    Attributes
    ----------
    mu : ndarray (m,)
        Friction coefficients.
    eigenvalues : ndarray (m, 4) complex
        From :func:`stickslip.stability.analysis.stability` (the simulator's Jacobian) [1/time].
    polynomial_eigenvalues : ndarray (m, 4) complex
        Roots of det(λ² M + λ C + K(μ)), the characteristic polynomial of the model's matrices.
    onset : float
        μ where the largest real part first exceeds 0 (damped) or 1e-6 (undamped, above the
        round-off of the imaginary eigenvalues): :func:`flutter_onset`.
    damping : tuple of float
        (c_x, c_y) of the sweep.
    """

    mu: np.ndarray
    eigenvalues: np.ndarray
    polynomial_eigenvalues: np.ndarray
    onset: float
    damping: tuple[float, float]


class OnsetError(StickSlipError, ValueError):
    """No flutter onset inside the μ range searched."""


def _hoffmann(mu: float, damping) -> FrictionModel:
    return load_model("hoffmann").replace(**{"contact.0.friction.mu_k": float(mu), "damping.x.x": damping[0],
                                             "damping.y.y": damping[1]})


def _characteristic_roots(model: FrictionModel) -> np.ndarray:
    """Roots of det(λ² M + λ C_eff + K_eff) of a 2-DOF model with one Coulomb contact of constant G
    and drive w > 0, sliding steadily (v = −w, so friction is +μ N along G). A prescribed load
    N = N0 + n·q gives K_eff = K − μ G nᵀ; a closed compliant contact, λ = −k (g0 + W·q) − c W·q̇
    acting as Wᵀλ, gives K_eff = K + k (W + μ G) Wᵀ and C_eff = C + c (W + μ G) Wᵀ (W Wᵀ the
    contact spring, μ G Wᵀ the friction it carries)."""
    contact = model.contacts[0]
    G, mu = contact.tangent[0], contact.friction.mu_k
    K, C = model.stiffness.copy(), model.damping.copy()
    if contact.unilateral:
        W, k, c = contact.gap_gradient, contact.normal.stiffness, contact.normal.damping
        K += k * np.outer(W, W) + mu * k * np.outer(G, W)
        C += c * np.outer(W, W) + mu * c * np.outer(G, W)
    else:
        K -= mu * np.outer(G, contact.normal_gradient)
    M = model.mass
    # det of the 2×2 matrix polynomial, coefficient by coefficient (λ⁴ … λ⁰)
    a = [np.array([M[i, j], C[i, j], K[i, j]]) for i in range(2) for j in range(2)]
    return np.roots(np.polysub(np.polymul(a[0], a[3]), np.polymul(a[1], a[2])))


def flutter_onset(damping=(0.0, 0.0), lo=0.0, hi=3.0, threshold=1e-6, tol=1e-10) -> float:
    """Smallest μ in [lo, hi] at which steady sliding of ``hoffmann`` has max Re λ > ``threshold``,
    by bisection on :func:`~stickslip.stability.analysis.stability` (undamped, Re λ grows like
    (μ − μc)^½ past the onset, so a threshold above round-off places it to ~threshold²)."""
    def unstable(mu):
        return stability(_hoffmann(mu, damping)).max_real_part > threshold

    if unstable(lo) or not unstable(hi):
        raise OnsetError(f"no flutter onset of hoffmann in mu = [{lo}, {hi}] with damping {damping}; "
                         "widen the range (lo stable, hi unstable)")
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if unstable(mid) else (mid, hi)
    return 0.5 * (lo + hi)


def hoffmann_sweep(mu=None, damping=(0.0, 0.0)) -> HoffmannSweep:
    """Eigenvalues of ``hoffmann`` over ``mu`` (default 0 … 2 in steps of 0.01) and its onset."""
    mu = np.linspace(0.0, 2.0, 201) if mu is None else np.asarray(mu, dtype=float)
    damping = (float(damping[0]), float(damping[1]))
    lam = np.empty((mu.size, 4), dtype=complex)
    poly = np.empty((mu.size, 4), dtype=complex)
    for i, value in enumerate(mu):
        model = _hoffmann(value, damping)
        lam[i] = stability(model).eigenvalues
        poly[i] = _characteristic_roots(model)
    threshold = 1e-6 if damping == (0.0, 0.0) else 0.0
    return HoffmannSweep(mu, lam, poly, flutter_onset(damping, threshold=threshold), damping)


# ----------------------------------------------------------------------------- belt
#: bSTAB's friction case: its template initial conditions (x, x') and their labels.
BSTAB_TEMPLATES = {"FP": (0.1, 0.1), "LC": (2.0, 2.0)}


@dataclasses.dataclass(frozen=True)
class BeltAttractors:
    """``belt`` from each of bSTAB's template initial conditions.

    Attributes
    ----------
    runs : dict of str → Trajectory
        By bSTAB's label (``FP``, ``LC``).
    breakaway : float
        x where the stick force k x + c V reaches μs N (the end of every stick phase).
    steady_sliding : float
        x of steady sliding, μ(V) N / k.
    feature : dict of str → float
        bSTAB's classification feature: max |x'| over t ≥ ``t_star`` (FP if ≤ 0.2).
    t_star : float
    """

    runs: dict
    breakaway: float
    steady_sliding: float
    feature: dict
    t_star: float


def belt_attractors(t_end=500.0, t_star=400.0, sample_rate=20.0) -> BeltAttractors:
    """Simulate ``belt`` from bSTAB's templates over bSTAB's time span (0 … 500, feature after 400)."""
    model = load_model("belt")
    runs = {label: simulate(model, t_end, ic={"x": x0, "dx": v0}, rtol=1e-10, atol=1e-12, sample_rate=sample_rate)
            for label, (x0, v0) in BSTAB_TEMPLATES.items()}
    contact = model.contacts[0]
    k, c, V, N = model.stiffness[0, 0], model.damping[0, 0], contact.drive[0], contact.normal_force
    feature = {label: float(np.max(np.abs(run.states[run.t >= t_star, 1]))) for label, run in runs.items()}
    return BeltAttractors(runs, (contact.friction.mu_s * N - c * V) / k,
                          float(contact.friction.coefficient(V)) * N / k, feature, t_star)


# ----------------------------------------------------------------------------- popp-stelter
def popp_stelter_orbit(t_end=200.0, sample_rate=200.0):
    """``popp-stelter`` from x1 = 0.1 at rest; the last part of the run is on its stick-slip orbit."""
    return simulate("popp-stelter", t_end, ic={"x1": 0.1}, rtol=1e-10, atol=1e-12, sample_rate=sample_rate)


# ----------------------------------------------------------------------------- script
def main(argv=None) -> int:
    """Compute the library figures and write them into the folder given as the argument."""
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print("usage: python -m stickslip.studies.models OUTPUT_FOLDER", file=sys.stderr)
        return 2
    out = Path(argv[0])
    out.mkdir(parents=True, exist_ok=True)
    sweeps = [hoffmann_sweep(), hoffmann_sweep(damping=(0.1, 0.1))]
    for sweep in sweeps:
        print(f"hoffmann, damping {sweep.damping}: flutter onset mu = {sweep.onset:.10f}")
    print("wrote", save_hoffmann_figure(sweeps, out / "hoffmann.png"))
    belt = belt_attractors()
    print("belt, bSTAB feature max|x'| after t = 400:", {k: round(v, 4) for k, v in belt.feature.items()})
    print("wrote", save_belt_figure(belt, out / "belt.png"))
    orbit = popp_stelter_orbit()
    print("wrote", save_popp_stelter_figure(orbit, out / "popp-stelter.png"))
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
