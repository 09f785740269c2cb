"""Shared set-up."""

import signal

import matplotlib

matplotlib.use("Agg")

# Several tests press Ctrl-C in a child process, as a user at a terminal would. A child inherits
# an *ignored* SIGINT (pytest started as a background job of a script, as CI may run it) and then
# rightly ignores Ctrl-C throughout; the children of a test session get the terminal's default.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
