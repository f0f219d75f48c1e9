"""MuJoCo simulation backend (installed as g1_control.sim)."""
