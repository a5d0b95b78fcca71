"""``emc tpa``, ``tpa-runup``, ``tpa-coupled``, ``frf``, ``ods``, ``decoupling``: why the body
vibrates (the work: :mod:`emc.diagnosis.why`)."""

from ..base import options


def _common(p):
    options.add_fmu(p)
    options.add_settings(p, "FMU start value (repeatable; checked against the model description; "
                            "default scene=2)")
    options.add_quiet(p)
    options.add_out(p)


def _paths(p, at_help: str, case_help: str):
    """The options of both path analyses (``tpa``, ``tpa-runup``)."""
    options.add_speed_range(p)
    p.add_argument("--at", type=options.number, default=None, help=at_help)
    options.add_order(p)
    options.add_responses(p)
    options.add_cases(p, case_help)


def _runs(function: str):
    return options.runs(f"emc.diagnosis.why:{function}")


def register(sub):
    t = sub.add_parser("tpa", help="transfer path analysis per order: each mount and "
                                   "direction's contribution to a body point over speed")
    _common(t)
    _paths(t, at_help="speed of the ranked contributions, rpm, within the range (added to the "
                      "points; default FROM)",
           case_help="a case with its own settings on top of --set (repeatable): each case is "
                     "analysed and the first case's dominant path compared across them")
    options.add_count(t, 18)
    options.add_window(t, 8)
    options.add_band(t)
    t.set_defaults(func=_runs("cmd_tpa"))

    u = sub.add_parser("tpa-runup", help="transfer paths of a run-up: each mount and "
                                         "direction's contribution per order, order-tracked")
    _common(u)
    _paths(u, at_help="speed of the ranked contributions, rpm: the block nearest it (default "
                      "FROM)",
           case_help="a case with its own settings on top of --set (repeatable)")
    options.add_runup(u)
    options.add_band(u)
    u.set_defaults(func=_runs("cmd_tpa_runup"))

    c = sub.add_parser("tpa-coupled", help="transfer paths of the engine FMU (scene 3) on the "
                                           "body FMU, coupled by emc.running.coupling, at one "
                                           "speed")
    _common(c)
    options.add_fmu(c, "dist/EngineMountBody.fmu", "--body-fmu",
                    "the body FMU; --set goes to the engine")
    options.add_speed_point(c)
    c.add_argument("--start", choices=("periodic", "static"), default="periodic",
                   help="periodic (default): the engine on its periodic orbit on the body at "
                        "rest; static: both at the static equilibrium, excitation faded in")
    c.add_argument("--settle", type=options.number, default=1.0,
                   help="s coupled before the analysed window (default 1)")
    c.add_argument("--revolutions", type=int, default=8,
                   help="analysed window, whole revolutions (even; default 8)")
    c.add_argument("--coupling-step", type=options.number, default=1e-4,
                   help="s (default 1e-4: the outputs are read every step)")
    c.add_argument("--algorithm", default="interface_jacobian",
                   help="jacobi, gauss_seidel or interface_jacobian (default)")
    options.add_order(c)
    options.add_responses(c, "acceleration to explain (repeatable; default steeringWheel.a[3])")
    c.set_defaults(func=_runs("cmd_tpa_coupled"))

    f = sub.add_parser("frf", help="transfer functions: the body's accelerance from each mount "
                                   "point, and the coupled system's from the load torque")
    _common(f)
    f.add_argument("--freq", nargs=2, type=options.number, default=[2.0, 200.0],
                   metavar=("FROM", "TO"), help="frequency range, Hz (default 2 200)")
    f.add_argument("--points", type=int, default=600, help="frequencies, log-spaced (default 600)")
    options.add_responses(f, "acceleration output (repeatable; default steeringWheel.a[3])")
    f.add_argument("--top", type=int, default=6, help="body paths drawn (largest peaks; default 6)")
    f.add_argument("--verify", type=options.number, nargs="+", metavar="HZ",
                   help="check the coupled transfer function at these frequencies against a "
                        "sine on the FMU's load torque in the time domain")
    f.add_argument("--verify-amplitude", type=options.number, default=20.0,
                   help="sine amplitude of --verify, N m (default 20)")
    f.add_argument("--verify-rtol", type=options.number, default=1e-6,
                   help="solver.relTol of the --verify runs (default 1e-6)")
    f.add_argument("--mark-rpm", type=options.number,
                   help="mark the --mark-order frequencies at this speed")
    f.add_argument("--mark-order", type=options.number, action="append",
                   help="order to mark (repeatable)")
    options.add_band(f)
    f.set_defaults(func=_runs("cmd_frf"))

    o = sub.add_parser("ods", help="operating deflection shape of one order at one speed: the "
                                   "whole body as VTU (ParaView) and a picture")
    _common(o)
    options.add_speed_point(o)
    options.add_order(o, help="engine order")
    o.add_argument("--compare", action="append", default=[],
                   help="an acceleration output whose point's shape is compared with the "
                        "simulation (repeatable, e.g. steeringWheel.a[3])")
    options.add_window(o, 8)
    options.add_band(o)
    o.set_defaults(func=_runs("cmd_ods"))

    d = sub.add_parser("decoupling", help="the mount decoupling table: rigid modes of the "
                                          "powertrain on ground and in the body, kinetic energy "
                                          "per direction, torque-roll axis")
    _common(d)
    d.set_defaults(func=_runs("cmd_decoupling"))
