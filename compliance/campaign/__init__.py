"""Campaigns: plan the procedure x operating-point runs of a requirement set, execute them,
judge the verdicts, write the results files; the regression gate between two results files."""
