"""``emc sweep``: constant-speed points on their periodic steady state."""

from ..base import options


def register(sub):
    s = sub.add_parser("sweep", help="constant-speed points on their periodic steady state")
    options.add_fmu(s)
    options.add_speed_range(s)
    options.add_signals(s, "output to analyse (repeatable; default every mount force and "
                           "comfort-point acceleration)")
    options.add_settings(s)
    options.add_cases(s)
    options.add_count(s, 18, "speed points, FROM to TO")
    options.add_window(s, revolutions=None)
    options.add_settled_start(s)
    options.add_plots(s, "the first")
    options.add_band(s)
    options.add_pool(s)
    options.add_quiet(s)
    options.add_out(s, parquet=True)
    s.set_defaults(func=options.runs("emc.running.sweep_cases:cmd_sweep"))
