"""Analyses over any model, each a module returning result objects (gyro.results): the
Campbell diagram, sweeps and stability maps, the harmonic, unbalance and forced responses,
sensitivities, tolerances, the generic motion, the hierarchy's scenes and level maps. None
knows a model by its name: what only one paper's system has is in gyro.systems, reached
through what the model declares."""
