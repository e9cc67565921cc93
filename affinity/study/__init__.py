"""The error-against-run-time study (``affinity bench``, issue 10).

One module per job:

- :mod:`.cases` — mesh files as study scenes (the built-in ones are
  ``affinity.scenes.study_scenes``), each with its view;
- :mod:`.sweep` — one scene: every method and hybrid setting drawn, timed and
  compared with the ``exact`` reference; the Pareto front;
- :mod:`.metrics` — attribute error (RMS, p99, max), PSNR, SSIM, crease;
- :mod:`.timing` — warm-up, interleaved repeats, median and spread, machine facts;
- :mod:`.tables`, :mod:`.charts` — the CSV, the markdown summary and the PNG charts;
- :mod:`.run` — all of it for a list of cases, into a folder.

Nothing heavy is imported here; matplotlib only by the charts.
"""
