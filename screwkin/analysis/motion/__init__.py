"""Where a mechanism is and how it moves: assembly modes, inverse kinematics, the one continuation (sweeps), absolute link and point motion."""
