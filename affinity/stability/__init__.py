"""Numerical stability of the quad coordinates on stiff and extreme cases (issue 11).

``cases`` (the catalogue), ``reference`` (exact results with mpmath),
``condition`` (the tolerance each case's own condition allows), ``naive`` (the
forms the project replaced), ``properties`` (what is measured), ``run`` (the
rows) and ``table`` (text, CSV, markdown). ``affinity stability`` drives them.
Nothing is computed at import.
"""
