"""The course solution: vector-loop equations, A, B, det A, the textbook Newton iteration, the skeleton a diagram is drawn from."""
