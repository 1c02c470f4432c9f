"""The homotopy: every isolated root of a mechanism's polynomial closure, and how complete the set is.

``tracking`` follows many paths of a homotopy at once (predictor, corrector, the Cauchy endgame);
``square`` makes the closure's rows a square system; ``symmetry`` finds the sign maps that leave them
alone; ``monodromy`` finds every root at a generic offset (monodromy loops, the trace test) and carries
them to the inputs; ``known_counts`` names the published bounds that settle a count; ``parameter`` is
the coefficient-parameter homotopy of a Stewart-Gough platform from its architecture's generic set.
"""
