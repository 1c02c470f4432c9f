"""The mechanism model: the Pinocchio model of the spanning tree, the cut joints and their
loop-closure equations (with the closure solver and the assembly search), the topology
(links, joints, compound joints, motion space) and the linear algebra they share."""
