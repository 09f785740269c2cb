"""Shared set-up."""

import os
import signal

import matplotlib

matplotlib.use("Agg")

# Several tests press Ctrl-C in a child process, as a user at a terminal would. A child inherits
# an *ignored* SIGINT (pytest started as a background job of a script, as CI may run it) and then
# rightly ignores Ctrl-C throughout; the children of a test session get the terminal's default.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

# pytest-xdist's workers already fill the cores: a cold start compiles in one process per worker
# (tests/integrate/test_compile_ahead.py turns the helper process on where it tests it).
os.environ.setdefault("STICKSLIP_COMPILE_PROCESSES", "1")
