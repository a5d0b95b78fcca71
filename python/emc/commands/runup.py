"""``emc runup``: a slow linear run-up, order-tracked in the crank-angle domain."""

from ..base import options


def register(sub):
    r = sub.add_parser("runup", help="slow linear run-up with continuous speed input, "
                                     "order-tracked in the crank-angle domain")
    options.add_fmu(r)
    options.add_speed_range(r)
    options.add_signals(r, "output to analyse (repeatable; default mount[1].F[3])")
    options.add_settings(r)
    options.add_cases(r)
    options.add_runup(r)
    options.add_plots(r, "every --signal")
    options.add_band(r)
    options.add_quiet(r)
    options.add_out(r, parquet=True)
    r.set_defaults(func=options.runs("emc.running.runup:cmd_runup"))
