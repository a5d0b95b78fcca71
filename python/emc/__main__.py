"""``python -m emc``: the ``emc`` command where its script is not on the path."""

from .cli import run

run()
