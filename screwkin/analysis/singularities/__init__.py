"""Where a mechanism loses control or stiffness: singularity measures, ellipsoids, maps and scans."""
