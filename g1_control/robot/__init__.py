"""G1 robot facts (g1.py), the models built from its description (description.py), the controller's
rigid-body dynamics (dynamics.py) and the collision geometry (collision.py). The motor law the
joint drivers run is sim/motor_law.py."""
