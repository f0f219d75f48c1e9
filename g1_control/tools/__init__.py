"""Tools that stand beside the stages: benchmarks (`g1 bench ...`), the fault-injection suite, the
WBC evaluation, the sim2sim measurement."""
