// Statistical test helpers (chi-square, z-tests); see stats.h.
