"""``emc correlate`` and ``emc calibrate``: does the model match the car that was measured
(the work: :mod:`emc.testbench`)."""

from ..base import options


def _measurement(p):
    """What both commands read and how they simulate it."""
    options.add_fmu(p)
    p.add_argument("--mapping", required=True,
                   help="the mapping file (TOML): which measured channel is which FMU output, "
                        "its unit, amplitude convention and order; it names the measurement")
    options.add_settings(p, "FMU start value of every run (repeatable; default scene=2), e.g. "
                            "configFile=/path/my_car.json")
    p.add_argument("--speeds", type=int, default=None,
                   help="simulate this many speeds evenly over the measured range, the "
                        "measurement interpolated onto them (default: the measured speeds)")
    p.add_argument("--revolutions", type=int, default=4,
                   help="analysed window per speed, periodic start (even; default 4)")
    options.add_pool(p)
    options.add_quiet(p, "no progress")


def register(sub):
    c = sub.add_parser("correlate", help="measured order cuts, FRFs and modes against the "
                                         "model: overlays with the band, level and peak "
                                         "differences, FRAC, MAC")
    _measurement(c)
    c.add_argument("--no-band", action="store_true",
                   help="no damping band (one run per speed)")
    options.add_band_from(c)
    options.add_out(c, "correlation tables, overlays, metadata.json")
    c.set_defaults(func=options.runs("emc.testbench.correlate:cmd_correlate"))

    k = sub.add_parser("calibrate", help="fit mount stiffness and damping and the body's "
                                         "damping to measured order cuts; intervals, "
                                         "correlations, a calibrated configuration")
    _measurement(k)
    k.add_argument("--param", action="append", metavar="NAME[=LOW:HIGH]",
                   help="a parameter to fit (repeatable): mount[i].stiffnessScale, "
                        "mount[i].rate[j], mount[i].dampingScale, mount[*].dampingScale, "
                        "chassis.modalDampingScale, body.damping.table[k] (the k-th ordinate of "
                        "the body's damping table); factors on the nominal, default bounds "
                        "0.5:2 (stiffness) and 0.25:4 (damping); default: every mount's "
                        "stiffnessScale, mount[*].dampingScale, chassis.modalDampingScale")
    k.add_argument("--uncertainty", type=options.number, default=0.05,
                   help="relative uncertainty of a measured level (default 0.05)")
    k.add_argument("--no-phase", action="store_true",
                   help="fit levels only, also where the data has phase")
    k.add_argument("--max-evaluations", type=int, default=40,
                   help="most residual evaluations of the solver (default 40; each Jacobian "
                        "costs one parameter set per parameter besides)")
    options.add_out(k, "the evaluations (kept: a calibration started again continues), "
                       "parameters, intervals, the calibrated configuration, plots, "
                       "metadata.json", resumable=True)
    k.set_defaults(func=options.runs("emc.testbench.calibrate:cmd_calibrate"))
