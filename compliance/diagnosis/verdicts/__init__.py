"""The names a diagnosis concludes with: its verdicts and its candidate explanations (``a+b+base``)."""
