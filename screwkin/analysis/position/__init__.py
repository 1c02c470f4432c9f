"""Where a mechanism is: its configurations at given inputs and their assembly modes (solve, certified counts, inverse kinematics)."""
