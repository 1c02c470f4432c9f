"""Where a mechanism loses control or stiffness over its inputs and modes: ellipsoids, maps, loci and scans (the measures of one configuration: analysis.singular)."""
