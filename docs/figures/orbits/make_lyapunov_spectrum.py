"""Regenerate docs/figures/orbits/lyapunov_spectrum_*.png (docs/orbits.md, "Lyapunov spectrum").

Run from the repository root: ``python docs/figures/orbits/make_lyapunov_spectrum.py`` (~5 min,
one core). Prints the exponents and the Floquet exponents ln|μ_i|/T of the attracting orbit.
"""

import time
from pathlib import Path

import numpy as np

from stickslip import Parameters, simulate
from stickslip.orbits import Section, lyapunov_spectrum, periodic_orbit
from stickslip.plot.orbits import plot_lyapunov_spectrum

OUT = Path(__file__).parent


def report(label, spec, orbit):
    floquet = np.log(np.abs(orbit.multipliers[:10])) / orbit.period
    print(f"{label}: T = {orbit.period:.7f} s, {orbit.stick_phases} stick phase(s), "
          f"{spec.t_transient:g} s transient + {spec.time[-1]:.0f} s averaging, {spec.wall_time:.0f} s wall")
    print("  spectrum:", np.array2string(np.sort(spec.exponents)[::-1], precision=5))
    print("  Floquet :", np.array2string(floquet, precision=5))
    return floquet


def main():
    # Fig. 10(b): N = 50 N, on its shooting orbit
    t = time.perf_counter()
    o50 = periodic_orbit(Parameters(N=50.0, Omega=0.5), "equilibrium", search_time=30.0)
    s50 = lyapunov_spectrum(ic=o50, t_transient=1.0, t_average=400.0, record=2.0)
    f50 = report("N = 50 N", s50, o50)
    fig = plot_lyapunov_spectrum(s50, reference=f50)
    fig.axes[0].set_yscale("symlog", linthresh=0.01)  # exponents from 0 to −3 1/s
    fig.savefig(OUT / "lyapunov_spectrum_N50.png", dpi=130)

    # Fig. 10(f): N = 120 N, from the perturbed equilibrium (the paper's "non-periodic" case)
    P = Parameters(N=120.0, Omega=0.5)
    s120 = lyapunov_spectrum(P, "equilibrium", t_transient=100.0, t_average=1000.0, record=5.0)
    late = simulate(P, 4000.0, ic="equilibrium", perturbation=1e-3, rtol=1e-10, atol=1e-13,
                    sample_rate=1.0)
    # a section crossed once per period, in slip (φ has two maxima per period, one of them in stick)
    o120 = periodic_orbit(P, late.final_state, search_time=30.0,
                          section=Section(0, -0.04, 1, "x1=-0.04 up"))
    f120 = report("N = 120 N", s120, o120)
    fig = plot_lyapunov_spectrum(s120, reference=f120)
    fig.axes[0].set_yscale("symlog", linthresh=0.01)
    fig.savefig(OUT / "lyapunov_spectrum_N120.png", dpi=130)
    print(f"total {time.perf_counter() - t:.0f} s")


if __name__ == "__main__":
    main()
