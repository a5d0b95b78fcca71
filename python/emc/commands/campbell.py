"""``emc campbell``: the engine orders against the model's natural frequencies."""

from ..base import options


def register(sub):
    c = sub.add_parser("campbell", help="Campbell diagram: engine orders against the model's "
                                        "natural frequencies, crossings listed")
    options.add_fmu(c)
    options.add_speed_range(c)
    options.add_settings(c)
    options.add_cases(c)
    options.add_quiet(c)
    options.add_out(c)
    c.set_defaults(func=options.runs("emc.diagnosis.campbell:cmd_campbell"))
