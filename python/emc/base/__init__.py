"""The bottom floor of emc: what every command shares and nothing in it imports from the rooms
above.

- :mod:`emc.base.errors`: the one-line failures (:class:`UsageError`).
- :mod:`emc.base.orders`: the engine orders every analysis reports, and the highest.
- :mod:`emc.base.fmu`: what an FMU's model description says (variables, outputs, mounts,
  configuration files).
- :mod:`emc.base.checks`: settings, cases and option values checked before anything runs.
- :mod:`emc.base.options`: every option that several commands take, registered in one place.
- :mod:`emc.base.outputs`: result folders, tables, ``metadata.json`` and messages.

Nothing here imports numpy, pandas, fmpy or matplotlib at import time, so that the command line
starts fast; a function that needs one imports it when called.
"""
