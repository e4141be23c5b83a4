"""Composite motion (the 1995 paper, §3): BSR controllers run in sequence, scored by a composite
script, their switch times searched; the BSR family."""
