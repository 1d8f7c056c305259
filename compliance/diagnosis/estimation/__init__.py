"""Estimation machinery of the diagnosis, independent of the servo: the simplex search whose evaluations stop
once they cannot matter (``simplex``) and the standard errors of a fit to correlated residuals (``standard_errors``)."""
