"""Speed sweeps, run-ups, waterfall diagrams and order cuts with the EngineMountChassis FMU.

- :mod:`emc.runner`: one FMU instance (fmpy's FMU2Slave) reused across operating points.
- :mod:`emc.spectra`: order amplitudes and spectra of stationary windows.
- :mod:`emc.sweep`: constant-speed points and run-ups, serial or in parallel with Dask.
- :mod:`emc.plots`: waterfall diagrams and order cuts as PNG.
- :mod:`emc.cli`: the ``emc`` command.
"""
