"""The ``emc`` command: speed sweeps and run-ups with the packaged FMU, tables and plots.

Examples:
    emc sweep --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --count 18 --out out/sweep
    emc sweep ... --set effects.balanceShaft=false --case no-balance-shaft
    emc sweep ... --scheduler tcp://10.0.0.5:8786        # a running Dask cluster
    emc runup --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --duration 10 --out out/runup
"""

from __future__ import annotations

import argparse
import pathlib
import re
import sys
import time

import numpy as np
import pandas as pd

from . import plots
from .comfort import comfort_table
from .runner import OperatingPoint, Runner
from .spectra import amplitude_spectrum
from .sweep import run_sweep, save, speed_points


def parse_value(text: str):
    lowered = text.lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


def parse_settings(items: list[str]) -> tuple:
    out = []
    for item in items or []:
        if "=" not in item:
            raise SystemExit(f"--set expects name=value, got {item!r}")
        name, value = item.split("=", 1)
        out.append((name.strip(), parse_value(value.strip())))
    return tuple(out)


def start_options(args) -> dict:
    """How each speed point starts: on the periodic steady state, or settled after a fade-in."""
    # A periodic response is resolved exactly by whole working cycles: 8 revolutions (4 cycles)
    # put every half order on a bin without leakage. After a settle the longer window averages
    # what is left of the transients.
    if args.start == "periodic":
        if args.settle is not None:
            raise SystemExit("--settle applies to --start settle only (a periodic start has no "
                             "transient to wait for)")
        options = {"periodic": True, "settle_revolutions": 0, "revolutions": 8}
    else:
        settle = 20 if args.settle is None else args.settle
        if settle < 0:
            raise SystemExit(f"--settle must be >= 0, got {settle}")
        options = {"periodic": False, "settle_revolutions": settle, "revolutions": 40}
    if args.revolutions is not None:
        if args.revolutions < 2 or args.revolutions % 2:
            raise SystemExit(f"--revolutions must be even and >= 2, got {args.revolutions}")
        options["revolutions"] = args.revolutions
    return options


def add_start_options(p):
    p.add_argument("--start", choices=("periodic", "settle"), default="periodic",
                   help="periodic (default): each point starts on its periodic steady state and "
                        "simulates only the window; settle: fade the excitation in and wait "
                        "--settle revolutions")
    p.add_argument("--settle", type=int, default=None,
                   help="revolutions before the window with --start settle (default 20)")


