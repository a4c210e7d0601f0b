"""What only one paper has, one module per system: the gimbal gyroscope's closed form
(Weierstrass's wp), the gyrohorizoncompass's conditions (3.6)/(4.3) and its motions, the
precession hierarchy's rate systems, the torsion gyrocompass's motion and its nonlinear
forced response. No command and no analysis imports these: a model reaches its module
only through what it declares (a level's evaluator `module`, the metadata's `system`),
and a model of a user's may name a module of its own the same way."""
