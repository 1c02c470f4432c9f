"""Analyses of a Mechanism: mobility, position/velocity/acceleration, sweeps, screws,
singularities, scans and maps.  Each returns plain result objects; none formats them."""
