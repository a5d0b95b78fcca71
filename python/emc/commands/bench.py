"""``emc bench-effects`` and ``emc bench-realtime``: what the FMU costs."""

from ..base import options


def register(sub):
    b = sub.add_parser("bench-effects",
                       help="CPU time per simulated second for each scene and effect set")
    options.add_fmu(b)
    b.add_argument("--scene", type=int, action="append",
                   help="scene(s) to measure (repeatable; default 2)")
    options.add_speed_point(b, 2000.0)
    b.add_argument("--seconds", type=options.number, default=1.0,
                   help="simulated time per case (default 1)")
    b.add_argument("--signal-name", default="mount[1].F[3]", help="signal whose RMS is reported")
    b.add_argument("--table", help="also write the table here (CSV, or Parquet for .parquet)")
    b.set_defaults(func=options.runs("emc.bench:cmd_bench_effects"))

    r = sub.add_parser("bench-realtime", help="the FMU's speed through fmpy's low-level doStep "
                                              "+ getReal loop (1 ms step, every output read "
                                              "every step)")
    options.add_fmu(r)
    options.add_speed_point(r, 2000.0)
    r.add_argument("--seconds", type=options.number, default=1.0,
                   help="simulated time per window (default 1)")
    r.add_argument("--repeats", type=int, default=3,
                   help="windows per case (the range is reported; default 3)")
    r.set_defaults(func=options.runs("emc.bench:cmd_bench_realtime"))
