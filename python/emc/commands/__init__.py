"""The ``emc`` commands, one module per command or family of commands, each with one
``register(subparsers)`` that adds its parsers.

A command module holds only its options: its work runs in the rooms below (imported when the
command runs, :func:`emc.base.options.runs`), so that ``emc --help`` and an argument error do not
import numpy, pandas, fmpy, matplotlib or dask. Adding a command: a module here with
``register``, and its name in :data:`MODULES`.
"""

# In the order of ``emc --help``.
MODULES = ("sweep", "runup", "campbell", "paper", "why", "accuracy", "tuning", "testbench", "bench",
           "tools")
