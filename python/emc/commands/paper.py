"""``emc study-mounts`` and ``emc study-engines``: the paper's comparisons."""

from ..base import options

STUDIES = (
    ("study-mounts", "paper §7.1: 4 mounts vs 3 mounts + stiffening bar (scene 2; --each: every "
                     "change alone and all three)", "cmd_study_mounts"),
    ("study-engines", "inline-3 (M13) vs the inline-4 it replaced, with and without Lanchester "
                      "shafts (scene 2)", "cmd_study_engines"),
)


def register(sub):
    for name, help_text, function in STUDIES:
        m = sub.add_parser(name, help=help_text)
        options.add_fmu(m)
        options.add_speed_range(m)
        options.add_signals(m, "output to analyse (repeatable; default the steering wheel, the "
                               "seat and mount[1].F[3])")
        options.add_settings(m)
        options.add_count(m, 18, "speed points per case")
        options.add_window(m, revolutions=None, load=False)
        options.add_settled_start(m)
        options.add_pool(m)
        options.add_quiet(m)
        options.add_out(m, parquet=True)
        if name == "study-mounts":
            m.add_argument("--each", action="store_true",
                           help="the original, each improvement alone (mount removed, bar, "
                                "stiffer front plate) and all three")
        m.set_defaults(func=options.runs(f"emc.studies.paper_cases:{function}"))
