"""Figure spec to equations of motion (the 1990 paper, §4): sympy derivation, the emitted numba
module, and the ``figure_motion`` of a state history."""
