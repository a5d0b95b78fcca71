"""The ``emc`` command: speed sweeps and run-ups with the packaged FMU, tables and plots.

Examples:
    emc sweep --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --count 18 --out out/sweep
    emc sweep ... --case "with shaft" --case "no shaft:effects.balanceShaft=off"
    emc sweep ... --scheduler tcp://10.0.0.5:8786        # a running Dask cluster
    emc runup --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --duration 20 --out out/runup
    emc accuracy --set configFile=/path/my_car.json --out out/accuracy  # what accuracy costs
    emc tpa --rpm 800 2500 --at 1100 --order 1.5 --out out/tpa   # which mount path carries it
    emc frf / emc ods --rpm-point 1100 / emc decoupling --out ...  # transfer functions, shapes, mounts

Every command runs scene 2 (the engine in the elastic body) unless --set scene=1. A case is
--case NAME or --case NAME:name=value,name=value (repeatable; the common --set values apply to
every case, a case's own settings on top). Settings are checked against the FMU's model
description before anything runs.
"""

from __future__ import annotations

import argparse
import atexit
import importlib
import os
import re
import sys

from .base import outputs
from .base.errors import UsageError, WorkerLost
from .commands import MODULES


class Parser(argparse.ArgumentParser):
    """argparse, taking ``--opt -1e-4`` as a negative number (argparse alone takes only ``-1``
    and ``-.5`` so, and a value in exponent form for an option), and reporting a bad argument
    in one line."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(
            r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|nan)$")

    def error(self, message):
        self.exit(2, f"error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="emc", description=__doc__,
                    formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for name in MODULES:
        importlib.import_module(f"{__package__}.commands.{name}").register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Runs one command; expected failures (a refused option, a failed point) end with the cause
    on stderr and a non-zero exit code, without a Python traceback."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as done:  # --help, or a bad argument reported by the parser
        return done.code or 0
    args.command_line = ["emc"] + list(sys.argv[1:] if argv is None else argv)
    try:
        # Deferred: the runner imports fmpy and numpy, which --help and argument errors do not
        # need (start-up time).
        from .running.runner import PointFailed, keep_freed_memory

        keep_freed_memory()
        if getattr(args, "out_policy", None):
            outputs.check(args)
        return args.func(args)
    except UsageError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except PointFailed as failure:
        print(failure.report(), file=sys.stderr)
        return 1
    except WorkerLost as lost:
        print(f"error: {lost}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    finally:
        if getattr(args, "out_claim", None) is not None:
            args.out_claim.release()


def run() -> None:
    """The ``emc`` command (and ``python -m emc``): :func:`main`, then the process ends without
    Python's own teardown. The exit handlers run (temporary folders, logging, a Dask cluster's
    finalisers) and the standard streams are flushed; skipped is only the clearing of the
    modules, 0.12-0.13 s of every command that loaded pandas, matplotlib and fmpy (a process that
    imports them and ends: 0.74-0.75 s against 0.61-0.62 s). Every file emc writes is closed
    where it is written, so nothing waits for the teardown."""
    code = main()
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe: nothing more can reach it
            pass
    os._exit(0 if code is None else code if isinstance(code, int) else 1)


if __name__ == "__main__":
    run()
