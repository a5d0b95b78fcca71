"""``emc bench-effects`` and ``emc bench-realtime``: what the FMU costs."""

from ..base import options


def register(sub):
    b = sub.add_parser("bench-effects",
                       help="CPU time per simulated second for each scene and effect set")
    options.add_fmu(b)
    b.add_argument("--scene", type=int, action="append",
                   help="scene(s) to measure (repeatable; default 2)")
    options.add_speed_point(b, 2000.0)
    _seconds(b, "case")
    b.add_argument("--signal-name", default="mount[1].F[3]", help="signal whose RMS is reported")
    b.add_argument("--table", help="also write the table here (CSV, or Parquet for .parquet)")
    b.set_defaults(func=options.runs("emc.bench:cmd_bench_effects"))

    r = sub.add_parser("bench-realtime", help="the FMU's speed through fmpy's low-level doStep "
                                              "+ getReal loop (1 ms step, every output read "
                                              "every step)")
    options.add_fmu(r)
    options.add_speed_point(r, 2000.0)
    _seconds(r, "window")
    r.add_argument("--repeats", type=int, default=3,
                   help="windows per case (the range is reported; default 3)")
    r.set_defaults(func=options.runs("emc.bench:cmd_bench_realtime"))

    s = sub.add_parser("bench-scaling", help="a sweep serial and on pools of several worker "
                                             "counts (warm instances), with speed-ups and a "
                                             "bit-for-bit check")
    options.add_fmu(s)
    _points(s, 48)
    options.add_speed_range(s, (800.0, 4000.0))
    _worker_counts(s, [2])
    s.add_argument("--threads", type=int, nargs="+", default=[1],
                   help="threads per worker (default 1); a worker with several runs that many "
                        "evaluations at once, each on an instance of its own")
    _timed_runs(s, ["guided"], "how a pool batches the points: shrinking batches (guided, the "
                               "default) and/or four equal batches per worker (equal); both to "
                               "compare them in one run")
    s.set_defaults(func=options.runs("emc.bench:cmd_scaling"))

    d = sub.add_parser("bench-scheduling", help="what distribution alone costs at many workers, "
                                                "on few cores: each point replaced by a wait of "
                                                "its measured time")
    options.add_fmu(d)
    _points(d, 192)
    options.add_speed_range(d, (800.0, 4000.0))
    _worker_counts(d, [16])
    d.add_argument("--scale", type=options.number, default=1.0,
                   help="each wait is this times the point's measured time (to stand in for a "
                        "slower machine; default 1)")
    _timed_runs(d, ["guided", "equal"], "batchings to compare (default both)")
    d.set_defaults(func=options.runs("emc.bench:cmd_scheduling"))

    c = sub.add_parser("bench-calibration", help="emc calibrate of 6 parameters and emc "
                                                 "correlate against a twin measurement of 4 "
                                                 "channels x 4 orders x 35 speeds, timed")
    options.add_fmu(c)
    c.add_argument("--workers", type=int, default=2,
                   help="worker processes on this machine (default 2)")
    c.add_argument("--speeds", type=int, default=35, help="measured speeds (default 35)")
    c.add_argument("--revolutions", type=int, default=4,
                   help="analysed window per speed (even; default 4)")
    c.add_argument("--keep", metavar="DIR", help="keep the files here (default: a temporary "
                                                 "folder)")
    c.set_defaults(func=options.runs("emc.testbench.bench:cmd_bench_calibration"))

    u = sub.add_parser("bench-startup", help="what the command line costs before and around "
                                             "its work: emc --help, an argument error, a 2-point "
                                             "sweep, 48 points serial and on 2 workers")
    options.add_fmu(u)
    _repeat(u, 3, "runs per row")
    _csv(u)
    u.set_defaults(func=options.runs("emc.bench:cmd_startup"))


def _seconds(p, per: str):
    p.add_argument("--seconds", type=options.number, default=1.0,
                   help=f"simulated time per {per} (default 1)")


def _repeat(p, default: int, help: str):
    p.add_argument("--repeat", type=int, default=default, help=f"{help} (default {default})")


def _csv(p):
    p.add_argument("--csv", help="also write the table here")


def _points(p, default: int):
    p.add_argument("--points", type=int, default=default,
                   help=f"speed points, 800-4000 rpm (default {default})")


def _worker_counts(p, default: list[int]):
    p.add_argument("--workers", type=int, nargs="+", default=default,
                   help=f"worker counts (default {' '.join(map(str, default))})")


def _timed_runs(p, batchings: list[str], help: str):
    _repeat(p, 2, "timed runs per row")
    p.add_argument("--pool", nargs="+", choices=("local", "dask"), default=["local", "dask"],
                   help="pools to compare: the process pool of --workers (local; its workers "
                        "have one thread each) and/or a local Dask cluster (dask); default both")
    p.add_argument("--batching", nargs="+", choices=("guided", "equal"), default=batchings,
                   help=help)
    _csv(p)
