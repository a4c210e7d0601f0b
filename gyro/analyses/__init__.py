"""Analyses over the generated models, each a module returning result objects
(gyro.results): the Campbell diagram, the stability map, the gimbal gyroscope's closed
form and its integrators."""
