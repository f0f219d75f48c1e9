"""G1 robot facts and models."""
