"""Candidates of a sweep: declared (sweep files, parameter paths), drawn, judged on the one executor, ranked, tabulated."""
