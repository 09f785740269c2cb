"""Elementary functions for model code that is differentiated by complex step.

``sin``, ``cos``, ``exp`` and ``sqrt`` behave as ``math``'s on float64 (sin and cos of angles up to
:data:`SMALL_ANGLE` by their Taylor polynomials, equal to round-off and several times faster than a
library call) and, on complex128, take the
complex-step shortcut: a complex step perturbs a value by i ε with ε ≤ 1e-8 relative (the
kernels use 1e-150), where cosh ε = 1 and sinh ε = ε exactly in double precision, so

    sin(a + i ε) = sin a + i ε cos a,   cos(a + i ε) = cos a − i ε sin a,
    exp(a + i ε) = eᵃ (1 + i ε),        sqrt(a + i ε) = √a + i ε / (2√a)   (a > 0)

are exact and cost one real evaluation (sin and cos of the same angle become one sincos), where
numpy's complex functions call sin, cos, sinh and cosh. Larger imaginary parts fall back to the
full complex functions, so the results are always right.

Use them in contact frames (:mod:`stickslip.model.kinematics`) and user friction laws; plain
``np.sin`` etc. are correct too, only slower on the complex path.
"""

from __future__ import annotations

import cmath
import math

from numba.core import types
from numba.extending import overload, register_jitable

from .jit import KERNEL_OPTIONS

__all__ = ["sin", "cos", "exp", "sqrt", "zero"]

#: Largest |Im z| / max(1, |Re z|) for which the shortcut is exact (ε²/2 below half an ulp of 1).
SHORTCUT = 1e-8

#: Largest |x| [rad] for which sin and cos are their Taylor polynomials (sin to x⁹, cos to x¹⁰:
#: truncation ≤ x¹¹/11! ≈ 2.5e-19 relative at 0.1, below round-off), a few multiply-adds instead
#: of a library call. Rotations of mechanical models (the plates' φ, ψ ≲ 0.1 rad) stay in it.
SMALL_ANGLE = 0.1
_S3, _S5, _S7, _S9 = -1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362880.0
_C2, _C4, _C6, _C8, _C10 = -0.5, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40320.0, -1.0 / 3628800.0


def sin(x):  # pragma: no cover - the Python versions below are used outside compiled code
    return cmath.sin(x) if isinstance(x, complex) else math.sin(x)


def cos(x):  # pragma: no cover
    return cmath.cos(x) if isinstance(x, complex) else math.cos(x)


def exp(x):  # pragma: no cover
    return cmath.exp(x) if isinstance(x, complex) else math.exp(x)


def sqrt(x):  # pragma: no cover
    return cmath.sqrt(x) if isinstance(x, complex) else math.sqrt(x)


def _is_complex(x) -> bool:
    return isinstance(x, types.Complex)


@register_jitable
def _real_sin(x):
    if abs(x) <= SMALL_ANGLE:
        x2 = x * x
        return x + x * x2 * (_S3 + x2 * (_S5 + x2 * (_S7 + x2 * _S9)))
    return math.sin(x)


@register_jitable
def _real_cos(x):
    if abs(x) <= SMALL_ANGLE:
        x2 = x * x
        return 1.0 + x2 * (_C2 + x2 * (_C4 + x2 * (_C6 + x2 * (_C8 + x2 * _C10))))
    return math.cos(x)


def _complex_step(func, real, applies, parts, full):
    """Overload ``func``: ``real(x)`` on floats; on complex numbers ``parts(a, b)`` = (real part,
    imaginary part) of func(a + i b) where ``applies(a, b)`` says the shortcut is exact, else
    ``full(x)``."""
    @overload(func, inline="always", jit_options=KERNEL_OPTIONS)
    def _overload(x):
        if _is_complex(x):
            def impl(x):
                a = x.real
                b = x.imag
                if applies(a, b):
                    re, im = parts(a, b)
                    return complex(re, im)
                return full(x)
            return impl
        return lambda x: real(x)


@register_jitable
def _angle_step(a, b):
    return abs(b) <= SHORTCUT * max(1.0, abs(a))


@register_jitable
def _exp_step(a, b):
    return abs(b) <= SHORTCUT


@register_jitable
def _sqrt_step(a, b):
    return a > 0.0 and abs(b) <= SHORTCUT * a


@register_jitable
def _sin_parts(a, b):
    return _real_sin(a), b * _real_cos(a)


@register_jitable
def _cos_parts(a, b):
    return _real_cos(a), -b * _real_sin(a)


@register_jitable
def _exp_parts(a, b):
    e = math.exp(a)
    return e, e * b


@register_jitable
def _sqrt_parts(a, b):
    r = math.sqrt(a)
    return r, 0.5 * b / r


@register_jitable
def _real_exp(x):
    return math.exp(x)


@register_jitable
def _real_sqrt(x):
    return math.sqrt(x)


_complex_step(sin, _real_sin, _angle_step, _sin_parts, cmath.sin)
_complex_step(cos, _real_cos, _angle_step, _cos_parts, cmath.cos)
_complex_step(exp, _real_exp, _exp_step, _exp_parts, cmath.exp)
_complex_step(sqrt, _real_sqrt, _sqrt_step, _sqrt_parts, cmath.sqrt)


def zero(x):  # pragma: no cover
    """0 of the number type of ``x`` (0.0 or 0j)."""
    return 0 * x


@overload(zero, jit_options=KERNEL_OPTIONS)
def _zero(x):
    if _is_complex(x):
        return lambda x: 0j
    return lambda x: 0.0
