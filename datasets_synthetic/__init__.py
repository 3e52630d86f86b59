"""Generators of the synthetic test data (no downloads): analytic functions sampled on grids."""
