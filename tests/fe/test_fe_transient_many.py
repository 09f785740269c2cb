"""The event loop's rules for a large model of many contacts (``integrate.slip_watch.shared_steps``)
against those of a model of one contact.

Two pads on a belt side by side, uncoupled (block-diagonal M and K), one compliant contact node
each, make one model of two contacts: its steps follow the rules of many contacts (homing only
within the error controller's step, no approach ratio control for 1-D contacts, the stick
projection only past the velocity resolution). Each pad alone is a model of one contact, run by
the rules that ``test_fe_transient.test_one_contact_against_scipy`` checks against an event-driven
scipy integrator. The pads do not interact, so each pad's part of the pair's run is that pad's run:
other steps, the same solution.
"""

import dataclasses

import numpy as np
import scipy.sparse as sp

from stickslip import simulate
from stickslip.analysis.signal import CLOSE, OPEN, SLIP, STICK
from stickslip.model.kinematics import LARGE_KINEMATICS
from stickslip.model.library import load_model

from .fe_models import FEModel, one_contact, pad_on_belt
from .test_fe_transient import PAD, TOL, first_frequency


def side_by_side(a: FEModel, b: FEModel) -> FEModel:
    """Models ``a`` and ``b`` (of the same friction and contact law) as one, uncoupled: block-diagonal
    M and K, ``b``'s DOFs after ``a``'s, the contacts of both."""
    n = a.n
    return dataclasses.replace(
        a, name="pads-side-by-side", mass=sp.block_diag([a.mass, b.mass]).tocsr(),
        stiffness=sp.block_diag([a.stiffness, b.stiffness]).tocsr(),
        tangent_dof=np.concatenate([a.tangent_dof, b.tangent_dof + n]),
        normal_dof=np.concatenate([a.normal_dof, b.normal_dof + n]), gap=np.concatenate([a.gap, b.gap]),
        node_ids=np.concatenate([a.node_ids, b.node_ids + a.ids.max() + 1]))


def test_two_pads_side_by_side_run_as_each_pad_alone(tmp_path):
    pad = pad_on_belt(**PAD)
    singles = [one_contact(pad, 4), one_contact(pad, 2)]
    pair = load_model(str(side_by_side(*singles).write(tmp_path / "pair", contacts="tables", nodes=False)))
    assert pair.n_contacts == 2 and type(pair.data.kin) is LARGE_KINEMATICS[type(pair.kinematics)]
    f1 = first_frequency(singles[0])
    t_end, rate = 3.0 / f1, 100 * f1
    both = simulate(pair, t_end, sample_rate=rate, **TOL)
    assert both.status == "success"
    n = pad.n
    for k, single in enumerate(singles):
        alone = simulate(load_model(str(single.write(tmp_path / f"pad{k}", contacts="tables", nodes=False))), t_end,
                         sample_rate=rate, **TOL)
        assert alone.status == "success"
        mine = both.transitions.contact == k
        np.testing.assert_array_equal(both.transitions.kind[mine], alone.transitions.kind)
        assert {STICK, SLIP, OPEN, CLOSE} <= set(alone.transitions.kind.tolist())
        # the same instants to 1e-7 of a period, as the one-contact run against scipy
        np.testing.assert_allclose(both.transitions.time[mine], alone.transitions.time, rtol=0, atol=1e-7 / f1)
        for part_alone, part_pair in ((slice(0, n), slice(k * n, (k + 1) * n)),
                                      (slice(n, 2 * n), slice(2 * n + k * n, 2 * n + (k + 1) * n))):
            x, y = alone.states[:, part_alone], both.states[:, part_pair]
            assert np.abs(x - y).max() <= 1e-6 * np.abs(x).max()
