"""Motion generators: operator Command -> KinematicReference."""
