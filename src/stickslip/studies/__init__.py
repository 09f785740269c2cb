"""Reproducible studies (computation only; figures in :mod:`stickslip.plot`, commands in
:mod:`stickslip.cli`).

==========================  ==============================================================
``timestep``                paper Sect. 4.2.1: AEOM / NAEOM step-size study (Table 2, Figs. 5–6)
``reproduce``               every figure of the paper beside it, with a report (``stickslip reproduce``)
``models``                  the library models' figures (docs/models/)
==========================  ==============================================================
"""

from .timestep import PAPER_TABLE2, TimestepStudy, run_timestep_study

__all__ = ["PAPER_TABLE2", "TimestepStudy", "run_timestep_study"]
