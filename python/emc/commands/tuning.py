"""``emc doe`` and ``emc optimise``: tuning the mounts for comfort within travel limits."""

import math

from ..base import options
from ..studies.defaults import DEFAULT_BOUNDS, METHODS, OBJECTIVES, Limits


def problem_options(p):
    """What defines a tuning problem and where it runs."""
    options.add_fmu(p)
    bounds = {kind: f"{low:g}:{high:g}" for kind, (low, high) in DEFAULT_BOUNDS.items()}
    p.add_argument("--var", action="append", metavar="NAME[=LOW:HIGH]",
                   help="design variable (repeatable): mount[i].stiffnessScale (default bounds "
                        f"{bounds['stiffnessScale']}), mount[i].dampingScale "
                        f"({bounds['dampingScale']}), mount[i].rate[j] ({bounds['rate']}, "
                        "mount i's curve along its axis j); default: every mount's "
                        "stiffnessScale and dampingScale")
    options.add_speed_range(p, (800.0, 2000.0), "the speed band of the objective")
    options.add_count(p, 12, "speed points in the band")
    p.add_argument("--revolutions", type=int, default=8,
                   help="analysed window per point, periodic start (even; default 8)")
    p.add_argument("--objective", choices=OBJECTIVES, default=OBJECTIVES[0],
                   help="mean or largest weighted steering-wheel a_hv over the band, or the mean "
                        "of a_hv + SEAT_WEIGHT × seat a_v (default wheel-mean)")
    p.add_argument("--seat-weight", type=options.number, default=1.0)
    limits = Limits()
    p.add_argument("--full-load-torque", type=options.number, default=limits.full_load_torque,
                   help="N·m about the crank axis, applied in both senses for the limits "
                        f"(default {limits.full_load_torque:g})")
    p.add_argument("--max-deflection", type=options.number, default=limits.deflection * 1e3,
                   help="mm, any mount along any axis under the weight and the full-load torque "
                        f"(default {limits.deflection * 1e3:g})")
    p.add_argument("--max-translation", type=options.number, default=limits.translation * 1e3,
                   help="mm, the powertrain's centre of gravity "
                        f"(default {limits.translation * 1e3:g})")
    p.add_argument("--max-rotation", type=options.number,
                   default=math.degrees(limits.rotation),
                   help=f"deg, the powertrain (default {math.degrees(limits.rotation):g})")
    options.add_settings(p, "a fixed FMU start value of every run (repeatable), e.g. "
                            "chassis.stiffeningBar=on")
    options.add_pool(p)
    options.add_quiet(p)
    options.add_out(p, "evaluations (kept: a study started again continues), tables, plots, "
                       "metadata.json", resumable=True)


def register(sub):
    d = sub.add_parser("doe", help="design of experiments over mount variables: variance-based "
                                   "sensitivity of comfort and static travel to each")
    problem_options(d)
    d.add_argument("--method", choices=METHODS, default=METHODS[0],
                   help="sobol: Saltelli plan, Sobol' S1 and ST (default); lhs: Latin hypercube, "
                        "RBD-FAST S1")
    d.add_argument("--samples", type=int, default=16,
                   help="N: sobol runs N (n + 2) designs for n variables, lhs N (default 16)")
    d.add_argument("--seed", type=int, default=1, help="seed of the plan (default 1)")
    d.set_defaults(func=options.runs("emc.studies.doe:cmd_doe"))

    o = sub.add_parser("optimise", help="tune mount stiffness and damping scales and rates "
                                        "for comfort over a speed band within travel limits")
    problem_options(o)
    o.add_argument("--evaluations", type=int, default=60,
                   help="largest number of designs the optimiser asks for (default 60)")
    o.add_argument("--start-from", metavar="DOE_FOLDER",
                   help="start from the best feasible design of an emc doe study")
    o.set_defaults(func=options.runs("emc.studies.optimise:cmd_optimise"))
