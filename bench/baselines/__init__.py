"""Baseline derivations of the seed models with sympy.physics.mechanics, one module per model.

Each is written as an ordinary user of sympy.physics.mechanics writes it: reference frames,
points, rigid bodies, LagrangesMethod and (for a linear operator) its Linearizer. Each
module's `run(point)` derives its quantity and evaluates it at `point` (numbers given by the
caller); `python -m bench.baselines.<model> --json POINT` prints one JSON line with the
times and the numbers. `common.run_child` runs one in a fresh process bounded in time.
"""
