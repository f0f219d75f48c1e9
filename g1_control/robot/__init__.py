"""G1 robot facts (g1.py), models built from its description (description.py) and the motor law."""
