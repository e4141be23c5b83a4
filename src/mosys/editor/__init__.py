"""The concatenation editor (``mosys edit``): a matplotlib window whose sliders set how long each
phase of a composite script runs its BSR controller (the 1995 paper, §3)."""
