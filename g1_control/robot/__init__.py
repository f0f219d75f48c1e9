"""G1 robot facts (g1.py), the models built from its description (description.py), the controller's
rigid-body dynamics (dynamics.py), the collision geometry (collision.py) and the Dex3-1 hands'
facts (dex3.py). The motor law the joint drivers run is sim/motor_law.py."""
