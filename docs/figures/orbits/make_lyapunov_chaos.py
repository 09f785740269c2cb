"""Regenerate docs/figures/orbits/lyapunov_chaos*.png (docs/orbits.md, "A chaotic case").

Model 1 with detuned stiffnesses and 1/10 of Table 1's damping, N = 100 N, Ω = 1 rad/s:
largest Lyapunov exponent (Benettin, two trajectories) for two seeds and two initial
separations, 300 s transient, 2000 s averaging; and the spectrum by 12 perturbed trajectories
(``lyapunov_spectrum(method="finite-difference")``). Run from the repository root:
``python docs/figures/orbits/make_lyapunov_chaos.py`` (~2.5 min, one core).
"""

import time
from pathlib import Path

import numpy as np

from stickslip import Parameters, simulate
from stickslip.orbits import lyapunov_exponent, lyapunov_spectrum
from stickslip.plot.orbits import plot_lyapunov_convergence, plot_lyapunov_spectrum

OUT = Path(__file__).parent
C = 0.01  # all viscous dampings [N s/m, N m s]; Table 1 has 0.1
PARAMS = Parameters(k_px=300.0, k_py=200.0, k_dx=2500.0, k_dy=3500.0, k_pphi=80.0, N=100.0, Omega=1.0,
                    c_px=C, c_py=C, c_dx=C, c_dy=C, c_pphi=C, c_dpsi=C)


def main():
    t = time.perf_counter()
    runs, labels = [], []
    for seed, d0 in [(0, 1e-7), (1, 1e-7), (0, 1e-6), (0, 1e-8)]:
        L = lyapunov_exponent(PARAMS, "equilibrium", t_transient=300.0, t_average=2000.0,
                              seed=seed, d0=d0)
        runs.append(L)
        labels.append(f"seed {seed}, d0 = {d0:g}")
        print(f"seed {seed} d0 {d0:g}: λ = {L.exponent:.4f} ± {L.standard_error:.4f} 1/s, "
              f"running {[round(float(L.estimate[i]), 4) for i in (99, 499, 999, 1999)]}")
    # the attractor: peak-to-peak of φ and stick fraction in 100 s windows after the transient
    tr = simulate(PARAMS, 1300.0, ic="equilibrium", perturbation=1e-3, rtol=1e-10, atol=1e-13,
                  sample_rate=50.0)
    for k in range(3, 13):
        m = (tr.t >= 100 * k) & (tr.t < 100 * (k + 1))
        print(f"window {100 * k}-{100 * (k + 1)} s: ptp φ = {np.ptp(tr.states[m, 4]):.4f} rad, "
              f"stick fraction {tr.mode[m].mean():.3f}")
    fig = plot_lyapunov_convergence(runs, labels=labels)
    fig.axes[0].set_title("Model 1, detuned stiffnesses, damping 0.01, N = 100 N, Ω = 1 rad/s", fontsize=9)
    fig.savefig(OUT / "lyapunov_chaos.png", dpi=130)
    S = lyapunov_spectrum(PARAMS, "equilibrium", t_transient=300.0, t_average=2000.0,
                          method="finite-difference")
    lam = np.sort(S.exponents)[::-1]
    print(f"spectrum (FD, {S.wall_time:.0f} s): {np.array2string(lam, precision=4)}; {S.stick_phases} stick phases")
    for i in (99, 499, 999, 1999):
        print(f"  at {S.time[i]:.0f} s: {np.array2string(np.sort(S.estimate[i])[::-1][:5], precision=4)}")
    finite = lam[lam > -10.0]
    print(f"  sum of the {finite.size} finite exponents {finite.sum():.4f} 1/s")
    fig = plot_lyapunov_spectrum(S)
    fig.axes[0].set_yscale("symlog", linthresh=0.01)
    fig.savefig(OUT / "lyapunov_chaos_spectrum.png", dpi=130)
    print(f"total {time.perf_counter() - t:.0f} s")


if __name__ == "__main__":
    main()
