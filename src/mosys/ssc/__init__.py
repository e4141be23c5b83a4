"""State-space controllers (the 1990 paper): the problem, the dynamic programming that solves it,
the controller tables it generates and their runtimes (interpolation, lookahead); the
state-space family."""