def safe_name(signal: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", re.sub(r"\[(\d+)\]", r"\1", signal)).strip("_")


def cmd_sweep(args) -> int:
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    points = speed_points(args.rpm[0], args.rpm[1], args.count, steps_per_revolution=args.steps_per_rev, load_torque=args.load_torque,
                          parameters=parse_settings(args.set), **start_options(args))
    started = time.perf_counter()
    orders, spectra = run_sweep(args.fmu, points, signals=args.signal or None, case=args.case,
                                parallel=not args.serial, scheduler=args.scheduler,
                                workers=args.workers, progress=not args.quiet)
    elapsed = time.perf_counter() - started
    suffix = ".parquet" if args.parquet else ".csv"
    save(orders, str(out / f"orders{suffix}"))
    save(spectra, str(out / f"spectra{suffix}"))
    for signal in args.plot or sorted(orders.signal.unique())[:1]:
        plots.waterfall(spectra, signal, str(out / f"waterfall_{safe_name(signal)}.png"))
        plots.order_cuts(orders, signal, str(out / f"order_cuts_{safe_name(signal)}.png"))
    exposure = comfort_table(spectra)
    if not exposure.empty:
        save(exposure, str(out / f"comfort{suffix}"))
        plots.comfort(exposure, str(out / "comfort.png"))
    print(f"{len(points)} points in {elapsed:.1f} s -> {out}")
    return 0


def cmd_runup(args) -> int:
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with Runner(args.fmu) as runner:
        signals = args.signal or ["mount[1].F[3]"]
        result = runner.run_up(args.rpm[0], args.rpm[1], args.duration, signals, step=args.step,
                               start_values=dict(parse_settings(args.set)))
    table = pd.DataFrame(result["samples"], columns=signals)
    table.insert(0, "rpm", result["rpm"])
    table.insert(0, "time", np.arange(1, len(table) + 1) * result["dt"])
    save(table, str(out / ("runup.parquet" if args.parquet else "runup.csv")))
    # Run-up waterfall from consecutive windows of ~0.25 s (quasi-stationary at slow rates).
    n = max(16, int(round(args.window / result["dt"])))
    rows = []
    for signal in signals:
        x = table[signal].to_numpy()
        for start in range(0, len(x) - n + 1, n):
            f, a = amplitude_spectrum(x[start:start + n], result["dt"])
            rpm = float(np.mean(result["rpm"][start:start + n]))
            keep = f <= 6.5 * rpm / 60
            rows += [{"case": "runup", "rpm": rpm, "signal": signal, "frequency": fi, "amplitude": ai}
                     for fi, ai in zip(f[keep], a[keep])]
    spectra = pd.DataFrame(rows)
    for signal in signals:
        plots.waterfall(spectra, signal, str(out / f"runup_waterfall_{safe_name(signal)}.png"),
                        title=f"{signal}: run-up {args.rpm[0]:g}→{args.rpm[1]:g} rpm in {args.duration:g} s")
    print(f"run-up -> {out}")
    return 0


STUDY_CASES = {
    "4 mounts": {"scene": 2},
    "3 mounts + stiffening bar": {"scene": 2, "configFile": "vehicle_three_mounts.json",
                                  "chassis.stiffeningBar": True},
}

# The M13 inline-3 against the inline-4 it replaced (paper §1), in the same body on the same mounts.
ENGINE_CASES = {
    "inline-3 (M13)": {"scene": 2},
    "inline-4": {"scene": 2, "configFile": "vehicle_i4.json"},
    "inline-4 + Lanchester shafts": {"scene": 2, "configFile": "vehicle_i4_lanchester.json"},
}


def cmd_study_mounts(args) -> int:
    """Paper §7.1: the original vehicle against the improved one, from one command."""
    return run_study(args, STUDY_CASES)


def cmd_study_engines(args) -> int:
    """The inline-3 against the inline-4 (with and without Lanchester shafts), side by side."""
    return run_study(args, ENGINE_CASES)


def run_study(args, cases: dict) -> int:
    """Sweeps each case and writes side-by-side waterfalls and order cuts on common scales."""
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tables = []
    started = time.perf_counter()
    for case, params in cases.items():
        points = speed_points(args.rpm[0], args.rpm[1], args.count, parameters=tuple(params.items()) + parse_settings(args.set),
                              **start_options(args))
        tables.append(run_sweep(args.fmu, points, signals=args.signal or STUDY_SIGNALS, case=case,
                                parallel=not args.serial, scheduler=args.scheduler,
                                workers=args.workers, progress=not args.quiet))
    orders = pd.concat([t[0] for t in tables], ignore_index=True)
    spectra = pd.concat([t[1] for t in tables], ignore_index=True)
    suffix = ".parquet" if args.parquet else ".csv"
    save(orders, str(out / f"orders{suffix}"))
    save(spectra, str(out / f"spectra{suffix}"))
    for signal in args.signal or STUDY_SIGNALS:
        name = safe_name(signal)
        plots.side_by_side(spectra, orders, signal, list(cases),
                           str(out / f"study_waterfall_{name}.png"), str(out / f"study_order_cuts_{name}.png"))
    summary = (orders[orders.order.isin([1.0, 1.5, 2.0, 4.0])]
               .groupby(["signal", "case", "order"]).amplitude.max().unstack("order"))
    print(summary.to_string(float_format=lambda v: f"{v:.4g}"))
    print(f"study in {time.perf_counter() - started:.1f} s -> {out}")
    return 0


STUDY_SIGNALS = ["steeringWheel.a[3]", "steeringWheel.a[2]", "mount[1].F[3]"]


def cmd_bench_effects(args) -> int:
    from .bench import effects_table

    table = effects_table(args.fmu, scenes=args.scene, rpm=args.rpm_point, seconds=args.seconds,
                          signal=args.signal_name)
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    if args.out:
        save(table, args.out)
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="emc", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)

    def common(p):
        p.add_argument("--fmu", default="dist/EngineMountChassis.fmu")
        p.add_argument("--rpm", nargs=2, type=float, default=[800.0, 2500.0], metavar=("FROM", "TO"))
        p.add_argument("--signal", action="append", help="output to analyse (repeatable)")
        p.add_argument("--set", action="append", metavar="NAME=VALUE",
                       help="FMU start value, e.g. effects.balanceShaft=false (repeatable)")
        p.add_argument("--out", required=True)
        p.add_argument("--parquet", action="store_true", help="write Parquet instead of CSV")

    s = sub.add_parser("sweep", help="constant-speed points on their periodic steady state")
    common(s)
    s.add_argument("--count", type=int, default=18)
    s.add_argument("--revolutions", type=int, default=None,
                   help="analysed window (even; default 8 with a periodic start, 40 after a settle)")
    add_start_options(s)
    s.add_argument("--steps-per-rev", type=int, default=72)
    s.add_argument("--load-torque", type=float, default=0.0)
    s.add_argument("--case", default="")
    s.add_argument("--plot", action="append", help="signal to plot (default: the first)")
    s.add_argument("--serial", action="store_true", help="no Dask")
    s.add_argument("--workers", type=int, default=2)
    s.add_argument("--scheduler", help="address of a running Dask scheduler")
    s.add_argument("--quiet", action="store_true")
    s.set_defaults(func=cmd_sweep)

    r = sub.add_parser("runup", help="slow linear run-up with continuous speed input")
    common(r)
    r.add_argument("--duration", type=float, default=10.0)
    r.add_argument("--step", type=float, default=2e-4)
    r.add_argument("--window", type=float, default=0.25, help="analysis window (s)")
    r.set_defaults(func=cmd_runup)

    studies = [("study-mounts", "paper §7.1: 4 mounts vs 3 mounts + stiffening bar (scene 2)", cmd_study_mounts),
               ("study-engines", "inline-3 (M13) vs the inline-4 it replaced, with and without Lanchester "
                                 "shafts (scene 2)", cmd_study_engines)]
    for name, help_text, func in studies:
        m = sub.add_parser(name, help=help_text)
        common(m)
        m.add_argument("--count", type=int, default=18)
        m.add_argument("--revolutions", type=int, default=None,
                       help="analysed window (even; default 8 with a periodic start, 40 after a settle)")
        add_start_options(m)
        m.add_argument("--serial", action="store_true", help="no Dask")
        m.add_argument("--workers", type=int, default=2)
        m.add_argument("--scheduler", help="address of a running Dask scheduler")
        m.add_argument("--quiet", action="store_true")
        m.set_defaults(func=func)

    b = sub.add_parser("bench-effects", help="CPU time per simulated second for each scene and effect set")
    b.add_argument("--fmu", default="dist/EngineMountChassis.fmu")
    b.add_argument("--scene", type=int, action="append", help="scene(s) to measure (default 1)")
    b.add_argument("--rpm-point", type=float, default=2000.0)
    b.add_argument("--seconds", type=float, default=1.0, help="simulated time per case")
    b.add_argument("--signal-name", default="mount[1].F[3]", help="signal whose RMS is reported")
    b.add_argument("--out", help="also write the table (CSV or .parquet)")
    b.set_defaults(func=cmd_bench_effects)

    args = parser.parse_args(argv)
    if getattr(args, "scene", None) is None and args.command == "bench-effects":
        args.scene = [1]
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
