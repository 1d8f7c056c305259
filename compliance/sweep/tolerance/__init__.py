"""Monte Carlo over tolerances: the yield of one candidate and the verdict bands of a check."""
