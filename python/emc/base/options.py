"""Every option that more than one command takes, registered here once: a command's
``register`` calls these and adds only what is its own.

The functions take what differs between commands (a default, a word of help) as arguments, so
that an option's name, type and meaning are written once. The result-folder options also mark
the command for the output-folder policy (:func:`emc.base.outputs.claim`).
"""

from __future__ import annotations

import argparse
import importlib
import math

DEFAULT_FMU = "dist/EngineMountChassis.fmu"
# A local pool without --workers: this many workers, for this many runs or more.
DEFAULT_WORKERS = 2
POOL_FROM = 16

# The damping band's default bounds. The body: 5 % of critical nominal, 3–7 % (Adams &
# Askenazi's range for metal structures with joints) as modalDampingScale 0.6–1.4. The mounts: a
# loss factor of 0.15 at 10 Hz nominal, 0.10–0.20 (rubber engine mounts) as dampingScale
# 2/3–4/3, paired the other way round: above the powertrain's own modes on its mounts a mount's
# damping transmits force to the body, so the least damped body with the most damped mounts gives
# the highest levels at the body's resonances (and the other pair the lowest).
BAND_BODY_SCALE = (0.6, 1.4)
BAND_MOUNT_SCALE = (4.0 / 3.0, 2.0 / 3.0)


def number(text: str) -> float:
    """A float option's value, which may be negative (``--opt -1e-4``) but must be finite."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite, got {text}")
    return value


def runs(target: str):
    """The command function ``module:function``, imported when the command runs: the command
    line builds every parser without importing numpy, pandas, fmpy, matplotlib or dask, which a
    command's work needs (a deferred heavy import, for start-up time)."""
    module, function = target.split(":")

    def run(args) -> int:
        return getattr(importlib.import_module(module), function)(args)

    run.target = target
    return run


def add_fmu(p, default: str = DEFAULT_FMU, option: str = "--fmu", what: str = "the packaged FMU"):
    p.add_argument(option, default=default, help=f"{what} (default {default})")


def add_speed_range(p, default=(800.0, 2500.0), help: str = "speed range, rpm"):
    p.add_argument("--rpm", nargs=2, type=number, default=list(default), metavar=("FROM", "TO"),
                   help=f"{help} (default {default[0]:g} {default[1]:g})")


def add_speed_point(p, default: float | None = None, help: str = "engine speed, rpm"):
    if default is None:
        p.add_argument("--rpm-point", type=number, required=True, help=help)
    else:
        p.add_argument("--rpm-point", type=number, default=default,
                       help=f"{help} (default {default:g})")


def add_count(p, default: int, help: str = "speed points"):
    p.add_argument("--count", type=int, default=default, help=f"{help} (default {default})")


def add_settings(p, help: str = "FMU start value for every case, e.g. "
                                "effects.balanceShaft=off (repeatable; checked against the model "
                                "description; default scene=2)"):
    p.add_argument("--set", action="append", metavar="NAME=VALUE", help=help)


def add_cases(p, help: str = "a case with its own settings on top of the common --set values "
                             "(repeatable: the cases accumulate in one table and are overlaid)"):
    p.add_argument("--case", action="append", metavar="NAME[:NAME=VALUE,...]", help=help)


def add_signals(p, help: str):
    p.add_argument("--signal", action="append", help=help)


def add_plots(p, default: str):
    p.add_argument("--plot", action="append",
                   help=f"analysed signal to plot (repeatable; default: {default})")


def add_responses(p, help: str = "acceleration to explain: steeringWheel.a[1..3], seat.a[1..3] "
                                 "or <body point>.a[1..3] (repeatable; default "
                                 "steeringWheel.a[3])"):
    p.add_argument("--response", action="append", help=help)


def add_order(p, default: float = 1.5, help: str = "order of the plots"):
    p.add_argument("--order", type=number, default=default, help=f"{help} (default {default:g})")


def add_load_torque(p):
    p.add_argument("--load-torque", type=number, default=0.0,
                   help="the drivetrain's reaction torque on the engine, N·m, every run "
                        "(default 0)")


