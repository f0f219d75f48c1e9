"""Real-robot transports (installed as g1_control.hardware)."""
