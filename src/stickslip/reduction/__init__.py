"""Reduced models of sparse friction models (Craig–Bampton, modal truncation with the contact DOFs
kept), written as model files every tool takes, with the error of their steady-sliding eigenvalues."""

from .bases import METHODS, Reduced, ReductionError, boundary_dofs, reduce_model
from .model_writer import write_model_file
from .report import ReductionReport, reduction_report

__all__ = ["reduce_model", "Reduced", "ReductionError", "boundary_dofs", "METHODS", "write_model_file",
           "reduction_report", "ReductionReport"]
