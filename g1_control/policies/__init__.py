"""Learned models and their adapters (installed as g1_control.policies)."""
