"""Shared setup for the package's tests."""

import signal

# A shell starts a background job (`cmd &`, `nohup … &`, as a CI harness may run the suite) with
# SIGINT ignored, and an ignored signal stays ignored across fork and exec: Python then installs
# no KeyboardInterrupt handler, in pytest or in the processes the tests start (a forked child, a
# `python -c`, Ray's workers), and every Ctrl-C test failed there (4 of 74 with the suite
# backgrounded; all pass in the foreground or under `timeout`, which resets the signal). The tests
# of Ctrl-C need it delivered, so pytest takes Python's own handler back before any test starts
# a process.
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
