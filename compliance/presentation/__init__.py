"""What a reader reads of a judged value: metric values and limits as text, the same in the terminal, JSON and report.

:mod:`~compliance.presentation.values` turns a metric's SI value into its display unit and a
requirement's limit into "as written (resolved)"; numbers and units themselves are formatted by
:mod:`compliance.units.formatting`. The CLI, the results files and the reports all call these.
"""
