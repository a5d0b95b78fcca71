"""Test data against the model: measured order cuts, FRFs and modes read and checked
(:mod:`.measurement`), mapped channel by channel to FMU outputs (:mod:`.mapping`), compared with
the simulation (:mod:`.metrics`, ``emc correlate`` in :mod:`.correlate`) and the uncertain
parameters fitted to them (``emc calibrate`` in :mod:`.calibrate`).
"""
