"""The solver: the case turned into fields (scene, parameters, compile-time configuration), one
explicit step as an ordered list of stages, the time step and its clocks, monitors, the guard,
checkpoints and the :class:`Simulation` that ties them together."""
