"""What a basin study's result depends on when its batches run in parallel (docs/basins.md, "What
depends on scheduling"): a state's record (verdict, what decided it, when) follows from the
cycles known when its batch was handed out, which worker scheduling decides; its label does not."""

import numpy as np

from stickslip.basins import basin_stability, box
from stickslip.basins.context import make_context
from stickslip.basins.early import Options, classify_state
from stickslip.model.library import load_model

POPP = load_model("popp-stelter")


def test_a_states_record_depends_on_the_cycles_known_and_its_label_does_not():
    ctx = make_context(POPP)
    states = box(POPP, {"x1": (-1, 1), "dx1": (-1, 1)}, n=12, seed=3).states(POPP, ctx.equilibrium[:POPP.n])
    opts = Options(t_end=300.0)
    alone = [classify_state(ctx, POPP, s, [], opts) for s in states]
    cycle = next(o.cycle for o in alone if o.decided_by == "period-rule")
    known = [classify_state(ctx, POPP, s, [cycle], opts) for s in states]
    assert any((a.decided_by, a.t_decided) != (k.decided_by, k.t_decided) for a, k in zip(alone, known))
    assert all(k.verdict == "periodic" and k.decided_by == "matched" for k in known)
    assert all(a.verdict in ("periodic", "unsettled") for a in alone)  # unsettled ones take the cycle at the end


def test_labels_and_fractions_do_not_depend_on_the_executor():
    """The measured case of docs/basins.md: 50 states × 6 drives, t_end 300."""
    states = box(POPP, {"x1": (-1, 1), "dx1": (-1, 1)}, n=50, seed=0)
    study = dict(param="contact.0.drive", values=np.linspace(0.5, 2.0, 6), t_end=300.0)
    serial = basin_stability(POPP, states, executor="serial", **study).to_xarray()
    pooled = basin_stability(POPP, states, executor="processes", workers=2, **study).to_xarray()
    for name in ("label", "count", "fraction", "standard_error"):
        assert np.array_equal(serial[name].values, pooled[name].values), name
    assert list(serial["attractor"].values) == list(pooled["attractor"].values)
