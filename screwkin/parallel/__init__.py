"""Running many analyses at once: studies on Dask (a local cluster, an existing one, or in process)."""
