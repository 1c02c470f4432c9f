"""How a mechanism moves along an input: the one continuation (sweeps: closed form, batched, step by step, streamed), change points, absolute link and point motion."""
