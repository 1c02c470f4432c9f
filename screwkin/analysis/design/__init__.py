"""What a mechanism can reach and how it should be sized: workspaces, studies of design families, synthesis."""
