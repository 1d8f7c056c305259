"""What a reader reads: every number, unit, quantity, metric value and limit as text, the same in the terminal,
the JSON display tables, JUnit and the reports.

- :mod:`~compliance.presentation.numbers`: the one number/unit formatter (significant digits, display
  resolution, typeset units, SI prefixes, margins, dates) and the one status-word table;
- :mod:`~compliance.presentation.quantities`: an SI quantity in the unit a reader expects (the one place a
  display conversion such as metres to millimetres is written);
- :mod:`~compliance.presentation.values`: a metric's SI value in its display unit, a verdict row's texts and a
  requirement's limit as written with its resolved value;
- :mod:`~compliance.presentation.measured_figures`: a measured figure beside the model's (model evidence).
"""
