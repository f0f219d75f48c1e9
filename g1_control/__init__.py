"""g1-control: real-time generative whole-body control for the Unitree G1."""
__version__ = "0.1.0"
