"""What a mechanism carries: statics, dynamics and grasps."""
