"""BSR controllers and their search: figures, time- and sense-based controllers, the search over a
population (the 1995 paper, §2 and §4); the BSR family."""
