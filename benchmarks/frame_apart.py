"""What a frame compiled apart costs a steady run: the same model with its frame inlined or called.

The worked example's arm on a belt (``stickslip.studies.models.belt_arm``: one DOF, nonlinear
kinematics, stick-slip) with its kinematics class ``BeltArm`` (a class of the package: the frame
compiled into kernels specialised for it, the sizes fixed) against the same numbers under a class
registered here with ``inline=False`` (the frame compiled on its own and called through its
address by kernels shared by every such class, sizes read at run time; the default for a user's
class). Both runs are checked to be the same bit for bit, then timed alternately (``--pairs``
pairs) so that both see the same machine. Prints the median ratio of wall times (apart / inlined)
with quartiles and writes JSON.

    python benchmarks/frame_apart.py [--t-end 3000] [--pairs 20]
Writes benchmarks/results/frame_apart.json.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path
from typing import NamedTuple

import numpy as np

import stickslip
from stickslip.model.kinematics import register_kinematics
from stickslip.studies import models as studies

ROOT = Path(__file__).resolve().parents[1]


class ArmApart(NamedTuple):
    """The belt arm's kinematics data under a class whose frame is compiled apart."""

    H: float
    V: float


register_kinematics(ArmApart, studies.belt_arm_frame, ndof=1, ncontacts=1, dim=1, inline=False)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=3000.0, help="simulated time of each timed run")
    ap.add_argument("--pairs", type=int, default=20)
    args = ap.parse_args()
    inlined = studies.belt_arm()
    cases = {"inlined": inlined, "apart": dataclasses.replace(inlined, kinematics=ArmApart(*inlined.kinematics))}
    ic = {"theta": 0.0, "dtheta": 0.1}
    runs = {name: stickslip.simulate(model, args.t_end, ic=ic) for name, model in cases.items()}
    if not np.array_equal(runs["inlined"].states, runs["apart"].states):
        raise SystemExit("the two runs differ: the comparison would not be of the same work")
    walls = {name: [] for name in cases}
    for i in range(args.pairs):
        for name in (("apart", "inlined") if i % 2 else ("inlined", "apart")):
            walls[name].append(stickslip.simulate(cases[name], args.t_end, ic=ic).stats.wall_time_s)
    ratios = np.array([a / b for a, b in zip(walls["apart"], walls["inlined"])])
    q1, med, q3 = np.percentile(ratios, [25, 50, 75])
    stats = runs["inlined"].stats
    print(f"belt arm, {args.t_end:g} time units, {stats.steps} steps, {stats.slip_to_stick} stick phases")
    print(f"inlined {np.median(walls['inlined']):.3f} s, apart {np.median(walls['apart']):.3f} s (medians)")
    print(f"apart / inlined: {med:.3f} (quartiles {q1:.3f} .. {q3:.3f}, {args.pairs} pairs)")
    out = ROOT / "benchmarks" / "results" / "frame_apart.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"t_end": args.t_end, "pairs": args.pairs, "steps": int(stats.steps),
                               "wall_s": walls, "ratio_median": med, "ratio_quartiles": [q1, q3]}, indent=2))


if __name__ == "__main__":
    main()
