"""What the result tables of the sweep, run-up, Campbell and accuracy commands hold, column by
column: the guide's reference page "Result files" is generated from this list
(docs/reference.py), and python/tests/test_result_files.py runs each command on a small case and
checks that the files it writes have exactly these columns.

A column written ``PREFIX <signal>`` or ``<signal>`` stands for one column per signal (or
signal group) of the run.
"""

from __future__ import annotations

import dataclasses


@dataclasses.dataclass(frozen=True)
class ResultFile:
    name: str
    commands: tuple[str, ...]
    what: str
    columns: tuple[tuple[str, str], ...]


CASE = ("case", "the case's name (`--case NAME`; empty without cases)")
RPM = ("rpm", "engine speed of the point, rpm")
BOUND = ("bound", "with `--band` only: `low`, `nominal` or `high` damping")
SIGNAL = ("signal", "the FMU output, e.g. `steeringWheel.a[3]`")
ORDER = ("order", "engine order (0.5 … 6 in steps of 0.5)")

SEAT = (
    ("seat_awx", "seat, x: frequency-weighted RMS acceleration, Wd (ISO 2631-1), m/s²"),
    ("seat_awy", "seat, y: the same, Wd, m/s²"),
    ("seat_awz", "seat, z: the same, Wk, m/s²"),
    ("seat_av_comfort", "seat: vibration total value with the comfort factors 1/1/1, m/s²"),
    ("seat_av_health", "seat: vibration total value with the health factors 1.4/1.4/1, m/s²"),
)
WHEEL = (
    ("wheel_ahwx", "steering wheel, x: frequency-weighted RMS acceleration, Wh (ISO 5349-1), m/s²"),
    ("wheel_ahwy", "steering wheel, y: the same, m/s²"),
    ("wheel_ahwz", "steering wheel, z: the same, m/s²"),
    ("wheel_ahv", "steering wheel: vibration total value a_hv, m/s²"),
)

FILES = (
    ResultFile("orders.csv", ("sweep", "study-mounts", "study-engines"),
               "the order amplitudes of every point (`.parquet` with `--parquet`).",
               (CASE, RPM, SIGNAL, ORDER,
                ("frequency", "the order's frequency at this speed, Hz"),
                ("amplitude", "peak amplitude (2|X|/N over whole revolutions) in the signal's "
                              "unit"),
                BOUND)),
    ResultFile("spectra.csv", ("sweep", "study-mounts", "study-engines"),
               "the spectrum of every point's window up to 6.5 orders: one row per spectral "
               "line (`.parquet` with `--parquet`).",
               (CASE, RPM, SIGNAL,
                ("frequency", "frequency of the spectral line, Hz"),
                ("amplitude", "peak amplitude of the line in the signal's unit"),
                BOUND)),
    ResultFile("comfort.csv", ("sweep", "study-mounts", "study-engines"),
               "with `seat.a[1..3]` and `steeringWheel.a[1..3]` recorded: the comfort values "
               "of every speed, from the window's spectrum up to 6.5 orders.",
               (CASE, RPM) + SEAT + WHEEL + (BOUND,)),
    ResultFile("order_band.csv", ("sweep",),
               "with `--band`: the main orders (1, 1.5, 2, 3, 4.5) at the three damping bounds "
               "side by side.",
               (CASE, SIGNAL, ORDER, RPM,
                ("amplitude_low", "peak amplitude at the low damping bound"),
                ("amplitude_nominal", "the same at the nominal damping"),
                ("amplitude_high", "the same at the high damping bound"))),
    ResultFile("comfort_band.csv", ("sweep",),
               "with `--band` and the comfort signals: every column of `comfort.csv` at the "
               "three bounds side by side.",
               (CASE, RPM, ("<value>_low, <value>_nominal, <value>_high",
                            "each comfort value of `comfort.csv` (`seat_awx` … `wheel_ahv`) at "
                            "the low bound, the nominal and the high bound"))),
    ResultFile("runup.csv", ("runup",),
               "the run-up's samples at every communication step (`.parquet` with "
               "`--parquet`).",
               (CASE, ("time", "simulated time, s"), ("rpm", "the speed set-point, rpm"),
                ("crankAngle", "the FMU's crank angle, rad"),
                ("<signal>", "one column per `--signal`, in its unit"), BOUND)),
    ResultFile("runup_orders.csv", ("runup",),
               "the order-tracked amplitudes: one row per block of `--block-revolutions`, "
               "labelled with its mean speed; the columns of `orders.csv`.",
               (CASE, ("rpm", "the block's mean speed, rpm"), SIGNAL, ORDER,
                ("frequency", "the order's frequency at the block's mean speed, Hz"),
                ("amplitude", "peak amplitude in the signal's unit"), BOUND)),
    ResultFile("runup_order_band.csv", ("runup",),
               "with `--band`: the main orders of the run-up at the three bounds side by side; "
               "the columns of `order_band.csv`.",
               (CASE, SIGNAL, ORDER, ("rpm", "the block's mean speed, rpm"),
                ("amplitude_low", "peak amplitude at the low damping bound"),
                ("amplitude_nominal", "the same at the nominal damping"),
                ("amplitude_high", "the same at the high damping bound"))),
    ResultFile("natural_modes.csv", ("campbell",),
               "the natural modes the FMU reports after initialisation (linearised at the "
               "static equilibrium).",
               (CASE, ("mode", "mode number, 1 the lowest"),
                ("frequency", "natural frequency, Hz"),
                ("damping", "damping ratio, fraction of critical"),
                ("powertrain_share", "the powertrain's share of the mode's kinetic energy, 0 … 1"))),
    ResultFile("crossings.csv", ("campbell",),
               "the speeds where a main order crosses a marked mode (every powertrain mode, "
               "the body modes damped up to 7.5 %).",
               (CASE, ORDER, ("mode", "mode number of `natural_modes.csv`"),
                ("frequency", "the mode's natural frequency, Hz"),
                ("rpm", "the speed at which the order's frequency equals it, rpm"),
                ("powertrain_share", "the mode's powertrain share"))),
    ResultFile("accuracy.csv", ("accuracy",),
               "one row per case, scenario and tolerance.",
               (CASE, ("scenario", "`RPM rpm` (stationary) or `run-up FROM-TO rpm`"),
                ("rtol", "the relative tolerance passed through `fmi2SetupExperiment`"),
                ("steps", "integrator steps of the run (`solver.steps`)"),
                ("cpu_s_per_s", "CPU time of the stepping per simulated second, s"),
                ("x_realtime", "simulated time over the stepping's wall time"),
                ("l2 <group>, orders <group>",
                 "per signal group (the name up to its first `[`), in turn: the relative L2 "
                 "error of the group's signals against the reference run, and (stationary "
                 "only, else empty) the largest relative error of its compared order "
                 "amplitudes"),
                ("reference_steps", "integrator steps of the reference run"))),
)
