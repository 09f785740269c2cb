"""``stickslip stability`` and ``stickslip stability-map``: linear stability of steady sliding.

Parse → library call → print/write; no physics here.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import List, Optional

import numpy as np
import typer
from rich.table import Table
from rich.text import Text

from ._app import (CONFIG_HELP, OVERWRITE_HELP, CLIError, app, build_parameters, check_finite, check_memory,
                   check_outputs, console)

_N_HELP = "Normal preload N [N] (default 50)."
_OMEGA_HELP = "Angular velocity Ω of the lower plate [rad/s] (default 5)."


@app.command()
def stability(
    N: Optional[float] = typer.Option(None, "--N", help=_N_HELP),
    omega: Optional[float] = typer.Option(None, "--omega", help=_OMEGA_HELP),
    mu_k: Optional[float] = typer.Option(None, "--mu-k", help="Kinetic friction coefficient μk (default 0.2)."),
    delta_mu: Optional[float] = typer.Option(None, "--delta-mu", help="μs − μk (default 0.1)."),
    alpha: Optional[float] = typer.Option(None, "--alpha", help="Decay factor α of Eq. (4) [s/m] (default 5)."),
    model: str = typer.Option("full", "--model", help="full | x | y | rotation (paper Models 1–4) or DOFs, e.g. phi,psi."),
    set_: Optional[List[str]] = typer.Option(None, "--set", help="Any parameter as NAME=VALUE (repeatable), e.g. --set k_px=400."),
    config: Optional[Path] = typer.Option(None, "--config", help=CONFIG_HELP),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object: equilibrium, eigenvalues, max_real_part, stable."),
) -> None:
    """Equilibrium of steady sliding (Eq. 14) and its eigenvalues (Eq. 15)."""
    from ..stability.analysis import stability as run_stability

    params, _ = build_parameters(config, set_, N=N, Omega=omega, mu_k=mu_k, delta_mu=delta_mu, alpha=alpha)
    result = run_stability(params, model=model)
    if as_json:
        print(json.dumps(result.summary()))
        return
    p = result.params
    eq = Table(title=f"steady sliding: model {result.model}, N = {p.N:g} N, Ω = {p.Omega:g} rad/s, "
                     f"μk = {p.mu_k:g}, Δμ = {p.delta_mu:g}, α = {p.alpha:g}")
    for name in result.dofs:
        eq.add_column(name, justify="right")
    eq.add_row(*[f"{result.equilibrium_dict[d]:.6g}" for d in result.dofs])
    console.print(eq)
    modes = Table(title="modes (one per conjugate pair), sorted by growth rate")
    for head in ("#", "growth rate [1/s]", "frequency [Hz]", "dominant DOF", "shape |.| (" + ", ".join(result.dofs) + ")"):
        modes.add_column(head, justify="right" if head != "dominant DOF" else "left")
    for row in result.modes():
        shape = ", ".join(f"{abs(c):.3g}" for c in row["shape"].values())
        style = "bold red" if row["growth_rate"] > 0 else None
        modes.add_row(str(row["index"]), f"{row['growth_rate']:.6g}", f"{row['frequency_hz']:.6g}",
                      row["dominant_dof"], shape, style=style)
    console.print(modes)
    verdict = Text("stable", style="green") if result.stable else Text("unstable", style="bold red")
    console.print(Text.assemble(f"max real part {result.max_real_part:.6g} 1/s: steady sliding is ", verdict))


#: Memory of a stability map [bytes]: per grid point and member, the largest real part and its
#: stacked copy; per Ω value, a row of 12 × 12 Jacobians and the eigenvalue solver's copy.
_MAP_POINT_BYTES, _MAP_OMEGA_BYTES = 24, 2 * 12 * 12 * 8


def _check_axis(name: str, lo: float, hi: float, n: int) -> None:
    """``n`` values from ``lo`` to ``hi`` must make a map axis ``name`` (``N`` or ``omega``)."""
    check_finite({f"--{name}-min": lo, f"--{name}-max": hi})
    if n < 2:
        raise CLIError(f"--{name}-points must be >= 2, got {n}")
    if not hi > lo:
        raise CLIError(f"--{name}-max {hi:g} must be greater than --{name}-min {lo:g}")
    if name == "N" and lo <= 0:
        raise CLIError(f"--N-min {lo:g}: normal loads must be > 0 (the plates are pressed together)")
    if name == "omega" and lo <= 0 <= hi:
        raise CLIError(f"--omega-min {lo:g} and --omega-max {hi:g} straddle 0, where there is no steady sliding; "
                       "give a range on one side of 0, e.g. --omega-min 0.2 --omega-max 20")


def _check_grid_memory(n_points: int, omega_points: int, members: int) -> None:
    need = float(n_points) * omega_points * members * _MAP_POINT_BYTES + float(omega_points) * _MAP_OMEGA_BYTES
    check_memory(need, f"a {n_points} × {omega_points} map of {members} member(s)", "lower --N-points or --omega-points")


@app.command("stability-map")
def stability_map(
    n_min: float = typer.Option(2.0, "--N-min", help="Smallest normal load [N]."),
    n_max: float = typer.Option(200.0, "--N-max", help="Largest normal load [N]."),
    n_points: int = typer.Option(100, "--N-points", help="Number of N values."),
    omega_min: float = typer.Option(0.2, "--omega-min", help="Smallest Ω [rad/s] (the range must not straddle 0)."),
    omega_max: float = typer.Option(20.0, "--omega-max", help="Largest Ω [rad/s]."),
    omega_points: int = typer.Option(100, "--omega-points", help="Number of Ω values (brackets for the boundary search)."),
    family: Optional[str] = typer.Option(None, "--family", help="Third parameter and its values, e.g. delta_mu=0.1,0.2,0.3 or model=full,rotation."),
    mu_k: Optional[float] = typer.Option(None, "--mu-k", help="Kinetic friction coefficient μk (default 0.2)."),
    delta_mu: Optional[float] = typer.Option(None, "--delta-mu", help="μs − μk (default 0.1)."),
    alpha: Optional[float] = typer.Option(None, "--alpha", help="Decay factor α of Eq. (4) [s/m] (default 5)."),
    model: str = typer.Option("full", "--model", help="full | x | y | rotation or DOFs (ignored with --family model=...)."),
    set_: Optional[List[str]] = typer.Option(None, "--set", help="Any parameter as NAME=VALUE (repeatable)."),
    config: Optional[Path] = typer.Option(None, "--config", help=CONFIG_HELP),
    no_boundary: bool = typer.Option(False, "--no-boundary", help="Skip the root-finding of the boundary Ω_c(N)."),
    out: Path = typer.Option(Path("stability_map.nc"), "--out", help="NetCDF output; the figure goes beside it as .png."),
    overwrite: bool = typer.Option(False, "--overwrite", help=OVERWRITE_HELP),
    no_plot: bool = typer.Option(False, "--no-plot", help="Do not draw the figure."),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON summary instead of the table."),
) -> None:
    """Stable/unstable regions of steady sliding over (N, Ω), with the boundary by root finding (Figs. 3, 4)."""
    from ..stability.maps import parse_family
    from ..stability.maps import stability_map as run_map

    params, _ = build_parameters(config, set_, mu_k=mu_k, delta_mu=delta_mu, alpha=alpha)
    _check_axis("N", n_min, n_max, n_points)
    _check_axis("omega", omega_min, omega_max, omega_points)
    try:
        members = parse_family(family)
    except ValueError as exc:  # the parser's messages name the fix; here they also name the option
        raise CLIError(f"--family: {exc}") from None
    if members is not None and members[0] in ("N", "Omega"):
        raise CLIError(f"--family {family}: {members[0]} is an axis of the map; choose another parameter or model")
    _check_grid_memory(n_points, omega_points, 1 if members is None else len(members[1]))
    check_outputs(out, not no_plot, overwrite)
    N, W = np.linspace(n_min, n_max, n_points), np.linspace(omega_min, omega_max, omega_points)
    smap = run_map(params, N, W, model=model, family=members, boundary=not no_boundary)
    out.parent.mkdir(parents=True, exist_ok=True)
    smap.to_netcdf(out)
    figure = None
    if not no_plot:
        from ..plot.stability import save_stability_map_figure

        figure = save_stability_map_figure(smap, out.with_suffix(".png"))
    rows = []
    for f, label in enumerate(smap.family_labels):
        mrp = smap.max_real_part[f]
        found = np.isfinite(mrp)
        rows.append({
            "member": label,
            "unstable_fraction": float(np.mean(mrp[found] > 0)) if np.any(found) else None,
            "no_equilibrium_fraction": float(np.mean(~found)),
            "boundary_points": int(np.sum(np.isfinite(smap.boundary[f]))),
        })
    if as_json:
        print(json.dumps({"out": str(out), "figure": None if figure is None else str(figure),
                          "family": smap.family_name, "members": rows, "timings": smap.timings}))
        return
    table = Table(title=f"stability map {n_points} × {omega_points} (N × Ω), model {smap.model}")
    for head in ("member", "unstable fraction", "no equilibrium", "boundary points"):
        table.add_column(head)
    for r in rows:
        uf = "–" if r["unstable_fraction"] is None else f"{r['unstable_fraction']:.3f}"
        table.add_row(r["member"], uf, f"{r['no_equilibrium_fraction']:.3f}", str(r["boundary_points"]))
    console.print(table)
    t = smap.timings
    console.print(f"grid {t['grid_s']:.2f} s, boundary {t['boundary_s']:.2f} s; wrote {out}"
                  + ("" if figure is None else f", {figure}"))
