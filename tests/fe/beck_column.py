"""Beck's column: a cantilever under a tangential (follower) end load, a published flutter onset.

A uniform Euler–Bernoulli cantilever of length L, bending stiffness EI and mass per length m,
clamped at x = 0 and loaded at its free end by a compressive force P that stays tangent to the
deformed axis. The load is not conservative, the column never buckles statically, and it loses
stability by flutter: its first two bending frequencies merge and split into a growing and a
decaying pair. Beck found the onset at

    P_k = 20.05 EI/L²

(M. Beck, "Die Knicklast des einseitig eingespannten, tangential gedrückten Stabes", Zeitschrift
für angewandte Mathematik und Physik 3, 1952; undamped, as here), the classic mode-coupling
number of non-conservative elastic stability (Bolotin, *Nonconservative Problems of the Theory of
Elastic Stability*, 1963; Langthjem & Sugiyama, "Dynamic stability of columns subjected to
follower loads: a survey", J. Sound Vib. 238, 809–851, 2000).

:func:`beck_column` discretises it by N two-node beam elements (dofs w, θ per node, the clamped
node removed: 2N dofs ``u0 … u{2N-1}``, node i's w = u[2i − 2], θ = u[2i − 1]) with the
textbook element matrices (Hermite cubics: Przemieniecki, *Theory of Matrix Structural
Analysis*, 1968): stiffness K_e, consistent mass M_e and geometric stiffness K_g,e of a unit axial
compression, so that the structure's stiffness is

    K(P) = K_e − P K_g + P e_w e_θᵀ,

the last term the follower load's transverse component −P θ(L) on the tip's w (not symmetric).
Built here with numpy and scipy.sparse alone, as a :class:`~stickslip.model.sparse_form.SparseForm`
without contacts, no damping.

:func:`continuum_onset` solves the column's differential equation EI w'''' + P w'' + m ẅ = 0 with
w(0) = w'(0) = 0, w''(L) = w'''(L) = 0 (the follower load adds no shear at the tip) for the load
where the two lowest frequencies coalesce: the exact onset of the continuum, independent of any
discretisation and of stickslip. :func:`flutter_onset` finds the onset of the finite-element
model with stickslip's complex eigenvalue analysis.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.sparse as sp

from stickslip.model.sparse_form import NodeMap, SparseForm

__all__ = ["BECK_LOAD", "BECK_DIGITS", "BAND", "beck_column", "continuum_onset", "flutter_onset", "pair"]

#: Beck's flutter load P_k L²/EI (M. Beck, ZAMP 3, 1952: "P_k = 20,05 α/l²", α the flexural rigidity).
BECK_LOAD = 20.05
#: Half a unit in the last digit Beck gives: the published number's own precision.
BECK_DIGITS = 0.005
#: Band of the CEA [rad/s] for EI = m = L = 1: the first two modes (3.52 and 22.0 rad/s unloaded,
#: 11.0 at the onset) lie in it, the third (61.7 unloaded) does not.
BAND = 30.0


def _element_matrices(h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """K_e (per EI), M_e (per m) and K_g,e (per unit compression) of a beam element of length h,
    dofs (w₁, θ₁, w₂, θ₂)."""
    stiffness = np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                          [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]]) / h**3
    mass = h / 420.0 * np.array([[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                                 [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]])
    geometric = np.array([[36, 3 * h, -36, 3 * h], [3 * h, 4 * h * h, -3 * h, -h * h],
                          [-36, -3 * h, 36, -3 * h], [3 * h, -h * h, -3 * h, 4 * h * h]]) / (30.0 * h)
    return stiffness, mass, geometric


def _assemble(block: np.ndarray, elements: int) -> sp.csr_matrix:
    """The (2N, 2N) sparse sum of one 4 × 4 element block over N elements, the clamped node's rows
    and columns left out."""
    first = 2 * np.arange(elements)[:, None] + np.arange(4)[None, :] - 2  # global index, −2 … : clamped
    rows = np.repeat(first, 4, axis=1).ravel()
    cols = np.tile(first, (1, 4)).ravel()
    values = np.tile(block.ravel(), elements)
    keep = (rows >= 0) & (cols >= 0)
    n = 2 * elements
    return sp.csr_matrix((values[keep], (rows[keep], cols[keep])), shape=(n, n))


def beck_column(elements: int, load: float, *, length: float = 1.0, bending_stiffness: float = 1.0,
                mass_per_length: float = 1.0) -> SparseForm:
    """The column of N = ``elements`` beam elements under the follower load P = ``load`` [N]
    (module docstring): a contact-free sparse form of 2N dofs, no damping."""
    h = length / elements
    k_e, m_e, g_e = _element_matrices(h)
    n = 2 * elements
    follower = sp.csr_matrix(([load], ([n - 2], [n - 1])), shape=(n, n))
    stiffness = sp.csr_matrix(bending_stiffness * _assemble(k_e, elements) - load * _assemble(g_e, elements)
                              + follower)
    mass = sp.csr_matrix(mass_per_length * _assemble(m_e, elements))
    empty = sp.csr_matrix((0, n))
    nodes = NodeMap(ids=np.arange(elements + 1), coordinates=np.c_[np.linspace(0.0, length, elements + 1),
                                                                      np.zeros((elements + 1, 2))],
                    node=np.repeat(np.arange(1, elements + 1), 2), component=np.tile([1, 5], elements),
                    cells=(("line", np.c_[np.arange(elements), np.arange(1, elements + 1)]),))
    return SparseForm(
        name=f"beck-column-{elements}", dofs=tuple(f"u{i}" for i in range(n)), mass=mass,
        damping=sp.csr_matrix((n, n)), stiffness=stiffness, force=np.zeros(n), free=np.ones(n, bool),
        tangent=empty, row_start=np.zeros(1, np.int64), drive=np.zeros(0), normal_force=np.zeros(0),
        normal_gradient=empty, normal_rate_gradient=empty, unilateral=np.zeros(0, bool),
        normal_law=np.zeros(0, str), gap=np.zeros(0), gap_gradient=empty, contact_stiffness=np.zeros(0),
        contact_damping=np.zeros(0), restitution=np.zeros(0), friction=(), contact_names=(), nodes=nodes)


def _boundary_determinant(load: float, omega2: float) -> float:
    """The determinant of the four end conditions of W(x) = A cos ax + B sin ax + C cosh bx +
    D sinh bx, the general solution of W'''' + p W'' − Ω² W = 0 (EI = m = L = 1), a² − b² = p,
    a² b² = Ω²."""
    root = math.sqrt(load * load + 4.0 * omega2)
    a, b = math.sqrt((load + root) / 2.0), math.sqrt((root - load) / 2.0)
    ca, sa, cb, sb = math.cos(a), math.sin(a), math.cosh(b), math.sinh(b)
    rows = np.array([[1.0, 0.0, 1.0, 0.0],                                 # W(0) = 0
                     [0.0, a, 0.0, b],                                     # W'(0) = 0
                     [-a * a * ca, -a * a * sa, b * b * cb, b * b * sb],   # W''(1) = 0
                     [a**3 * sa, -(a**3) * ca, b**3 * sb, b**3 * cb]])     # W'''(1) = 0
    return float(scipy.linalg.det(rows))


