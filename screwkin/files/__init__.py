"""Reading files: the text of a URDF (with <loop_joint>, <mimic>, <transmission>), an
Extended-URDF YAML sidecar or an SDF becomes a plain description (MechanismSpec).
Untrusted input is bounded and checked here; nothing here solves or computes kinematics."""
