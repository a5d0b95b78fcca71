"""``emc accuracy``: what accuracy costs for your configuration."""

from ..base import options
from ..studies.defaults import COMPARED_ORDERS, DEFAULT_TOLERANCES, REFERENCE_TOLERANCE


def register(sub):
    p = sub.add_parser(
        "accuracy",
        help="work-precision table and plot for your configuration: error against a tight "
             "reference and CPU time per simulated second, at a list of tolerances")
    options.add_fmu(p)
    options.add_settings(p, "FMU start value for every case (repeatable; default scene=2); "
                            "solver.relTol is what the command varies")
    options.add_cases(p, "a configuration with its own settings on top of --set (repeatable)")
    p.add_argument("--rtol", type=options.number, nargs="+", default=list(DEFAULT_TOLERANCES),
                   metavar="TOL", help="tolerances to measure, passed through "
                   "fmi2SetupExperiment (default 1e-3 … 1e-9, one per decade)")
    p.add_argument("--reference-rtol", type=options.number, default=REFERENCE_TOLERANCE,
                   help=f"tolerance of the reference run (default {REFERENCE_TOLERANCE:g})")
    p.add_argument("--scenario", action="append", choices=("stationary", "runup"),
                   help="stationary: constant --rpm-point; runup: linear --runup FROM TO over "
                        "--duration (repeatable; default both)")
    options.add_speed_point(p, 2000.0, "speed of the stationary scenario, rpm")
    options.add_load_torque(p)
    p.add_argument("--runup", type=options.number, nargs=2, default=[800.0, 2500.0],
                   metavar=("FROM", "TO"), help="speeds of the run-up, rpm (default 800 2500)")
    p.add_argument("--duration", type=options.number, default=0.5,
                   help="compared window, s: the constant-speed run or the run-up from FROM to "
                        "TO (default 0.5)")
    p.add_argument("--settle", type=options.number, default=0.0,
                   help="simulated time before the window, s, at the stationary speed or the "
                        "run-up's FROM (default 0: the window starts at the start)")
    p.add_argument("--step", type=options.number, default=1e-3,
                   help="communication step, s: where the outputs are compared (default 1e-3)")
    p.add_argument("--start", choices=("static", "periodic"), default="static",
                   help="static (default): the static equilibrium, excitation faded in over "
                        "excitation.fadeInTime; periodic: the periodic steady state")
    options.add_signals(p, "output to compare (repeatable; default the mount forces and the "
                           "steering-wheel acceleration); signals are grouped by the name before "
                           "their first '['")
    p.add_argument("--order", type=options.number, action="append",
                   help="engine order whose amplitude is compared in the stationary scenario "
                        "(repeatable; default " + ", ".join(f"{o:g}" for o in COMPARED_ORDERS)
                        + ")")
    p.add_argument("--repeat", type=int, default=1,
                   help="runs per tolerance, the least CPU time kept (default 1; 3 on a busy "
                        "machine)")
    options.add_quiet(p, "no progress lines")
    options.add_out(p, "accuracy.csv, accuracy.png, metadata.json")
    p.set_defaults(func=options.runs("emc.studies.accuracy:cmd_accuracy"))
