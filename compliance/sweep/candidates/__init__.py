"""Candidates of a sweep: declared (sweep files), drawn, judged on the one executor, ranked, tabulated."""
