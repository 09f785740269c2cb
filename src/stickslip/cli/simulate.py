"""``stickslip simulate``: one run, written to NetCDF with a figure and a summary."""

from __future__ import annotations

import json
from pathlib import Path
from typing import List, Optional

import typer
from rich.table import Table

from ._app import CONFIG_HELP, app, build_parameters, check_nc_path, console, user_errors


def _parse_ic(text: str):
    """'zero' | 'equilibrium' | FILE.nc | 12 comma-separated numbers."""
    if "," in text:
        try:
            return [float(v) for v in text.split(",")]
        except ValueError:
            raise ValueError(f"--ic {text!r}: give 12 comma-separated numbers") from None
    return text


@app.command()
def simulate(
    N: Optional[float] = typer.Option(None, "--N", help="Normal preload N [N] (default 50)."),
    omega: Optional[float] = typer.Option(None, "--omega", help="Angular velocity Ω of the lower plate [rad/s] (default 5)."),
    mu_k: Optional[float] = typer.Option(None, "--mu-k", help="Kinetic friction coefficient μk (default 0.2)."),
    delta_mu: Optional[float] = typer.Option(None, "--delta-mu", help="μs − μk (default 0.1)."),
    alpha: Optional[float] = typer.Option(None, "--alpha", help="Decay factor α of Eq. (4) [s/m] (default 5)."),
    model: str = typer.Option("full", "--model", help="full | x | y | rotation (paper Models 1–4) or DOFs, e.g. phi,psi."),
    t_end: str = typer.Option("100", "--t-end", help="Simulated time [s], or 'auto': extend the run until it "
                              "has settled, up to --cap (the steady window is then the last 100 s)."),
    cap: float = typer.Option(2000.0, "--cap", help="With --t-end auto: the longest run [s]."),
    method: str = typer.Option("event", "--method", help="Integration method."),
    dt: Optional[float] = typer.Option(None, "--dt", help="Fixed step (fixed-step methods) or largest step (event) [s]."),
    rtol: float = typer.Option(1e-8, "--rtol", help="Relative tolerance (event)."),
    atol: float = typer.Option(1e-10, "--atol", help="Absolute tolerance (event)."),
    ic: str = typer.Option("zero", "--ic", help="zero | equilibrium | RUN.nc (its final state) | 12 comma-separated numbers."),
    perturb: Optional[float] = typer.Option(None, "--perturb", help="Added to φ of the initial state [rad]."),
    sample_rate: float = typer.Option(1000.0, "--sample-rate", help="Output samples per second [Hz]."),
    steady_from: Optional[float] = typer.Option(None, "--steady-from", help="Start of the steady-state window [s] (default: last half)."),
    set_: Optional[List[str]] = typer.Option(None, "--set", help="Any parameter as NAME=VALUE (repeatable), e.g. --set k_px=400."),
    config: Optional[Path] = typer.Option(None, "--config", help=CONFIG_HELP),
    out: Path = typer.Option(Path("run.nc"), "--out", help="NetCDF output; the figure goes beside it as .png."),
    no_plot: bool = typer.Option(False, "--no-plot", help="Do not draw the figure."),
    as_json: bool = typer.Option(False, "--json", help="Print the steady-state summary as one JSON object."),
) -> None:
    """Simulate the two-plate model (defaults: Table 1, N = 50 N, Ω = 5 rad/s, 100 s)."""
    from ..integrate.driver import simulate as run_simulation

    with user_errors():
        params = build_parameters(config, set_, N=N, Omega=omega, mu_k=mu_k, delta_mu=delta_mu, alpha=alpha)
        check_nc_path(out)
        options = dict(model=model, method=method, ic=_parse_ic(ic), perturbation=perturb, rtol=rtol, atol=atol,
                       dt=dt, sample_rate=sample_rate)
        if t_end.strip().lower() == "auto":
            from ..analysis.settle import simulate_until_settled

            if steady_from is not None:
                raise ValueError("--steady-from cannot be combined with --t-end auto (the window is the last 100 s); "
                                 "drop one of them")
            traj = simulate_until_settled(params, cap=cap, **options)
        else:
            try:
                t_end_s = float(t_end)
            except ValueError:
                raise ValueError(f"--t-end {t_end}: give a time in seconds or auto") from None
            traj = run_simulation(params, t_end_s, steady_from=steady_from, **options)
        out.parent.mkdir(parents=True, exist_ok=True)
        traj.to_netcdf(out)
        figure = None
        if not no_plot:
            from ..plot.trajectory import save_trajectory_figure

            figure = save_trajectory_figure(traj, out.with_suffix(".png"))
    summary = traj.summary()
    if as_json:
        print(json.dumps(summary))
    else:
        _print_summary(traj, summary, out, figure)
    if traj.status != "success":
        raise typer.Exit(1)


def _print_summary(traj, summary: dict, out: Path, figure) -> None:
    s = traj.steady
    p = traj.params
    table = Table(title=f"stickslip: model {traj.model}, N = {p.N:g} N, Ω = {p.Omega:g} rad/s, "
                        f"μk = {p.mu_k:g}, Δμ = {p.delta_mu:g}, α = {p.alpha:g}", show_header=False)
    freq, dominant = summary["fundamental_frequency_hz"], summary["dominant_frequency_hz"]
    kind = summary["attractor"] + (f", {summary['period_count']} peak(s) of φ per period" if summary["period_count"] else "")
    kind += (f" (settled by {summary['settle_time_s']:g} s)" if summary["settled"]
             else f" ({summary['evidence'].get('reason', 'no verdict')})")
    rows = [
        ("status", traj.status),
        ("steady window", f"{s.t_from:g} – {s.t_to:g} s"),
        ("response", kind),
        ("fundamental frequency of φ", "–" if freq is None else f"{freq:.6g} Hz"),
        ("dominant frequency of φ", "–" if dominant is None else f"{dominant:.6g} Hz"),
        ("stick fraction", f"{s.stick_fraction:.4f}"),
        ("transitions in window", str(s.n_transitions)),
        ("φ min / max", f"{s.phi_min:.6g} / {s.phi_max:.6g} rad"),
        ("steps (accepted + rejected)", f"{traj.stats.steps} ({traj.method})"),
        ("wall time", f"{traj.stats.wall_time_s:.3f} s"),
        ("wrote", str(out) + ("" if figure is None else f", {figure}")),
    ]
    for key, value in rows:
        table.add_row(key, value)
    console.print(table)
    if not summary["settled"]:
        console.print("[dim]not settled in the window: no period is claimed (the dominant frequency is the "
                      "highest peak of the φ spectrum); run longer or use --t-end auto[/]")
    if traj.stats.compile_time_s > 0:
        console.print(f"[dim]first call: kernels compiled or loaded from cache in {traj.stats.compile_time_s:.1f} s "
                      "(not included in the wall time)[/]")
