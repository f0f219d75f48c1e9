"""Training of the generator's networks (torch; `g1 train ...`). The runtime in g1_control/generator/
never imports this package: it runs exported ONNX files."""