def continuum_onset() -> tuple[float, float]:
    """(P_c L²/EI, Ω_c L² √(m/EI)) of the continuous column: the load and frequency where the two
    lowest roots Ω² of the boundary determinant merge (the determinant and its Ω²-derivative both
    vanish), by Newton's method (scipy's fsolve) from (20, 121)."""
    def equations(x):
        load, omega2 = x
        step = 1e-6 * omega2
        slope = (_boundary_determinant(load, omega2 + step) - _boundary_determinant(load, omega2 - step)) / (2 * step)
        return [_boundary_determinant(load, omega2), slope]

    (load, omega2), _, ier, message = scipy.optimize.fsolve(equations, [20.0, 121.0], full_output=True, xtol=1e-13)
    if ier not in (1, 5):  # 5: no further progress at xtol, i.e. converged to round-off
        raise RuntimeError(f"continuum onset: {message}")
    return float(load), math.sqrt(omega2)


def pair(band) -> np.ndarray:
    """The two eigenvalues with Im λ > 0 of smallest modulus in a CEA band: the coalescing pair."""
    upper = band.eigenvalues[band.eigenvalues.imag > 0]
    return upper[np.argsort(np.abs(upper))][:2]


def flutter_onset(elements: int, *, bracket=(19.0, 21.0), xtol: float = 1e-9):
    """(P_c, Ω_c, band at P_c) of the N-element column, every eigenvalue from stickslip's CEA
    (:func:`stickslip.stability.stability` with ``max_frequency`` = :data:`BAND`).

    The onset is the root of the pair's discriminant d(P) = ((λ₁² − λ₂²)/2)²: positive while the
    pair is two frequencies (λ² = −ω₁², −ω₂²), negative once they have merged (λ = ±a + ib),
    linear in P through the onset, where the growth rate rises as √(P − P_c) — so Brent's method
    on d takes ~10 CEAs where bisection on the stability verdict would take ~30. Ω_c: the mean
    frequency of the pair at P_c.
    """
    from stickslip.stability import stability

    def discriminant(load: float) -> float:
        a, b = pair(stability(beck_column(elements, load), max_frequency=BAND))
        return float((((a * a - b * b) / 2.0) ** 2).real)

    load = scipy.optimize.brentq(discriminant, *bracket, xtol=xtol)
    band = stability(beck_column(elements, load), max_frequency=BAND)
    return load, float(np.mean(pair(band).imag)), band