def add_window(p, revolutions: int | None, steps: int = 72, load: bool = True):
    """The analysed window of constant-speed points: revolutions (``None``: by the start, see
    :func:`emc.base.checks.start_options`), samples per revolution and the load torque."""
    if revolutions is None:
        p.add_argument("--revolutions", type=int, default=None,
                       help="analysed window (even; default 8 with a periodic start, 40 after "
                            "a settle)")
    else:
        p.add_argument("--revolutions", type=int, default=revolutions,
                       help=f"analysed window per speed, whole revolutions (even; default "
                            f"{revolutions})")
    p.add_argument("--steps-per-rev", type=int, default=steps,
                   help=f"communication steps (output samples) per revolution (default {steps})")
    if load:
        add_load_torque(p)


def add_settled_start(p):
    """How constant-speed points start (``emc sweep``, the paper's studies)."""
    p.add_argument("--start", choices=("periodic", "settle"), default="periodic",
                   help="periodic (default): each point starts on its periodic steady state and "
                        "simulates only the window; settle: fade the excitation in and wait "
                        "--settle revolutions")
    p.add_argument("--settle", type=int, default=None,
                   help="revolutions before the window with --start settle (default 20)")


def add_runup(p):
    """The run-up's options (``emc runup``, ``emc tpa-runup``): duration, sampling, blocks,
    start and load."""
    p.add_argument("--duration", type=number, default=20.0, help="s, FROM to TO (default 20)")
    p.add_argument("--step", type=number, default=2e-4,
                   help="communication step, s: the outputs' sampling (default 2e-4)")
    p.add_argument("--block-revolutions", type=int, default=4,
                   help="revolutions per order-tracking block (even; default 4)")
    p.add_argument("--start", choices=("periodic", "fade-in"), default="periodic",
                   help="periodic (default): start on the periodic steady state at FROM; "
                        "fade-in: from the static equilibrium, the excitation faded in")
    p.add_argument("--load-torque", type=number, default=0.0, help="N·m, constant")


def add_band(p):
    """``--band`` and its bounds: the run at two damping bounds beside the nominal."""
    body, mounts = BAND_BODY_SCALE, BAND_MOUNT_SCALE
    p.add_argument("--band", action="store_true",
                   help="run at two damping bounds beside the nominal and draw the band: "
                        f"body modal damping x{body[0]:g}..x{body[1]:g} (5 %% nominal: 3-7 %%) "
                        f"with mount damping x{mounts[0]:.3g}..x{mounts[1]:.3g} (loss factor "
                        "0.15: 0.20-0.10)")
    p.add_argument("--band-body", nargs=2, type=number, metavar=("LOW", "HIGH"),
                   help="the band's chassis.modalDampingScale at the low and the high bound "
                        "(the low bound the less damped; implies --band)")
    p.add_argument("--band-mounts", nargs=2, type=number, metavar=("LOW", "HIGH"),
                   help="the band's mount[i].dampingScale at the low and the high bound, every "
                        "mount (implies --band; 1 1 leaves the mounts nominal)")
    add_band_from(p)


def add_band_from(p):
    """The band's bounds from a calibration (``emc calibrate`` writes them as band.json)."""
    p.add_argument("--band-from", metavar="BAND_JSON",
                   help="the band's bounds from a calibration (the band.json emc calibrate "
                        "writes: the calibrated damping's 95 %% intervals; implies --band)")


def add_pool(p):
    """Where the points run: worker processes of this machine, a running Dask cluster, or this
    process."""
    p.add_argument("--workers", type=int, default=None,
                   help=f"worker processes on this machine (default {DEFAULT_WORKERS}; fewer than "
                        f"{POOL_FROM} runs go in this process, where a pool's start would cost "
                        "more than it saves)")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (the FMU is sent to "
                                       "the workers by content)")
    p.add_argument("--serial", action="store_true", help="every point in this process")


def add_quiet(p, help: str = "no progress bars"):
    p.add_argument("--quiet", action="store_true", help=help)


def add_out(p, what: str = "tables, plots, metadata.json", resumable: bool = False,
            parquet: bool = False):
    """The result folder and ``--overwrite``, under the output-folder policy
    (:func:`emc.base.outputs.claim`); ``resumable``: a study continues in its own folder."""
    p.add_argument("--out", required=True, help=f"result folder ({what})")
    p.add_argument("--overwrite", action="store_true",
                   help="replace the results of another command or other settings in --out")
    if parquet:
        p.add_argument("--parquet", action="store_true", help="write Parquet instead of CSV")
    p.set_defaults(out_policy="resume" if resumable else "replace")
