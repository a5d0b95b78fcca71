"""``emc ssp``, ``coupling-table``, ``split-table``, ``check-references``, ``accuracy-plot``:
the engine and body FMUs as an SSP archive and coupled, measured; the FMUs' reference
experiments checked; the work-precision table of ``examples/accuracy_cost.rs`` drawn."""

from ..base import options


def _pair(p):
    options.add_fmu(p, what="the engine FMU")
    options.add_fmu(p, "dist/EngineMountBody.fmu", "--body-fmu", "the body FMU")


def _speeds_and_steps(p, steps: list[float] | None, shown: str):
    p.add_argument("--rpm", type=options.number, nargs="+", default=[1100.0, 2000.0],
                   help="speeds, rpm (default 1100 2000)")
    p.add_argument("--steps", type=options.number, nargs="+", default=steps,
                   help=f"coupling steps, ms (default {shown})")


def _t_end(p, default: float):
    p.add_argument("--t-end", type=options.number, default=default,
                   help=f"simulated time, s (default {default:g})")


def register(sub):
    s = sub.add_parser("ssp", help="write the SSP archive of the engine and the body FMU, "
                                   "connected mount by mount")
    _pair(s)
    s.add_argument("archive", nargs="?", default="dist/EngineInBody.ssp",
                   help="the archive to write (default dist/EngineInBody.ssp)")
    s.add_argument("--step", type=options.number, default=5e-5,
                   help="coupling step, s (default 5e-5: a plain exchange within 0.5 %% of the "
                        "monolithic model at the default damping)")
    s.set_defaults(func=options.runs("emc.running.ssp:cmd_ssp"))

    c = sub.add_parser("coupling-table", help="the engine FMU on the body FMU with emc's "
                                              "coupling algorithms at several steps, against "
                                              "scene 2: stability, accuracy, cost (minutes)")
    _pair(c)
    _speeds_and_steps(c, None, "0.1 … 50")
    c.add_argument("--algorithms", nargs="+",
                   help="jacobi, gauss_seidel, interface_jacobian (default all)")
    _t_end(c, 1.0)
    c.add_argument("--stiffness-scale", type=options.number, default=1.0,
                   help="mount[i].stiffnessScale of the engine in both scenes (default 1)")
    c.set_defaults(func=options.runs("emc.running.coupling:cmd_coupling_table"))

    t = sub.add_parser("split-table", help="scene 2 split at the mounts, the archive in "
                                           "libcosim against the monolithic scene 2")
    _pair(t)
    _speeds_and_steps(t, [0.1, 1.0, 10.0], "0.1 1 10")
    _t_end(t, 1.2)
    t.add_argument("--rel-tol", type=options.number, default=1e-8,
                   help="solver.relTol of both (default 1e-8)")
    t.set_defaults(func=options.runs("emc.running.split:cmd_split_table"))

    r = sub.add_parser("check-references", help="each FMU through the reference experiments it "
                                                "carries (exit 1 if one leaves its band)")
    r.add_argument("fmus", nargs="+", metavar="FMU")
    r.set_defaults(func=options.runs("emc.running.references:cmd_check_references"))

    a = sub.add_parser("accuracy-plot", help="the log-log plot of a work-precision table written "
                                             "by examples/accuracy_cost.rs")
    a.add_argument("table", help="the table (CSV)")
    a.add_argument("png", help="the plot to write")
    a.set_defaults(func=options.runs("emc.figures.accuracy_plot:cmd_accuracy_plot"))
