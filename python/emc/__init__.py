"""Speed sweeps, run-ups, waterfalls, transfer paths and studies with the EngineMountChassis FMU.

The package is a house of rooms; a room imports only from the floors below it (checked by
``python/tests/test_house.py``):

0. :mod:`emc.base`: errors, engine orders, what the FMU's model description says, settings and
   option checks, every shared option, result folders and ``metadata.json``.
1. :mod:`emc.signals`: spectra, order tracking and comfort values of sampled signals.
2. :mod:`emc.figures`: waterfalls, order cuts, bands and the other plots.
3. :mod:`emc.running`: the FMU driven through fmpy (:mod:`emc.running.runner`), many runs on
   Dask (:mod:`emc.running.distributed`), sweeps, run-ups, the damping band, the modal export,
   the engine and body FMUs coupled, the SSP archive.
4. :mod:`emc.diagnosis` (why it vibrates: paths, transfer functions, shapes, mounts, Campbell),
   :mod:`emc.studies` (the paper's cases, DOE, optimisation, accuracy) and :mod:`emc.bench`
   (benchmarks, ``emc bench-…``).
5. :mod:`emc.commands`: one module per command, each registering its options.
6. :mod:`emc.cli`: the ``emc`` command.
"""
