"""The verdict of a linear stability analysis in words: stable, marginal or unstable.

A real part within a tolerance of 0, set by the accuracy of the eigenvalue solver, is neither a
growth nor a decay: steady sliding is then *marginal* (a centre, or a zero eigenvalue), which the
linearisation leaves undecided. Every verdict of steady sliding — the result types, their JSON
fields, the command line and the run summaries — is worded by these functions.
"""

from __future__ import annotations

__all__ = ["MARGINAL_RTOL", "VERDICTS", "stability_verdict", "verdict_text"]

#: Real parts within this fraction of the scale of the eigenproblem (‖J‖₂, the Jacobian's largest
#: singular value) count as 0: steady sliding is then *marginal*, neither stable nor unstable in
#: the linearisation. LAPACK's QR algorithm (numpy.linalg.eig) is backward stable: its eigenvalues
#: are exact for J + E with ‖E‖ of order n ε ‖J‖ ≈ 1e-14 ‖J‖ for the models here, and a simple
#: eigenvalue moves by at most its condition number times ‖E‖; 1e-9 leaves room for condition
#: numbers up to ~1e5 and for the complex-step Jacobian's own round-off. An undamped centre's real
#: parts come out 0 or of order 1e-17 ‖J‖. The smallest |Re λ| of the library's defaults is far
#: above it (the plates: 9e-3 1/s against a tolerance of 3.4e-7 1/s, ‖J‖₂ = 339 1/s²).
MARGINAL_RTOL = 1e-9

#: The words of a linear-stability verdict of steady sliding.
VERDICTS = ("stable", "marginal", "unstable")


def stability_verdict(max_real_part: float, tolerance: float) -> str:
    """``stable`` (every Re λ < −tolerance), ``unstable`` (some Re λ > tolerance) or ``marginal``
    (the largest real part within ±tolerance of 0: a centre or a zero eigenvalue, which the
    linearisation leaves undecided) [of :data:`VERDICTS`]."""
    if max_real_part > tolerance:
        return "unstable"
    return "stable" if max_real_part < -tolerance else "marginal"


def verdict_text(max_real_part: float, tolerance: float) -> str:
    """The verdict in words for messages, with its number: e.g. ``marginal (max Re λ = 0 1/s, 0
    within the eigenvalue solver's accuracy 1.2e-08 1/s: the linearisation neither decays nor
    grows)``."""
    verdict = stability_verdict(max_real_part, tolerance)
    head = f"{verdict} (max Re λ = {max_real_part:.3g} 1/s"
    if verdict == "marginal":
        return (f"{head}, 0 within the eigenvalue solver's accuracy {tolerance:.2g} 1/s: the linearisation "
                "neither decays nor grows)")
    return head + ")"
