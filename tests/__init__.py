"""The test suite (a package so that `tests.paths` and friends never resolve to another distribution's
top-level `tests` package, which some PyPI packages install into site-packages)."""
