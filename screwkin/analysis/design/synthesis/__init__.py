"""Synthesis of planar linkages (issue 14): motion, function and path generation of
four-bars, and type and number synthesis of kinematic chains; every result is written as a
URDF (screwkin.files.writer) and checked with screwkin's own analyses (check.py)."""
