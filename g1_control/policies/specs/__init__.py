"""Policy specs (YAML): how to feed and read each tracking policy."""
