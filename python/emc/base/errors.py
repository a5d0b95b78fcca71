"""The failures a command reports as one line (``error: …``) without a traceback."""


class UsageError(Exception):
    """A bad option, setting, file or folder: reported as one line before anything runs."""


class ClusterMismatch(UsageError):
    """A Dask worker cannot give the numbers this process would: another emc, fmpy or numpy,
    or another copy (or none) of a file the settings name."""


class WorkerLost(RuntimeError):
    """A worker process of a local pool ended in the middle of its work (killed, or a crash):
    reported as one line, with how it ended."""
